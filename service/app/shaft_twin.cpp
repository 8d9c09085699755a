// One shaft of hoist-twind: see shaft_twin.hpp.
#include "shaft_twin.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <fcntl.h>
#include <unistd.h>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/service/alarm_command.hpp"
#include "hoist/service/messages.hpp"
#include "hoist/service/winder_decode.hpp"

namespace hoist::svc {

using std::chrono::duration;

namespace {

/// Steady-clock span in nanoseconds (the cost split).
inline std::int64_t nanos(std::chrono::steady_clock::duration d) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count();
}

bool finiteAll(const hoist::cage_state_t& m) {
  bool ok = std::isfinite(m.t) && std::isfinite(m.l) && std::isfinite(m.v) && std::isfinite(m.a) &&
            std::isfinite(m.x_c) && std::isfinite(m.y_c) && std::isfinite(m.theta) &&
            std::isfinite(m.y_top) && std::isfinite(m.y_bottom) &&
            std::isfinite(m.guide_deflection) && std::isfinite(m.clearance_pos_y) &&
            std::isfinite(m.clearance_neg_y) && std::isfinite(m.clearance_guide) &&
            std::isfinite(m.min_clearance) && std::isfinite(m.rope_slack_threshold) &&
            std::isfinite(m.rope_overload_threshold);
  for (double v : m.lambdas) ok = ok && std::isfinite(v);
  return ok;
}

bool finiteAll(const hoist::guide_shape_t& m) {
  bool ok = std::isfinite(m.t) && std::isfinite(m.l) && std::isfinite(m.h);
  for (int i = 0; i < m.n; ++i)
    ok = ok && std::isfinite(m.x[i]) && std::isfinite(m.y1[i]) && std::isfinite(m.y2[i]);
  return ok;
}

bool finiteAll(const hoist::alarm_t& m) {
  return std::isfinite(m.t) && std::isfinite(m.value) && std::isfinite(m.threshold) &&
         std::isfinite(m.shelved_for);
}

bool finiteAll(const hoist::health_t& m) {
  return std::isfinite(m.uptime) && std::isfinite(m.t) && std::isfinite(m.rate) &&
         std::isfinite(m.window) && std::isfinite(m.step_p50_us) && std::isfinite(m.step_p99_us) &&
         std::isfinite(m.step_max_us) && std::isfinite(m.late_p50_us) &&
         std::isfinite(m.late_p99_us) && std::isfinite(m.late_max_us) && std::isfinite(m.input_age);
}

bool finiteAll(const hoist::forecast_t& m) {
  bool ok = std::isfinite(m.t_start) && std::isfinite(m.l) && std::isfinite(m.v) && std::isfinite(m.a) &&
            std::isfinite(m.compute_time);
  for (int i = 0; i < m.num_scenarios; ++i) {
    const hoist::forecast_scenario_t& s = m.scenarios[static_cast<std::size_t>(i)];
    ok = ok && std::isfinite(s.horizon) && std::isfinite(s.t_reached) && std::isfinite(s.min_clearance) &&
         std::isfinite(s.t_min_clearance) && std::isfinite(s.t_warning) && std::isfinite(s.t_critical) &&
         std::isfinite(s.peak_y_c) && std::isfinite(s.peak_theta) && std::isfinite(s.lambda0_min) &&
         std::isfinite(s.lambda0_max);
    for (double v : s.peak_lambdas) ok = ok && std::isfinite(v);
    for (int k = 0; k < s.num_points; ++k) {
      const auto j = static_cast<std::size_t>(k);
      ok = ok && std::isfinite(s.series_t[j]) && std::isfinite(s.series_min_clearance[j]) &&
           std::isfinite(s.series_lambda0_min[j]) && std::isfinite(s.series_lambda0_max[j]);
    }
  }
  return ok;
}

int divider(double rate, double sub_rate) {
  if (!(sub_rate > 0.0)) return 1;
  return std::max(1, static_cast<int>(std::lround(rate / sub_rate)));
}

}  // namespace

