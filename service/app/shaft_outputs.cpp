// The outputs of one shaft: see shaft_outputs.hpp.
#include "shaft_outputs.hpp"

#include <algorithm>
#include <cmath>

#include "hoist/bus/lcm_util.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/service/lcm/messages.hpp"

namespace hoist::service::inline app {

namespace {

int divider(double rate, double sub_rate) {
  if (!(sub_rate > 0.0)) return 1;
  return std::max(1, static_cast<int>(std::lround(rate / sub_rate)));
}

}  // namespace

ShaftOutputs::ShaftOutputs(const ShaftContext& ctx, TwinCore& core, OutputStats& stats, const InputStats& inputs,
                           ::lcm::LCM& out)
    : ctx_(ctx), core_(core), stats_(stats), inputs_(inputs), out_(out) {
  const ServiceConfig& s = ctx_.cfg.service;
  cage_div_ = divider(s.rate, s.cage_rate);
  shape_div_ = divider(s.rate, s.shape_rate);
  log_limit_.setLimit(s.log_rate_limit);

  // Preallocate every outgoing message and its buffer.
  const GuideRopeEnvelope& sh = core_.shape();
  shape_msg_.n = static_cast<int32_t>(sh.depths().size());
  shape_msg_.x.assign(sh.depths().data(), sh.depths().data() + sh.depths().size());
  shape_msg_.y1.assign(shape_msg_.n, 0.0);
  shape_msg_.y2.assign(shape_msg_.n, 0.0);
  shape_msg_.h = ctx_.cfg.shaft.h;
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

  // Look-ahead forecasts: the message, sized once.  A non-finite scenario
  // keeps its status in the message; the numbers of a scenario that stopped
  // early cover [0, t_reached].
  if (ctx_.cfg.forecast.enabled) {
    forecast_msg_.instance_id = ctx_.instance_id;
    forecast_msg_.num_scenarios = ForecastResult::kScenarios;
    forecast_msg_.scenarios.resize(ForecastResult::kScenarios);
    for (int i = 0; i < ForecastResult::kScenarios; ++i) {
      hoist::forecast_scenario_t& m = forecast_msg_.scenarios[static_cast<std::size_t>(i)];
      m.name = ForecastResult::kNames[i];
      m.num_points = static_cast<int16_t>(ctx_.cfg.forecast.series_points);
      m.series_t.assign(m.num_points, 0.0);
      m.series_min_clearance.assign(m.num_points, 0.0);
      m.series_lambda0_min.assign(m.num_points, 0.0);
      m.series_lambda0_max.assign(m.num_points, 0.0);
    }
    forecast_buf_.resize(static_cast<std::size_t>(forecast_msg_.getEncodedSize()) + 64);
  }
  alarm_msg_.kind.reserve(64);
  alarm_msg_.user.reserve(kUserMax + 4);
  cage_msg_.instance_id = ctx_.instance_id;
  estimate_msg_.instance_id = ctx_.instance_id;
  estimate_buf_.resize(static_cast<std::size_t>(estimate_msg_.getEncodedSize()) + 64);
  health_msg_.instance_id = ctx_.instance_id;
  alarm_msg_.instance_id = ctx_.instance_id;  // clients accept alarm events only from this instance
  alarm_msg_.message.reserve(sizeof text_);
  cage_buf_.resize(static_cast<std::size_t>(cage_msg_.getEncodedSize()) + 64);
  shape_buf_.resize(static_cast<std::size_t>(shape_msg_.getEncodedSize()) + 64);
  alarm_buf_.resize(static_cast<std::size_t>(alarm_msg_.getEncodedSize()) + 64 + sizeof text_);
  // The miss record's arrays, sized once at their bound (n_misses says how
  // many are in use); the buffer fits them all.
  {
    hoist::health_t& h = health_msg_;
    const auto m = static_cast<std::size_t>(hoist::health_t::MAX_MISSES);
    h.n_misses = hoist::health_t::MAX_MISSES;
    h.miss_utime.assign(m, 0);
    h.miss_t.assign(m, 0.0);
    h.miss_tick.assign(m, 0);
    h.miss_skipped.assign(m, 0);
    h.miss_late_us.assign(m, 0.0);
    h.miss_shafts_late.assign(m, 0);
    for (auto* v : {&h.miss_receive_us, &h.miss_step_us, &h.miss_envelope_us, &h.miss_publish_us,
                    &h.miss_forecast_us, &h.miss_start_us, &h.miss_health_us, &h.miss_other_us, &h.miss_timer_us})
      v->assign(m, 0.0);
  }
  health_buf_.resize(static_cast<std::size_t>(health_msg_.getEncodedSize()) + 256);
  health_msg_.n_misses = 0;
  text_[0] = '\0';
}

bool ShaftOutputs::publishBytes(const std::string& channel, const std::vector<std::uint8_t>& buf, int len,
                                bool batch) {
  OutputStats& st = stats_;
  const int every = ctx_.hooks.fail_publish_every;
  const bool injected = every > 0 && ++st.publish_attempts % every == 0;
  const auto n = static_cast<std::size_t>(len);
  bool ok = false;
  if (injected) ok = false;
  else if (sender_ && batch && sender_->queue(channel, buf.data(), n, &st.publish_failures)) ok = true;
  else if (sender_ && n <= UdpmSender::kMaxPayload) ok = sender_->send(channel, buf.data(), n);
  else ok = out_.publish(channel, buf.data(), static_cast<unsigned int>(len)) == 0;
  if (!ok) {
    ++st.publish_failures;
    std::int64_t suppressed = 0;
    if (log_limit_.allow(kLogPublish, ctx_.wallNow(), suppressed))
      ctx_.log.error("{}LCM publish failed on {} [{} similar suppressed]", ctx_.tag, channel, suppressed);
    return false;
  }
  return true;
}

template <class Msg>
bool ShaftOutputs::encodeAndPublish(const std::string& channel, const Msg& msg, std::vector<std::uint8_t>& buf,
                                    bool batch) {
  OutputStats& st = stats_;
  if (!hoist::msg::allFinite(msg)) {  // generated from the .lcm files (hoist/msg/codec.hpp)
    ++st.nonfinite_blocked;
    std::int64_t suppressed = 0;
    if (log_limit_.allow(kLogPublish, ctx_.wallNow(), suppressed))
      ctx_.log.error("{}withheld a message on {}: non-finite value", ctx_.tag, channel);
    return false;
  }
  const int need = msg.getEncodedSize();
  if (need > static_cast<int>(buf.size())) {
    ++st.publish_failures;
    ctx_.log.error("{}message on {} too large for its buffer ({} > {} bytes)", ctx_.tag, channel, need, buf.size());
    return false;
  }
  const int len = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  if (len < 0) {
    ++st.publish_failures;
    return false;
  }
  return publishBytes(channel, buf, len, batch);
}

void ShaftOutputs::publishTick(std::int64_t k, std::int64_t utime) {
  if ((k + cage_phase_) % cage_div_ == 0) {
    publishCage(utime, true);
    publishEstimate(utime, true);
  }
  if (ctx_.cfg.service.shape_rate > 0.0 && (k + shape_phase_) % shape_div_ == 0) publishShape(utime, true);
}

void ShaftOutputs::publishStep(std::int64_t utime) {
  publishCage(utime);
  publishEstimate(utime, false);
  const double rate = ctx_.cfg.service.shape_rate;
  const double t = core_.modelTime();
  if (rate > 0.0 && t - last_shape_t_ >= 1.0 / rate - 1e-9) {
    last_shape_t_ = t;
    publishShape(utime, false);
  }
}

void ShaftOutputs::publishCage(std::int64_t utime, bool batch) {
  cage_msg_.utime = utime;
  cage_msg_.seq = cage_seq_++;
  toCageMessage(core_.output(), cage_msg_);
  encodeAndPublish(ctx_.ch.cage, cage_msg_, cage_buf_, batch);
}

void ShaftOutputs::publishEstimate(std::int64_t utime, bool batch) {
  const LoadEstimate* e = core_.estimate();
  if (!e) return;  // [estimator] disabled, or not stepped since the last refused step
  estimate_msg_.utime = utime;
  estimate_msg_.seq = estimate_seq_++;
  const EstimatorCounters& c = *core_.estimatorCounters();
  const double wall = ctx_.wallNow();
  const InputStats& st = inputs_;
  toEstimateMessage(*e, c, core_.publishedTime(e->t), st.last_imu_wall < 0.0 ? -1.0 : wall - st.last_imu_wall,
                    st.last_rope_wall < 0.0 ? -1.0 : wall - st.last_rope_wall, core_.estimateGate(),
                    core_.modelTime(), core_.calibrating(), estimate_msg_);
  estimate_msg_.detect_trip = detect_.trip;
  estimate_msg_.loss30_separation = detect_.loss30_separation;
  estimate_msg_.loss30_visible = detect_.loss30_visible;
  encodeAndPublish(ctx_.ch.estimate, estimate_msg_, estimate_buf_, batch);
  logGateEvents();
}

void ShaftOutputs::logGateEvents() {
  const EstimateGate& g = core_.estimateGate();
  const std::int64_t n = g.events();
  if (n - gate_seen_ > EstimateGate::kEvents) {
    ctx_.log.warn("{}{} estimate switch/load-change log lines lost (more than {} between two steps)", ctx_.tag,
                  n - gate_seen_ - EstimateGate::kEvents, EstimateGate::kEvents);
    gate_seen_ = n - EstimateGate::kEvents;
  }
  const double hold = ctx_.cfg.estimator.clear_hold;
  for (; gate_seen_ < n; ++gate_seen_) {
    const GateEvent& e = g.event(gate_seen_);
    const double t = core_.publishedTime(e.t);
    switch (e.type) {
      case GateEvent::Type::Switch:
        if (e.to_estimate)
          ctx_.log.info("{}alarms now judge the load estimate (t = {:.2f} s); an active alarm clears only after "
                        "{} s of it", ctx_.tag, t, hold);
        else
          ctx_.log.warn("{}alarms now judge the open-loop twin, not the load estimate (t = {:.2f} s): {}{}{}{}{}; "
                        "an active alarm clears only after {} s of it", ctx_.tag, t,
                        (e.not_used & kNotUsedNoSensors) ? "no sensor in use " : "",
                        (e.not_used & kNotUsedMismatch) ? "MODEL_MISMATCH " : "",
                        (e.not_used & kNotUsedImplausible) ? "estimate outside the physical bounds " : "",
                        (e.not_used & kNotUsedNonFinite) ? "non-finite estimate " : "",
                        (e.not_used & kNotUsedSensorFault) ? "sensor fault " : "", hold);
        break;
      case GateEvent::Type::LoadChange:
        ctx_.log.warn("{}load change detected (t = {:.2f} s): Fa {:.0f} -> {:.0f} N, M {:.0f} -> {:.0f} N m so far; "
                      "alarms hold their state for {} s", ctx_.tag, t, e.Fa0, e.Fa1, e.M0, e.M1, hold);
        break;
      case GateEvent::Type::LoadSettled:
        ctx_.log.info("{}load change held {} s (t = {:.2f} s): Fa {:.0f} -> {:.0f} N ({:+.0f} N), M {:.0f} -> {:.0f} "
                      "N m ({:+.0f} N m)", ctx_.tag, hold, t, e.Fa0, e.Fa1, e.Fa1 - e.Fa0, e.M0, e.M1, e.M1 - e.M0);
        break;
    }
  }
}

void ShaftOutputs::publishShape(std::int64_t utime, bool batch) {
  TwinCore& core = core_;
  core.evaluateShape();
  const GuideRopeEnvelope& sh = core.shape();
  shape_msg_.utime = utime;
  shape_msg_.t = core.output().t;
  shape_msg_.l = core.output().kin.l;
  for (int i = 0; i < shape_msg_.n; ++i) {
    shape_msg_.y1[i] = sh.y1()(i);
    shape_msg_.y2[i] = sh.y2()(i);
  }
  encodeAndPublish(ctx_.ch.guide_shape, shape_msg_, shape_buf_, batch);
}

void ShaftOutputs::publishAlarmEvents(const CommandCause& by) {
  TwinCore& core = core_;
  const AlarmEvents& ev = core.events();
  if (ev.empty()) return;
  const std::int64_t utime = bus::wallUtime();
  const AlarmCause& cause = cause_;
  AlarmTextContext tc;
  tc.alarms = &ctx_.cfg.alarms;
  tc.stale_timeout = core.staleTimeout();
  tc.range = core.validRange();
  tc.fault_what = core.lastFaultWhat();
  tc.requested_shelve = by.requested_shelve;
  tc.predicted_clearance_scenario = cause.predicted_clearance_scenario;
  tc.predicted_slack_scenario = cause.predicted_slack_scenario;
  tc.slack_threshold = cause.slack_threshold;
  if (const LoadEstimate* est = core.estimate())
    tc.mismatch_test = est->nis_exceeded    ? "nis"
                       : est->drift_exceeded ? "drift"
                       : core.preloadMismatch() ? "preload"
                                                : "";
  tc.sensor = core.lastSensorFault().sensor;
  tc.sensor_reason = core.lastSensorFault().reason;
  tc.preload_text = cause.preload_text.data();
  tc.fingerprint_text = cause.fingerprint_text.data();
  tc.preload_verdict_text = cause.preload_verdict_text.data();
  alarm_msg_.user.assign(by.user.data(), by.user.size());  // who caused these events ("" for the twin itself)
  RtLog& log = ctx_.log;
  const std::string& tag = ctx_.tag;
  for (const AlarmEvent& e : ev) {
    describeAlarm(e, tc, text_, sizeof text_);
    alarm_msg_.utime = utime;
    alarm_msg_.id = alarm_id_++;
    alarm_msg_.t = core.publishedTime(e.t);  // one time origin with HOIST_CAGE.t
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
    alarm_msg_.from_estimate = e.from_estimate;
    alarm_msg_.message.assign(text_);
    if (encodeAndPublish(ctx_.ch.alarm, alarm_msg_, alarm_buf_)) ++stats_.alarm_events;
    switch (e.type) {
      case AlarmEventType::Reannounce: log.debug("{}alarm: {} (t = {:.2f} s)", tag, text_, alarm_msg_.t); break;
      case AlarmEventType::Raise:
        if (e.level == AlarmLevel::Critical) log.error("{}ALARM {} (t = {:.2f} s)", tag, text_, alarm_msg_.t);
        else log.warn("{}ALARM {} (t = {:.2f} s)", tag, text_, alarm_msg_.t);
        break;
      default:
        if (!by.user.empty()) log.info("{}alarm: {} (t = {:.2f} s, by '{}')", tag, text_, alarm_msg_.t, by.user);
        else log.info("{}alarm: {} (t = {:.2f} s)", tag, text_, alarm_msg_.t);
        break;
    }
  }
  if (ev.dropped() > 0) log.error("{}{} alarm events dropped (event buffer full)", tag, ev.dropped());
  core.clearEvents();
}

void ShaftOutputs::publishForecast(const ForecastResult& r) {
  forecast_t& m = forecast_msg_;
  m.utime = r.utime;
  m.seq = forecast_seq_++;
  m.t_start = r.t_published;
  m.l = r.kin.l;
  m.v = r.kin.v;
  m.a = r.kin.a;
  m.plan_seq = r.plan_seq;
  m.from_estimate = r.from_estimate;
  m.Fa = r.Fa;
  m.moment = r.moment;
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
  encodeAndPublish(ctx_.ch.forecast, m, forecast_buf_);
}

void ShaftOutputs::publishHealth() { encodeAndPublish(ctx_.ch.health, health_msg_, health_buf_); }

}  // namespace hoist::service::app