ShaftTwin::ShaftTwin(const TwinConfig& cfg, std::string label, lcm::LCM& lcm, RtLog& log, TestHooks hooks,
                     std::int64_t instance_id, lcm::LCM* lcm_out)
    : cfg_(cfg),
      label_(std::move(label)),
      tag_(label_.empty() ? std::string() : "[" + label_ + "] "),
      lcm_(lcm),
      out_(lcm_out ? *lcm_out : lcm),
      instance_id_(instance_id),
      log_(log),
      hooks_(hooks),
      ch_(cfg_.service.channel_prefix),
      core_(cfg_, cfg_.service.clock) {
  const ServiceConfig& s = cfg_.service;
  cage_div_ = divider(s.rate, s.cage_rate);
  shape_div_ = divider(s.rate, s.shape_rate);
  reject_log_.setLimit(s.log_rate_limit);

  // Preallocate every outgoing message and its buffer.
  const GuideRopeEnvelope& sh = core_.shape();
  shape_msg_.n = static_cast<int32_t>(sh.depths().size());
  shape_msg_.x.assign(sh.depths().data(), sh.depths().data() + sh.depths().size());
  shape_msg_.y1.assign(shape_msg_.n, 0.0);
  shape_msg_.y2.assign(shape_msg_.n, 0.0);
  shape_msg_.h = cfg_.shaft.h;
  health_msg_.clock = toString(s.clock);
  health_msg_.rate = s.rate;
  health_msg_.n_reasons = kRejectReasons + kExtraReasons;
  health_msg_.reject_reason.resize(kRejectReasons + kExtraReasons);
  health_msg_.rejected.assign(kRejectReasons + kExtraReasons, 0);
  for (int i = 0; i < kRejectReasons; ++i)
    health_msg_.reject_reason[i] = toString(static_cast<RejectReason>(i));
  health_msg_.reject_reason[kRejectReasons] = "command_decode";
  health_msg_.reject_reason[kRejectReasons + 1] = "handler_exception";
  for (int i = 0; i < kPlanRejectReasons; ++i)
    health_msg_.reject_reason[kRejectReasons + 2 + i] = toString(static_cast<PlanReject>(i));

  // Look-ahead forecasts: the job (workspace, mailboxes) and the message,
  // sized once.  A non-finite scenario keeps its status in the message; the
  // numbers of a scenario that stopped early cover [0, t_reached].
  if (cfg_.forecast.enabled) {
    cfg_.forecast.validate(s.rate);
    fast_ = dynamic_cast<const FastSolver*>(&core_.solver());
    if (!fast_) throw std::invalid_argument("forecast.enabled: the forecasts need the fast solver");
    fjob_ = std::make_unique<ForecastJob>(core_.solver().modelPtr(), cfg_);
    forecast_msg_.instance_id = instance_id_;
    forecast_msg_.num_scenarios = ForecastResult::kScenarios;
    forecast_msg_.scenarios.resize(ForecastResult::kScenarios);
    for (int i = 0; i < ForecastResult::kScenarios; ++i) {
      hoist::forecast_scenario_t& m = forecast_msg_.scenarios[static_cast<std::size_t>(i)];
      m.name = ForecastResult::kNames[i];
      m.num_points = static_cast<int16_t>(cfg_.forecast.series_points);
      m.series_t.assign(m.num_points, 0.0);
      m.series_min_clearance.assign(m.num_points, 0.0);
      m.series_lambda0_min.assign(m.num_points, 0.0);
      m.series_lambda0_max.assign(m.num_points, 0.0);
    }
    forecast_buf_.resize(static_cast<std::size_t>(forecast_msg_.getEncodedSize()) + 64);
  }
  alarm_msg_.kind.reserve(64);
  alarm_msg_.user.reserve(kUserMax + 4);
  cage_msg_.instance_id = instance_id_;
  health_msg_.instance_id = instance_id_;
  statm_fd_ = ::open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
  alarm_msg_.message.reserve(sizeof text_);
  cage_buf_.resize(static_cast<std::size_t>(cage_msg_.getEncodedSize()) + 64);
  shape_buf_.resize(static_cast<std::size_t>(shape_msg_.getEncodedSize()) + 64);
  alarm_buf_.resize(static_cast<std::size_t>(alarm_msg_.getEncodedSize()) + 64 + sizeof text_);
  health_buf_.resize(static_cast<std::size_t>(health_msg_.getEncodedSize()) + 256);
  text_[0] = '\0';
}

ShaftTwin::~ShaftTwin() {
  if (statm_fd_ >= 0) ::close(statm_fd_);
}

void ShaftTwin::subscribe(InputRouter* router) {
  // Our own health channel too: another publisher there (by instance_id) is
  // a second twin on our outputs.  Here when outputs share the input URL;
  // else the daemon watches the output URL (watchOwnOutputs).
  const bool own_health = &out_ == &lcm_;
  if (router) {
    router->add(ch_.winder, [this](const lcm::ReceiveBuffer* rb, const std::string& c) { onWinder(rb, c); });
    router->add(ch_.ack, [this](const lcm::ReceiveBuffer* rb, const std::string& c) { onAck(rb, c); });
    if (fjob_)
      router->add(ch_.trip_plan, [this](const lcm::ReceiveBuffer* rb, const std::string& c) { onTripPlan(rb, c); });
    if (own_health)
      router->add(ch_.health, [this](const lcm::ReceiveBuffer* rb, const std::string& c) { onOwnHealth(rb, c); });
    return;
  }
  // lcm::subscribe takes a regular expression: subscribe to the literal
  // names (a prefix "mine.1/" must not match "mineX1/").
  lcm_.subscribe(regexEscape(ch_.winder), &ShaftTwin::onWinder, this);
  lcm_.subscribe(regexEscape(ch_.ack), &ShaftTwin::onAck, this);
  if (fjob_) lcm_.subscribe(regexEscape(ch_.trip_plan), &ShaftTwin::onTripPlan, this);
  if (own_health) lcm_.subscribe(regexEscape(ch_.health), &ShaftTwin::onOwnHealth, this);
}

void ShaftTwin::watchOwnOutputs(InputRouter* router) {
  router->add(ch_.health, [this](const lcm::ReceiveBuffer* rb, const std::string& c) { onOwnHealth(rb, c); });
}

void ShaftTwin::onOwnHealth(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  // instance_id is the first field after utime: read it without decoding
  // the whole message (8-byte fingerprint, int64 utime, int64 instance_id).
  if (rbuf->data_size < 24) return;
  const auto* b = static_cast<const std::uint8_t*>(rbuf->data);
  std::int64_t fp = 0, id = 0;
  for (int i = 0; i < 8; ++i) fp = (fp << 8) | b[i];
  for (int i = 16; i < 24; ++i) id = static_cast<std::int64_t>((static_cast<std::uint64_t>(id) << 8) | b[i]);
  if (fp != static_cast<std::int64_t>(hoist::health_t::getHash()) || id == instance_id_) return;
  const double wall = wallNow();
  if (!(other_seen_wall_ >= 0.0) || id != other_id_)
    log_.error("{}another publisher (instance {}) on {}: a second twin with the same channels? "
               "(this one is instance {})", tag_, id, ch_.health, instance_id_);
  other_id_ = id;
  other_seen_wall_ = wall;
  core_.setDuplicatePublisher(true, static_cast<double>(id));
  drainAlarmEvents();
}

void ShaftTwin::start(Clock::time_point start, double health_phase) {
  start_ = start;
  publishHealth();  // announce ourselves at once
  // Shafts of one daemon spread their later health messages over the period.
  last_health_wall_ = -health_phase;
}

double ShaftTwin::wallNow() const { return duration<double>(Clock::now() - start_ - sync_pause_).count(); }

// ---- LCM input ---------------------------------------------------------------

void ShaftTwin::logReject(RejectReason r, const char* detail) {
  std::int64_t suppressed = 0;
  if (!reject_log_.allow(static_cast<int>(r), wallNow(), suppressed)) return;
  if (suppressed > 0)
    log_.warn("{}rejected winder input ({}): {} [{} similar suppressed]", tag_, toString(r), detail, suppressed);
  else
    log_.warn("{}rejected winder input ({}): {}", tag_, toString(r), detail);
}

void ShaftTwin::handlerFailed(const char* what, const char* channel) {
  ++handler_exceptions_;
  std::int64_t suppressed = 0;
  if (reject_log_.allow(kLogHandlerException, wallNow(), suppressed))
    log_.error("{}exception in the {} handler caught (message dropped): {} [{} similar suppressed]", tag_, channel,
               what, suppressed);
}

void ShaftTwin::onWinder(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  try {
    handleWinder(rbuf);
  } catch (const std::exception& e) {
    handlerFailed(e.what(), "HOIST_WINDER");
  } catch (...) {
    handlerFailed("unknown exception", "HOIST_WINDER");
  }
}

void ShaftTwin::onAck(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  try {
    handleAck(rbuf);
  } catch (const std::exception& e) {
    handlerFailed(e.what(), "HOIST_ALARM_ACK");
  } catch (...) {
    handlerFailed("unknown exception", "HOIST_ALARM_ACK");
  }
}

void ShaftTwin::handleWinder(const lcm::ReceiveBuffer* rbuf) {
  const double wall = wallNow();
  WinderSample s;
  const WinderDecode dec = decodeWinder(rbuf->data, rbuf->data_size, winder_in_, s);
  if (dec != WinderDecode::Ok) {
    core_.rejectUndecodable();
    std::snprintf(text_, sizeof text_, "%u bytes: %s", static_cast<unsigned>(rbuf->data_size), describe(dec));
    logReject(RejectReason::Decode, text_);
    return;
  }

  const auto t0 = Clock::now();
  const InputResult res = core_.onInput(s, wall);
  const auto t1 = Clock::now();
  if (!res.accepted) {
    std::snprintf(text_, sizeof text_, "seq %lld utime %lld v %g a %g%s%g",
                  static_cast<long long>(s.seq), static_cast<long long>(s.utime), s.v, s.a,
                  s.has_length ? " length " : " (no length) ", s.has_length ? s.length : 0.0);
    logReject(res.reason, text_);
  }
  if (res.reinitialized)
    log_.info("{}new winder stream (seq {}): model re-initialized at l = {} m", tag_, s.seq,
              core_.output().kin.l);
  if (res.republish) publishCage(s.utime);  // the held state, flagged degraded
  if (res.stepped) {
    const double us = duration<double, std::micro>(t1 - t0).count();
    step_hist_.add(us);
    publishCage(s.utime);
    const double rate = cfg_.service.shape_rate;
    if (rate > 0.0 && core_.modelTime() - last_shape_t_ >= 1.0 / rate - 1e-9) {
      last_shape_t_ = core_.modelTime();
      publishShape(s.utime);
    }
    if (fjob_) maybeForecast(s.utime);
  }
  drainAlarmEvents();
}

void ShaftTwin::handleAck(const lcm::ReceiveBuffer* rbuf) {
  // Operator commands are rare and outside the tick: decoding them into the
  // message's std::strings may allocate.  Anyone on the group can send
  // commands (docs/security.md): at most max_commands_per_tick are handled
  // per tick (the rest are dropped and counted); junk is logged under a rate
  // limit; every EFFECTIVE command is audited (log line and the HOIST_ALARM
  // events it causes carry the user) and never rate-limited.
  if (++commands_this_tick_ > cfg_.service.max_commands_per_tick) {
    ++commands_dropped_;
    logJunk(fmt::format("alarm command dropped: more than service.max_commands_per_tick = {} this tick",
            cfg_.service.max_commands_per_tick));
    return;
  }
  hoist::alarm_ack_t ack;
  const auto size = static_cast<std::size_t>(rbuf->data_size);
  // Every length is validated before anything is decoded (a 37-byte command
  // with a string length of 0 or 0x80000000 used to kill the daemon, issue 12).
  if (const auto st = hoist::msg::checkedDecode(rbuf->data, size, ack); st != hoist::msg::DecodeStatus::ok) {
    ++command_decode_rejects_;
    ++commands_invalid_;
    logJunk(fmt::format("ignored undecodable alarm command ({} bytes, {})", size, hoist::msg::toString(st)));
    return;
  }
  const std::string user = printable(ack.user, kUserMax);
  const char* why = "";
  const std::optional<AckCommand> cmd = validateAck(ack, why);
  if (!cmd) {
    ++commands_invalid_;
    logJunk(fmt::format("ignored alarm command from '{}' (kind '{}'): {}", user, printable(ack.kind), why));
    return;
  }
  const int n = core_.command(cmd->action, cmd->kind, cmd->level, cmd->shelve_duration);
  const char* what = cmd->action == AlarmAction::Ack ? "acknowledge" : cmd->action == AlarmAction::Shelve ? "shelve" : "unshelve";
  if (n == 0) {
    // Not effective (nothing to acknowledge, already shelved, ...): no
    // state changed, so no event and no audit line (a flood of identical
    // commands stays silent).
    logJunk(fmt::format("alarm command from '{}' had no effect: {} {}", user, what, cmd->kind ? toString(*cmd->kind) : "*"));
    return;
  }
  char for_s[96] = "";
  if (cmd->action == AlarmAction::Shelve) {
    const double eff = std::min(cmd->shelve_duration, cfg_.alarms.max_shelve);
    if (eff < cmd->shelve_duration)
      std::snprintf(for_s, sizeof for_s, " for %g s (requested %g s, clamped to max_shelve)", eff, cmd->shelve_duration);
    else
      std::snprintf(for_s, sizeof for_s, " for %g s", eff);
  }
  log_.info("{}AUDIT operator '{}': {} {}/{}{} -> {} alarm(s)", tag_, user, what,
            cmd->kind ? toString(*cmd->kind) : "*", cmd->level == AlarmLevel::None ? "*" : toString(cmd->level),
            for_s, n);
  cmd_user_ = user;
  cmd_requested_shelve_ = cmd->action == AlarmAction::Shelve ? cmd->shelve_duration : 0.0;
  drainAlarmEvents();
  cmd_user_.clear();
  cmd_requested_shelve_ = 0.0;
}

void ShaftTwin::logJunk(const std::string& what) {
  std::int64_t suppressed = 0;
  if (!reject_log_.allow(kLogJunkCommand, wallNow(), suppressed)) return;
  if (suppressed > 0) log_.warn("{}{} junk alarm-command log lines suppressed", tag_, suppressed);
  log_.warn("{}{}", tag_, what);
}

// ---- look-ahead forecasts (issue 17) ------------------------------------------------

void ShaftTwin::setForecastPool(ForecastPool* pool, double phase) {
  pool_ = pool;
  forecast_phase_ = phase;
  next_forecast_t_ = phase / cfg_.forecast.rate;
}

void ShaftTwin::onTripPlan(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  try {
    handleTripPlan(rbuf);
  } catch (const std::exception& e) {
    handlerFailed(e.what(), "HOIST_TRIP_PLAN");
  } catch (...) {
    handlerFailed("unknown exception", "HOIST_TRIP_PLAN");
  }
}

void ShaftTwin::rejectPlan(PlanReject r, const char* detail) {
  ++plan_rejects_[static_cast<std::size_t>(r)];
  std::int64_t suppressed = 0;
  if (!reject_log_.allow(kLogPlan, wallNow(), suppressed)) return;
  log_.warn("{}rejected trip plan ({}): {} [{} similar suppressed]", tag_, toString(r), detail, suppressed);
}

void ShaftTwin::handleTripPlan(const lcm::ReceiveBuffer* rbuf) {
  // Every byte is validated before anything is decoded (checked decoder);
  // trip_plan_t is flat (no string, no array): decoding allocates nothing.
  const auto size = static_cast<std::size_t>(rbuf->data_size);
  if (const auto st = hoist::msg::checkedDecode(rbuf->data, size, plan_in_); st != hoist::msg::DecodeStatus::ok) {
    std::snprintf(text_, sizeof text_, "%zu bytes: %s", size, hoist::msg::toString(st));
    rejectPlan(PlanReject::Decode, text_);
    return;
  }
  const trip_plan_t& m = plan_in_;
  if (have_plan_ && m.seq <= plan_seq_) {
    std::snprintf(text_, sizeof text_, "seq %lld is not newer than the plan in force (seq %lld)",
                  static_cast<long long>(m.seq), static_cast<long long>(plan_seq_));
    rejectPlan(PlanReject::OldSeq, text_);
    return;
  }
  const TripPlan p{m.target_length, m.vmax, m.amax, m.jerk};
  const CageOutput& o = core_.output();
  const PlanCheck pc = checkPlan(p, core_.modelTime(), o.kin, cfg_.shaft, plan_scratch_);
  if (!pc.ok()) {
    // describe() allocates: plans are rare, off the tick (as alarm commands).
    const std::string why = describe(pc);
    std::snprintf(text_, sizeof text_, "seq %lld target %g m vmax %g amax %g jerk %g at l = %.3f m, v = %.3f m/s, "
                  "a = %.3f m/s^2: %s",
                  static_cast<long long>(m.seq), m.target_length, m.vmax, m.amax, m.jerk, o.kin.l, o.kin.v, o.kin.a,
                  why.c_str());
    rejectPlan(planReject(pc.error), text_);
    return;
  }
  const bool first = !have_plan_;
  have_plan_ = true;
  plan_ = p;
  plan_seq_ = m.seq;
  ++plans_accepted_;
  if (first)
    log_.info("{}trip plan accepted (seq {}): target {} m, vmax {} m/s, amax {} m/s^2, jerk {} m/s^3", tag_, m.seq,
              m.target_length, m.vmax, m.amax, m.jerk);
}

void ShaftTwin::maybeForecast(std::int64_t utime) {
  const double tp = core_.output().t;
  const double period = 1.0 / cfg_.forecast.rate;
  // The published time restarts at the first input (wall clock) or a new
  // stream: re-align the schedule when it went back.
  if (tp + period < next_forecast_t_) next_forecast_t_ = (std::floor(tp / period) + forecast_phase_) * period;
  if (tp + 1e-9 < next_forecast_t_) return;
  while (next_forecast_t_ <= tp + 1e-9) next_forecast_t_ += period;
  if (core_.degraded() || !core_.solver().finite()) {
    // A state just re-initialized after a fault, stale input, the domain
    // edge, a limited catch-up: not a state to forecast from.  The
    // predictions are withdrawn (MODEL_FAULT / INPUT_STALE / MODEL_DOMAIN
    // say what is wrong).
    ++forecasts_skipped_;
    core_.setPredictions(false, 0.0, false, 0.0, cfg_.forecast.horizon);
    return;
  }
  ForecastSnapshot& snap = fjob_->snapshotSlot();
  fast_->saveState(snap.state);
  snap.utime = utime;
  snap.t_published = tp;
  snap.has_plan = have_plan_;
  snap.plan = plan_;
  snap.plan_seq = plan_seq_;
  if (core_.clock() == ClockMode::Input || !pool_) {
    // Deterministic: the forecast runs here, at this instant, and its result
    // is published before the next input is read.
    const auto c0 = Clock::now();
    const ForecastResult& r = fjob_->runNow();
    sync_pause_ += Clock::now() - c0;
    onForecastResult(r);
    return;
  }
  if (fjob_->postSnapshot()) ++forecasts_dropped_;
  pool_->notify();
}

void ShaftTwin::onForecastResult(const ForecastResult& r) {
  if (r.failed) {
    ++forecast_failures_;
    return;
  }
  ++forecasts_;
  const double us = r.compute_s * 1e6;
  forecast_hist_.add(us);
  forecast_total_.add(us);
  if (r.plan_error != PlanError::None) {
    // The plan was valid when it came, but no longer fits the motion (e.g.
    // braking already, the target closer than the plan's stopping distance):
    // "continue" used the no-plan rule.
    ++plan_unusable_;
    std::int64_t suppressed = 0;
    if (reject_log_.allow(kLogPlan, wallNow(), suppressed))
      log_.info("{}trip plan seq {} no longer fits the motion at t = {:.2f} s ({}): the continue scenario uses the "
                "no-plan rule [{} similar suppressed]",
                tag_, plan_seq_, r.t_published, hoist::toString(r.plan_error), suppressed);
  }
  const ForecastSummary* sc[ForecastResult::kScenarios];
  for (int i = 0; i < ForecastResult::kScenarios; ++i) sc[i] = &r.scenario[i];
  slack_threshold_ = slackThreshold(cfg_, core_.solver().model(), r.kin.l);
  const ForecastVerdict v = judgeForecast(sc, ForecastResult::kScenarios, slack_threshold_);
  pred_clearance_scenario_ = v.clearance ? ForecastResult::kNames[v.clearance_scenario] : "";
  pred_slack_scenario_ = v.slack ? ForecastResult::kNames[v.slack_scenario] : "";
  core_.setPredictions(v.clearance, v.clearance_s, v.slack, v.slack_s, cfg_.forecast.horizon);
  publishForecast(r);
  drainAlarmEvents();
}

void ShaftTwin::publishForecast(const ForecastResult& r) {
  forecast_t& m = forecast_msg_;
  m.utime = r.utime;
  m.seq = forecast_seq_++;
  m.t_start = r.t_published;
  m.l = r.kin.l;
  m.v = r.kin.v;
  m.a = r.kin.a;
  m.plan_seq = r.plan_seq;
  m.compute_time = r.compute_s;
  for (int i = 0; i < ForecastResult::kScenarios; ++i) {
    const ForecastSummary& f = r.scenario[i];
    forecast_scenario_t& s = m.scenarios[static_cast<std::size_t>(i)];
    s.status = static_cast<int8_t>(f.status);
    s.horizon = f.horizon;
    s.t_reached = f.t_reached;
    s.min_clearance = f.min_clearance;
    s.t_min_clearance = f.t_min_clearance;
    s.t_warning = f.t_warning;
    s.t_critical = f.t_critical;
    s.peak_y_c = f.peak_y_c;
    s.peak_theta = f.peak_theta;
    for (int k = 0; k < 4; ++k) s.peak_lambdas[k] = f.peak_lambda[static_cast<std::size_t>(k)];
    s.lambda0_min = f.lambda0_min;
    s.lambda0_max = f.lambda0_max;
    const int np = std::clamp(f.series_count, 0, static_cast<int>(s.series_t.size()));
    s.num_points = static_cast<int16_t>(np);
    for (int k = 0; k < np; ++k) {
      const auto j = static_cast<std::size_t>(k);
      s.series_t[j] = f.series_t[j];
      s.series_min_clearance[j] = f.series_min_clearance[j];
      s.series_lambda0_min[j] = f.series_lambda0_min[j];
      s.series_lambda0_max[j] = f.series_lambda0_max[j];
    }
  }
  encodeAndPublish(ch_.forecast, m, forecast_buf_);
}

// ---- the tick ------------------------------------------------------------------

void ShaftTwin::tick(std::int64_t k, Clock::time_point deadline, std::int64_t skipped) {
  const auto now = Clock::now();
  const double late_us = std::max(0.0, duration<double, std::micro>(now - deadline).count());
  late_hist_.add(late_us);
  ++ticks_;
  deadline_misses_ += skipped;
  commands_this_tick_ = 0;
  const double wall = duration<double>(now - start_ - sync_pause_).count();
  if (hooks_.inject_fault_at >= 0.0 && !fault_injected_ && wall >= hooks_.inject_fault_at) {
    fault_injected_ = true;
    log_.warn("{}test: injecting a model fault (non-finite state) at wall time {:.3f} s", tag_, wall);
    core_.injectFault();
  }

  if (core_.clock() == ClockMode::Wall) {
    const double t = static_cast<double>(k) / cfg_.service.rate;
    const auto t0 = Clock::now();
    const TickResult r = core_.tick(t, wall);
    core_.housekeeping(wall);
    const auto t1 = Clock::now();
    ns_model_ += nanos(t1 - t0);
    if (r.stepped) {
      const double us = duration<double, std::micro>(t1 - t0).count();
      step_hist_.add(us);
      }
    if (r.catchup_limited) {
      std::int64_t suppressed = 0;
      if (reject_log_.allow(kLogCatchup, wall, suppressed))
        log_.warn("{}the loop fell behind: a tick had to cross more than service.max_catchup_periods = {} periods; "
                  "crossed with longer substeps, output flagged degraded [{} similar suppressed]",
                  tag_, cfg_.service.max_catchup_periods, suppressed);
    }
    if (fjob_) {
      // Results of earlier snapshots (the worker posts them when done).
      if (const ForecastResult* fr = fjob_->takeResult()) onForecastResult(*fr);
    }
    if (r.stepped && core_.hasInput()) {
      const auto p0 = Clock::now();
      const std::int64_t utime = bus::wallUtime();
      if (k % cage_div_ == 0) publishCage(utime, true);
      if (cfg_.service.shape_rate > 0.0 && k % shape_div_ == 0) publishShape(utime, true);
      ns_publish_ += nanos(Clock::now() - p0);
      if (fjob_) maybeForecast(utime);
    }
  } else {
    core_.housekeeping(wall);
  }
  // The other publisher is gone after three health periods without a word.
  if (other_seen_wall_ >= 0.0 && wall - other_seen_wall_ > 3.0 / cfg_.service.health_rate) {
    other_seen_wall_ = -1.0;
    core_.setDuplicatePublisher(false, 0.0);
  }
  drainAlarmEvents();

  if (wall - last_health_wall_ >= 1.0 / cfg_.service.health_rate - 0.5 / cfg_.service.rate) {
    const auto p0 = Clock::now();
    publishHealth();
    ns_publish_ += nanos(Clock::now() - p0);
  }
  ns_tick_ += nanos(Clock::now() - now);
}

// ---- outputs -----------------------------------------------------------------

bool ShaftTwin::publishBytes(const std::string& channel, const std::vector<std::uint8_t>& buf, int len, bool batch) {
  const bool injected = hooks_.fail_publish_every > 0 && ++publish_attempts_ % hooks_.fail_publish_every == 0;
  const auto n = static_cast<std::size_t>(len);
  bool ok = false;
  if (injected) ok = false;
  else if (sender_ && batch && sender_->queue(channel, buf.data(), n, &publish_failures_)) ok = true;
  else if (sender_ && n <= UdpmSender::kMaxPayload) ok = sender_->send(channel, buf.data(), n);
  else ok = out_.publish(channel, buf.data(), static_cast<unsigned int>(len)) == 0;
  if (!ok) {
    ++publish_failures_;
    std::int64_t suppressed = 0;
    if (reject_log_.allow(kLogPublish, wallNow(), suppressed))
      log_.error("{}LCM publish failed on {} [{} similar suppressed]", tag_, channel, suppressed);
    return false;
  }
  return true;
}

template <class Msg>
bool ShaftTwin::encodeAndPublish(const std::string& channel, const Msg& msg, std::vector<std::uint8_t>& buf,
                                 bool batch) {
  if (!finiteAll(msg)) {
    ++nonfinite_blocked_;
    std::int64_t suppressed = 0;
    if (reject_log_.allow(kLogPublish, wallNow(), suppressed))
      log_.error("{}withheld a message on {}: non-finite value", tag_, channel);
    return false;
  }
  const int need = msg.getEncodedSize();
  if (need > static_cast<int>(buf.size())) {
    ++publish_failures_;
    log_.error("{}message on {} too large for its buffer ({} > {} bytes)", tag_, channel, need, buf.size());
    return false;
  }
  const int len = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  if (len < 0) {
    ++publish_failures_;
    return false;
  }
  return publishBytes(channel, buf, len, batch);
}

void ShaftTwin::publishCage(std::int64_t utime, bool batch) {
  cage_msg_.utime = utime;
  cage_msg_.seq = cage_seq_++;
  toCageMessage(core_.output(), cage_msg_);
  encodeAndPublish(ch_.cage, cage_msg_, cage_buf_, batch);
}

void ShaftTwin::publishShape(std::int64_t utime, bool batch) {
  core_.evaluateShape();
  const GuideRopeEnvelope& sh = core_.shape();
  shape_msg_.utime = utime;
  shape_msg_.t = core_.output().t;
  shape_msg_.l = core_.output().kin.l;
  for (int i = 0; i < shape_msg_.n; ++i) {
    shape_msg_.y1[i] = sh.y1()(i);
    shape_msg_.y2[i] = sh.y2()(i);
  }
  encodeAndPublish(ch_.shape, shape_msg_, shape_buf_, batch);
}

void ShaftTwin::drainAlarmEvents() {
  const AlarmEvents& ev = core_.events();
  if (ev.empty()) return;
  const std::int64_t utime = bus::wallUtime();
  AlarmTextContext ctx;
  ctx.alarms = &cfg_.alarms;
  ctx.stale_timeout = core_.staleTimeout();
  ctx.range = core_.validRange();
  ctx.fault_what = core_.lastFaultWhat();
  ctx.requested_shelve = cmd_requested_shelve_;
  ctx.predicted_clearance_scenario = pred_clearance_scenario_;
  ctx.predicted_slack_scenario = pred_slack_scenario_;
  ctx.slack_threshold = slack_threshold_;
  alarm_msg_.user.assign(cmd_user_);  // who caused these events ("" for the twin itself)
  for (const AlarmEvent& e : ev) {
    describeAlarm(e, ctx, text_, sizeof text_);
    alarm_msg_.utime = utime;
    alarm_msg_.id = alarm_id_++;
    alarm_msg_.t = core_.publishedTime(e.t);  // one time origin with HOIST_CAGE.t
    alarm_msg_.kind.assign(toString(e.kind));
    alarm_msg_.level = static_cast<int8_t>(e.level);
    alarm_msg_.event_type = static_cast<int8_t>(e.type);
    alarm_msg_.active = e.active;
    alarm_msg_.acked = e.acked;
    alarm_msg_.shelved = e.shelved;
    alarm_msg_.latched = e.latched;
    alarm_msg_.value = e.value;
    alarm_msg_.threshold = e.threshold;
    alarm_msg_.shelved_for = e.shelved_for;
    alarm_msg_.message.assign(text_);
    if (encodeAndPublish(ch_.alarm, alarm_msg_, alarm_buf_)) ++alarm_events_;
    switch (e.type) {
      case AlarmEventType::Reannounce: log_.debug("{}alarm: {} (t = {:.2f} s)", tag_, text_, alarm_msg_.t); break;
      case AlarmEventType::Raise:
        if (e.level == AlarmLevel::Critical) log_.error("{}ALARM {} (t = {:.2f} s)", tag_, text_, alarm_msg_.t);
        else log_.warn("{}ALARM {} (t = {:.2f} s)", tag_, text_, alarm_msg_.t);
        break;
      default:
        if (!cmd_user_.empty()) log_.info("{}alarm: {} (t = {:.2f} s, by '{}')", tag_, text_, alarm_msg_.t, cmd_user_);
        else log_.info("{}alarm: {} (t = {:.2f} s)", tag_, text_, alarm_msg_.t);
        break;
    }
  }
  if (ev.dropped() > 0) log_.error("{}{} alarm events dropped (event buffer full)", tag_, ev.dropped());
  core_.clearEvents();
}

void ShaftTwin::publishHealth(bool final_report) {
  const double wall = wallNow();
  const InputCounters& c = core_.counters();
  const AlarmEngine& al = core_.alarms();
  health_msg_.utime = bus::wallUtime();
  health_msg_.uptime = std::max(0.0, wall);
  health_msg_.t = core_.publishedTime(core_.modelTime());
  health_msg_.window = std::max(0.0, wall - std::max(0.0, last_health_wall_));
  health_msg_.ticks = ticks_;
  health_msg_.steps = core_.steps();
  health_msg_.deadline_misses = deadline_misses_;
  health_msg_.step_p50_us = step_hist_.quantile(0.5);
  health_msg_.step_p99_us = step_hist_.quantile(0.99);
  health_msg_.step_max_us = step_hist_.max();
  health_msg_.late_p50_us = late_hist_.quantile(0.5);
  health_msg_.late_p99_us = late_hist_.quantile(0.99);
  health_msg_.late_max_us = late_hist_.max();
  health_msg_.input_age = core_.inputAge(wall);
  health_msg_.accepted = c.accepted;
  health_msg_.seq_gaps = c.seq_gaps;
  health_msg_.rejected_total = c.rejectedTotal();
  for (int i = 0; i < kRejectReasons; ++i) health_msg_.rejected[i] = c.rejected[i];
  health_msg_.rejected[kRejectReasons] = command_decode_rejects_;
  health_msg_.rejected[kRejectReasons + 1] = handler_exceptions_;
  std::int64_t plans_rejected = 0;
  for (int i = 0; i < kPlanRejectReasons; ++i) {
    health_msg_.rejected[kRejectReasons + 2 + i] = plan_rejects_[static_cast<std::size_t>(i)];
    plans_rejected += plan_rejects_[static_cast<std::size_t>(i)];
  }
  health_msg_.forecast_p50_us = forecast_hist_.count() > 0 ? forecast_hist_.quantile(0.5) : 0.0;
  health_msg_.forecast_p99_us = forecast_hist_.count() > 0 ? forecast_hist_.quantile(0.99) : 0.0;
  health_msg_.forecasts = forecasts_;
  health_msg_.forecasts_dropped = forecasts_dropped_;
  health_msg_.forecasts_skipped = forecasts_skipped_;
  health_msg_.plans_accepted = plans_accepted_;
  health_msg_.plans_rejected = plans_rejected;
  health_msg_.alarms_active = al.activeCount();
  health_msg_.alarms_unacked = al.unackedCount();
  health_msg_.alarms_shelved = al.shelvedCount();
  health_msg_.alarm_events = alarm_events_;
  health_msg_.model_faults = core_.modelFaults();
  health_msg_.model_resets = core_.modelResets();
  health_msg_.publish_failures = publish_failures_;
  health_msg_.nonfinite_blocked = nonfinite_blocked_;
  health_msg_.degraded = core_.degraded();
  health_msg_.rss_kb = rssKb();
  health_msg_.commands_dropped = commands_dropped_;
  health_msg_.commands_invalid = commands_invalid_;
  health_msg_.catchup_limited = core_.catchupLimited();
  health_msg_.datagrams_ignored = ignored_counter_ ? *ignored_counter_ : 0;
  encodeAndPublish(ch_.health, health_msg_, health_buf_);
  if (!final_report)
    log_.debug("{}health: t={:.2f} s steps={} step p50/p99/max={:.0f}/{:.0f}/{:.0f} us late "
               "p50/p99/max={:.0f}/{:.0f}/{:.0f} us misses={} inputs ok={} rejected={} gaps={} "
               "alarms active={} faults={} publish failures={}{}",
               tag_, health_msg_.t, health_msg_.steps, health_msg_.step_p50_us, health_msg_.step_p99_us,
               health_msg_.step_max_us, health_msg_.late_p50_us, health_msg_.late_p99_us,
               health_msg_.late_max_us, deadline_misses_, c.accepted, c.rejectedTotal(), c.seq_gaps,
               health_msg_.alarms_active, health_msg_.model_faults, publish_failures_,
               health_msg_.degraded ? " DEGRADED" : "");
  // The whole-run histograms take each window at its end (one add per
  // value per tick instead of two: with hundreds of shafts every histogram
  // bin touched is a cache miss).
  step_total_.merge(step_hist_);
  late_total_.merge(late_hist_);
  step_hist_.reset();
  late_hist_.reset();
  forecast_hist_.reset();
  last_health_wall_ = wall;
}

void ShaftTwin::logFinal() {
  const InputCounters& c = core_.counters();
  log_.info("{}final health: t={:.2f} s ticks={} steps={} over the whole run: step p50/p99/p99.9/max="
            "{:.1f}/{:.1f}/{:.1f}/{:.0f} us, tick lateness p50/p99/p99.9/max={:.0f}/{:.0f}/{:.0f}/{:.0f} us, "
            "deadline misses={}; inputs accepted={} rejected={} sequence gaps={}; alarms "
            "active={} events={}; model faults={} resets={}; publish failures={} withheld "
            "(non-finite)={}{}",
            tag_, core_.modelTime(), ticks_, core_.steps(), step_total_.quantile(0.5),
            step_total_.quantile(0.99), step_total_.quantile(0.999), step_total_.max(),
            late_total_.quantile(0.5), late_total_.quantile(0.99), late_total_.quantile(0.999),
            late_total_.max(), deadline_misses_, c.accepted, c.rejectedTotal(), c.seq_gaps,
            core_.alarms().activeCount(), alarm_events_, core_.modelFaults(), core_.modelResets(),
            publish_failures_, nonfinite_blocked_, core_.degraded() ? " DEGRADED" : "");
  for (int i = 0; i < kRejectReasons; ++i)
    if (c.rejected[i] > 0) log_.info("{}  rejected {}: {}", tag_, toString(static_cast<RejectReason>(i)), c.rejected[i]);
  if (command_decode_rejects_ > 0) log_.info("{}  rejected alarm commands (command_decode): {}", tag_, command_decode_rejects_);
  if (handler_exceptions_ > 0) log_.info("{}  exceptions caught in LCM handlers: {}", tag_, handler_exceptions_);
  if (fjob_) {
    log_.info("{}forecasts: {} done (compute p50/p99/max {:.1f}/{:.1f}/{:.1f} ms), {} dropped (worker late), {} skipped "
              "(degraded), {} failed; trip plans accepted {}, no longer fitting the motion {}",
              tag_, forecasts_, forecast_total_.quantile(0.5) / 1e3, forecast_total_.quantile(0.99) / 1e3,
              forecast_total_.max() / 1e3, forecasts_dropped_, forecasts_skipped_, forecast_failures_, plans_accepted_,
              plan_unusable_);
    for (int i = 0; i < kPlanRejectReasons; ++i)
      if (plan_rejects_[static_cast<std::size_t>(i)] > 0)
        log_.info("{}  rejected trip plans {}: {}", tag_, toString(static_cast<PlanReject>(i)),
                  plan_rejects_[static_cast<std::size_t>(i)]);
  }
}

std::int64_t ShaftTwin::rssKb() const {
  // /proc/self/statm: size resident ... in pages.  pread into a stack
  // buffer: no allocation.
  if (statm_fd_ < 0) return -1;
  char b[128];
  const ssize_t n = ::pread(statm_fd_, b, sizeof b - 1, 0);
  if (n <= 0) return -1;
  b[n] = '\0';
  long size = 0, resident = 0;
  if (std::sscanf(b, "%ld %ld", &size, &resident) != 2) return -1;
  return static_cast<std::int64_t>(resident) * (::sysconf(_SC_PAGESIZE) / 1024);
}

ShaftRunStats ShaftTwin::runStats() const {
  ShaftRunStats s;
  const InputCounters& c = core_.counters();
  s.label = !label_.empty() ? label_ : cfg_.service.channel_prefix.empty() ? "default" : cfg_.service.channel_prefix;
  s.ticks = ticks_;
  s.steps = core_.steps();
  s.deadline_misses = deadline_misses_;
  s.accepted = c.accepted;
  s.rejected = c.rejectedTotal();
  s.seq_gaps = c.seq_gaps;
  s.alarm_events = alarm_events_;
  s.model_faults = core_.modelFaults();
  s.publish_failures = publish_failures_;
  s.nonfinite_blocked = nonfinite_blocked_;
  s.step = &step_total_;
  s.late = &late_total_;
  s.ns_model = ns_model_;
  s.ns_envelope = core_.envelopeNanos();
  s.ns_publish = ns_publish_;
  s.ns_tick = ns_tick_;
  s.envelope_exact = core_.envelope().exactEvaluations();
  s.envelope_bounded = core_.envelope().boundedEvaluations();
  s.forecasts = forecasts_;
  s.forecasts_dropped = forecasts_dropped_;
  s.forecasts_skipped = forecasts_skipped_;
  s.plans_accepted = plans_accepted_;
  for (auto n : plan_rejects_) s.plans_rejected += n;
  s.forecast = &forecast_total_;
  return s;
}

}  // namespace hoist::svc
