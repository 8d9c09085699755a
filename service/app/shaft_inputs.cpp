// The inputs of one shaft: see shaft_inputs.hpp.
#include "shaft_inputs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "forecast_scheduler.hpp"
#include "offset_keeper.hpp"
#include "preload_keeper.hpp"
#include "trip_room.hpp"
#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/contract/alarm_command.hpp"
#include "hoist/service/lcm/messages.hpp"
#include "hoist/service/lcm/winder_decode.hpp"

namespace hoist::service::inline app {

using std::chrono::duration;

ShaftInputs::ShaftInputs(const ShaftContext& ctx, TwinCore& core, InputStats& stats, const ShaftPeers& peers,
                         ::lcm::LCM& in, ShaftOutputs& out, ForecastScheduler* forecast)
    : ctx_(ctx), core_(core), stats_(stats), peers_(peers), in_(in), out_(out), forecast_(forecast) {
  log_limit_.setLimit(ctx_.cfg.service.log_rate_limit);
  decode_budget_ = std::max(kMinDecodesPerTick, static_cast<int>(kDecodesPerSecond / ctx_.cfg.service.rate));
  routes_[kWinder] = {this, &ctx_.ch.winder, &ShaftInputs::handleWinder, bus::kChannelWinder.data()};
  routes_[kAck] = {this, &ctx_.ch.alarm_ack, &ShaftInputs::handleAck, bus::kChannelAlarmAck.data()};
  routes_[kTripPlan] = {this, &ctx_.ch.trip_plan, &ShaftInputs::handleTripPlan, bus::kChannelTripPlan.data()};
  routes_[kOwnHealth] = {this, &ctx_.ch.health, &ShaftInputs::handleOwnHealth, bus::kChannelHealth.data()};
  routes_[kOwnAlarm] = {this, &ctx_.ch.alarm, &ShaftInputs::handleOwnAlarm, bus::kChannelAlarm.data()};
  routes_[kCageImu] = {this, &ctx_.ch.cage_imu, &ShaftInputs::handleCageImu, bus::kChannelCageImu.data()};
  routes_[kRopeLoad] = {this, &ctx_.ch.rope_load, &ShaftInputs::handleRopeLoad, bus::kChannelRopeLoad.data()};
  text_[0] = '\0';
}

void ShaftInputs::Route::onMessage(const ::lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  try {
    (self->*handle)(rbuf);
  } catch (const std::exception& e) {
    self->handlerFailed(e.what(), name);
  } catch (...) {
    self->handlerFailed("unknown exception", name);
  }
}

void ShaftInputs::add(bus::InputRouter* router, Route& r) {
  if (router) {
    router->add(*r.channel, [&r](const ::lcm::ReceiveBuffer* rb, const std::string& c) { r.onMessage(rb, c); });
    return;
  }
  // ::lcm::subscribe takes a regular expression: subscribe to the literal
  // names (a prefix "mine.1/" must not match "mineX1/").
  in_.subscribe(regexEscape(*r.channel), &Route::onMessage, &r);
}

void ShaftInputs::subscribe(bus::InputRouter* router, bool own_health) {
  // Our own health channel too: another publisher there (by instance_id) is
  // a second twin on our outputs.  Here when outputs share the input URL;
  // else the daemon watches the output URL (watchOwnOutputs).
  add(router, routes_[kWinder]);
  add(router, routes_[kAck]);
  if (forecast_) add(router, routes_[kTripPlan]);
  if (own_health) {
    add(router, routes_[kOwnHealth]);
    add(router, routes_[kOwnAlarm]);
  }
  if (core_.estimatorEnabled()) {
    add(router, routes_[kCageImu]);
    add(router, routes_[kRopeLoad]);
  }
}

void ShaftInputs::watchOwnOutputs(bus::InputRouter* router) {
  add(router, routes_[kOwnHealth]);
  add(router, routes_[kOwnAlarm]);
}

void ShaftInputs::forgetSilentPublisher(double wall) {
  if (other_seen_wall_ >= 0.0 && wall - other_seen_wall_ > 3.0 / ctx_.cfg.service.health_rate) {
    other_seen_wall_ = -1.0;
    core_.setDuplicatePublisher(false, 0.0);
  }
}

// ---- logging -------------------------------------------------------------------

void ShaftInputs::logReject(RejectReason r, const char* detail) {
  std::int64_t suppressed = 0;
  if (!log_limit_.allow(static_cast<int>(r), ctx_.wallNow(), suppressed)) return;
  if (suppressed > 0)
    ctx_.log.warn("{}rejected winder input ({}): {} [{} similar suppressed]", ctx_.tag, toString(r), detail,
                  suppressed);
  else
    ctx_.log.warn("{}rejected winder input ({}): {}", ctx_.tag, toString(r), detail);
}

void ShaftInputs::handlerFailed(const char* what, const char* channel) {
  ++stats_.handler_exceptions;
  std::int64_t suppressed = 0;
  if (log_limit_.allow(kLogHandlerException, ctx_.wallNow(), suppressed))
    ctx_.log.error("{}exception in the {} handler caught (message dropped): {} [{} similar suppressed]", ctx_.tag,
                   channel, what, suppressed);
}

void ShaftInputs::logJunk(const std::string& what) {
  std::int64_t suppressed = 0;
  if (!log_limit_.allow(kLogJunkCommand, ctx_.wallNow(), suppressed)) return;
  if (suppressed > 0) ctx_.log.warn("{}{} junk alarm-command log lines suppressed", ctx_.tag, suppressed);
  ctx_.log.warn("{}{}", ctx_.tag, what);
}

void ShaftInputs::rejectPlan(PlanReject r, const char* detail) {
  ++stats_.plan_rejects[static_cast<std::size_t>(r)];
  std::int64_t suppressed = 0;
  if (!log_limit_.allow(kLogPlan, ctx_.wallNow(), suppressed)) return;
  ctx_.log.warn("{}rejected trip plan ({}): {} [{} similar suppressed]", ctx_.tag, toString(r), detail, suppressed);
}

// ---- HOIST_WINDER ----------------------------------------------------------------

void ShaftInputs::handleWinder(const ::lcm::ReceiveBuffer* rbuf) {
  TwinCore& core = core_;
  const double wall = ctx_.wallNow();
  WinderSample s;
  const WinderDecode dec = decodeWinder(rbuf->data, rbuf->data_size, winder_in_, s);
  if (dec != WinderDecode::Ok) {
    core.rejectUndecodable();
    std::snprintf(text_, sizeof text_, "%u bytes: %s", static_cast<unsigned>(rbuf->data_size), describe(dec));
    logReject(RejectReason::Decode, text_);
    return;
  }

  const auto t0 = ShaftContext::Clock::now();
  const InputResult res = core.onInput(s, wall);
  const auto t1 = ShaftContext::Clock::now();
  if (!res.accepted) {
    std::snprintf(text_, sizeof text_, "seq %lld utime %lld v %g a %g%s%g",
                  static_cast<long long>(s.seq), static_cast<long long>(s.utime), s.v, s.a,
                  s.has_length ? " length " : " (no length) ", s.has_length ? s.length : 0.0);
    logReject(res.reason, text_);
  }
  if (res.reinitialized)
    ctx_.log.info("{}new winder stream (seq {}): model re-initialized at l = {} m{}", ctx_.tag, s.seq,
                  s.has_length ? s.length : core.output().kin.l,
                  core.startPending() ? " (at the next tick within the start budget)" : "");
  if (res.republish) out_.publishCage(s.utime);  // the held state, flagged degraded
  if (res.stepped) {
    stats_.step.add(duration<double, std::micro>(t1 - t0).count());
    out_.publishStep(s.utime);
    if (forecast_) forecast_->afterStep(s.utime);
    if (peers_.offsets) peers_.offsets->afterTick(core);
    if (peers_.trips) peers_.trips->afterStep(core, s.utime);
  }
  out_.publishAlarmEvents();
}

// ---- HOIST_ALARM_ACK -------------------------------------------------------------

void ShaftInputs::handleAck(const ::lcm::ReceiveBuffer* rbuf) {
  // Operator commands are rare and outside the tick: decoding them into the
  // message's std::strings may allocate.  Anyone on the group can send
  // commands (docs/security.md), so junk must never take a genuine
  // command's place:
  //   * decoding is bounded on its own, at decode_budget_ datagrams per tick
  //     (200 000 a second, at least 256 per tick); beyond it a datagram is
  //     dropped undecoded and counted;
  //   * only a VALID command counts against max_commands_per_tick: undecodable
  //     or invalid ones cost their decode and are counted in commands_invalid;
  //   * junk is logged under a rate limit; every EFFECTIVE command is audited
  //     (log line and the HOIST_ALARM events it causes carry the user) and
  //     never rate-limited.
  InputStats& st = stats_;
  if (++decodes_this_tick_ > decode_budget_) {
    ++st.commands_dropped;
    ++st.command_decodes_dropped;
    logJunk(fmt::format("alarm command dropped undecoded: more than {} command datagrams this tick", decode_budget_));
    return;
  }
  hoist::alarm_ack_t ack;
  const auto size = static_cast<std::size_t>(rbuf->data_size);
  // Every length is validated before anything is decoded (a 37-byte command
  // with a string length of 0 or 0x80000000 used to kill the daemon).
  if (const auto dst = hoist::msg::checkedDecode(rbuf->data, size, ack); dst != hoist::msg::DecodeStatus::ok) {
    ++st.command_decode_rejects;
    ++st.commands_invalid;
    logJunk(fmt::format("ignored undecodable alarm command ({} bytes, {})", size, hoist::msg::toString(dst)));
    return;
  }
  const std::string user = printable(ack.user, kUserMax);
  const char* why = "";
  const std::optional<AckCommand> cmd = validateAck(ack, why);
  if (!cmd) {
    ++st.commands_invalid;
    logJunk(fmt::format("ignored alarm command from '{}' (kind '{}'): {}", user, printable(ack.kind), why));
    return;
  }
  if (cmd->action == AlarmAction::Reannounce) {
    // Changes no state: outside the command budget, rate-limited on its own.
    requestReannounce(cmd->kind, cmd->level, user);
    return;
  }
  const int budget = ctx_.cfg.service.max_commands_per_tick;
  if (++commands_this_tick_ > budget) {
    ++st.commands_dropped;
    logJunk(fmt::format("alarm command from '{}' dropped: more than service.max_commands_per_tick = {} valid "
                        "commands this tick", user, budget));
    return;
  }
  if (cmd->action == AlarmAction::Calibrate) {
    calibrate(*cmd, user);
    return;
  }
  if (cmd->action == AlarmAction::AdoptPreload) {
    adoptPreload(*cmd, user, bus::wallUtime());  // the daemon's clock, not the sender's
    return;
  }
  const int n = core_.command(cmd->action, cmd->kind, cmd->level, cmd->shelve_duration);
  const char* what = cmd->action == AlarmAction::Ack      ? "acknowledge"
                     : cmd->action == AlarmAction::Shelve ? "shelve"
                                                          : "unshelve";
  if (n == 0) {
    // Not effective (nothing to acknowledge, already shelved, ...): no
    // state changed, so no event and no audit line (a flood of identical
    // commands stays silent).
    logJunk(fmt::format("alarm command from '{}' had no effect: {} {}", user, what,
                        cmd->kind ? toString(*cmd->kind) : "*"));
    return;
  }
  ++st.commands_applied;
  char for_s[96] = "";
  if (cmd->action == AlarmAction::Shelve) {
    const double eff = std::min(cmd->shelve_duration, ctx_.cfg.alarms.max_shelve);
    if (eff < cmd->shelve_duration)
      std::snprintf(for_s, sizeof for_s, " for %g s (requested %g s, clamped to max_shelve)", eff,
                    cmd->shelve_duration);
    else
      std::snprintf(for_s, sizeof for_s, " for %g s", eff);
  }
  ctx_.log.info("{}AUDIT operator '{}': {} {}/{}{} -> {} alarm(s)", ctx_.tag, user, what,
                cmd->kind ? toString(*cmd->kind) : "*", cmd->level == AlarmLevel::None ? "*" : toString(cmd->level),
                for_s, n);
  out_.publishAlarmEvents(CommandCause{user, cmd->action == AlarmAction::Shelve ? cmd->shelve_duration : 0.0});
}

void ShaftInputs::calibrate(const AlarmCommand& cmd, const std::string& user) {
  // The live calibration: no alarm changes; audited as an effective command.
  if (!core_.calibrate(cmd.known_fa, cmd.known_b, cmd.calibrate_duration)) {
    logJunk(fmt::format("calibration from '{}' ignored: [estimator] is not enabled", user));
    return;
  }
  ++stats_.commands_applied;
  ctx_.log.info("{}AUDIT operator '{}': calibrate: the load is known, Fa = {} N at b = {} m (M = {} N m), for {} s "
                "from t = {:.2f} s", ctx_.tag, user, cmd.known_fa, cmd.known_b, cmd.known_fa * cmd.known_b,
                cmd.calibrate_duration, core_.publishedTime(core_.modelTime()));
}

void ShaftInputs::adoptPreload(const AlarmCommand& cmd, const std::string& user, std::int64_t utime) {
  // A new model for the live twin: built and kept off the loop, swapped in
  // at rest (preload_keeper.hpp).  Audited now and again when in use.
  if (!peers_.preload) {
    logJunk(fmt::format("preload adoption from '{}' ignored: this twin is not hosted by the daemon", user));
    return;
  }
  if (!peers_.preload->request(cmd.preload_scale, user, utime)) {
    logJunk(fmt::format("preload adoption x{} from '{}' refused: an earlier adoption is still being built or waits "
                        "for the cage to rest", cmd.preload_scale, user));
    return;
  }
  ++stats_.commands_applied;
  ctx_.log.warn("{}AUDIT operator '{}': adopt the guide-rope preloads x{} (the live twin runs x{}); built off the "
                "loop, in use when the cage rests", ctx_.tag, user, cmd.preload_scale, core_.preloadScale());
}

void ShaftInputs::requestReannounce(std::optional<AlarmKind> kind, AlarmLevel level, const std::string& user) {
  InputStats& st = stats_;
  ++st.reannounce_requests;
  if (reannounce_pending_) {
    ++st.reannounce_merged;
    if (kind != reannounce_kind_) reannounce_kind_.reset();  // two different requests: everything
    if (level != reannounce_level_) reannounce_level_ = AlarmLevel::None;
    return;
  }
  reannounce_pending_ = true;
  reannounce_kind_ = kind;
  reannounce_level_ = level;
  std::int64_t suppressed = 0;
  if (log_limit_.allow(kLogReannounce, ctx_.wallNow(), suppressed))
    ctx_.log.info("{}'{}' asks for every alarm's current state: re-announced (at most once per {} s) [{} similar "
                  "suppressed]", ctx_.tag, user, kReannounceInterval, suppressed);
  serviceReannounce();
}

void ShaftInputs::serviceReannounce() {
  const double wall = ctx_.wallNow();
  if (reannounce_wall_ >= 0.0 && wall - reannounce_wall_ < kReannounceInterval) return;
  reannounce_pending_ = false;
  reannounce_wall_ = wall;
  ++stats_.reannounces;
  core_.command(AlarmAction::Reannounce, reannounce_kind_, reannounce_level_, 0.0);
  out_.publishAlarmEvents();
}

// ---- HOIST_TRIP_PLAN -------------------------------------------------------------

void ShaftInputs::handleTripPlan(const ::lcm::ReceiveBuffer* rbuf) {
  // Every byte is validated before anything is decoded (checked decoder);
  // trip_plan_t is flat (no string, no array): decoding allocates nothing.
  const auto size = static_cast<std::size_t>(rbuf->data_size);
  if (const auto dst = hoist::msg::checkedDecode(rbuf->data, size, plan_in_); dst != hoist::msg::DecodeStatus::ok) {
    std::snprintf(text_, sizeof text_, "%zu bytes: %s", size, hoist::msg::toString(dst));
    rejectPlan(PlanReject::Decode, text_);
    return;
  }
  const trip_plan_t& m = plan_in_;
  const double t = core_.modelTime();
  const double timeout = ctx_.cfg.forecast.plan_timeout;
  // The sequence rule is per sender (hoist/service/core/plan_senders.hpp): another
  // sender's seq, however large, never makes this sender's plans old.
  std::int64_t last_seq = 0;
  double last_t = 0.0;
  if (plan_senders_.isOld(m.sender_id, m.seq, t, timeout, last_seq, last_t)) {
    std::snprintf(text_, sizeof text_, "seq %lld from sender %lld is not newer than that sender's last accepted "
                  "plan (seq %lld, %.1f s ago; any seq is accepted again once it is forecast.plan_timeout = %g s "
                  "old)",
                  static_cast<long long>(m.seq), static_cast<long long>(m.sender_id),
                  static_cast<long long>(last_seq), std::fabs(t - last_t), timeout);
    rejectPlan(PlanReject::OldSeq, text_);
    return;
  }
  const TripPlan p{m.target_length, m.vmax, m.amax, m.jerk};
  const CageOutput& o = core_.output();
  const PlanCheck pc = checkPlan(p, core_.modelTime(), o.kin, ctx_.cfg.shaft, plan_scratch_);
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
  // Physically plausible: within the winder's own limits (a plan with a jerk
  // of 1e6 would forecast forces the shaft never sees, marked OK).
  const ForecastConfig& fc = ctx_.cfg.forecast;
  if (m.vmax > fc.vmax || m.amax > fc.amax || m.jerk > fc.jerk) {
    std::snprintf(text_, sizeof text_, "seq %lld vmax %g amax %g jerk %g beyond the winder's limits "
                  "(forecast.vmax %g m/s, amax %g m/s^2, jerk %g m/s^3)",
                  static_cast<long long>(m.seq), m.vmax, m.amax, m.jerk, fc.vmax, fc.amax, fc.jerk);
    rejectPlan(PlanReject::AboveLimits, text_);
    return;
  }
  ++stats_.plans_accepted;
  plan_senders_.accept(m.sender_id, m.seq, t, timeout);
  forecast_->hasPlan(t);  // expire (and log) the plan in force first
  const bool other_sender = plan_sender_ != m.sender_id;
  plan_sender_ = m.sender_id;
  if (forecast_->acceptPlan(p, m.seq, t) || other_sender) {
    // The first plan, or a plan from another sender than the last one's
    // (two controllers, or a forged sender): logged, rate-limited.
    std::int64_t suppressed = 0;
    if (log_limit_.allow(kLogPlan, ctx_.wallNow(), suppressed))
      ctx_.log.info("{}trip plan accepted (seq {} from sender {}): target {} m, vmax {} m/s, amax {} m/s^2, jerk {} "
                    "m/s^3 [{} similar suppressed]",
                    ctx_.tag, m.seq, m.sender_id, m.target_length, m.vmax, m.amax, m.jerk, suppressed);
  }
}

// ---- our own HOIST_HEALTH from another instance ------------------------------------

namespace {
/// Our own HOIST_HEALTH whose utime is this far from our clock [s] is a replay.
constexpr double kReplaySkew = 5.0;
}  // namespace

void ShaftInputs::handleOwnHealth(const ::lcm::ReceiveBuffer* rbuf) {
  // instance_id is the first field after utime: read it without decoding
  // the whole message (8-byte fingerprint, int64 utime, int64 instance_id).
  if (rbuf->data_size < 24) return;
  const auto* b = static_cast<const std::uint8_t*>(rbuf->data);
  std::int64_t fp = 0, id = 0;
  std::uint64_t ut = 0;
  for (int i = 0; i < 8; ++i) fp = (fp << 8) | b[i];
  for (int i = 8; i < 16; ++i) ut = (ut << 8) | b[i];
  for (int i = 16; i < 24; ++i) id = static_cast<std::int64_t>((static_cast<std::uint64_t>(id) << 8) | b[i]);
  if (fp != static_cast<std::int64_t>(hoist::health_t::getHash())) return;
  otherPublisher(id, ut, ctx_.ch.health);
}

namespace {
/// Big-endian integer of `n` bytes at `p`.
std::uint64_t readBe(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}
}  // namespace

void ShaftInputs::handleOwnAlarm(const ::lcm::ReceiveBuffer* rbuf) {
  // alarm_t's instance_id follows its strings: walk the encoding (no decode,
  // no allocation) -- fingerprint, utime, id, t (4 x 8), kind (int32 length
  // + bytes), level, event_type, active, acked, shelved, latched (6 x 1),
  // value, threshold, shelved_for (3 x 8), message, user (strings),
  // from_estimate (1), instance_id (8).  A message too short for that is not
  // a daemon's alarm event: ignored (clients refuse it as undecodable).
  const auto* b = static_cast<const std::uint8_t*>(rbuf->data);
  const std::size_t n = rbuf->data_size;
  if (n < 32 || readBe(b, 8) != static_cast<std::uint64_t>(hoist::alarm_t::getHash())) return;
  const std::uint64_t ut = readBe(b + 8, 8);
  std::size_t at = 32;
  const auto skipString = [&]() {
    if (at + 4 > n) return false;
    const std::uint64_t len = readBe(b + at, 4);
    if (len > n - at - 4) return false;
    at += 4 + static_cast<std::size_t>(len);
    return true;
  };
  if (!skipString()) return;
  at += 6 + 24;
  if (at > n || !skipString() || !skipString()) return;
  at += 1;
  if (at + 8 > n) return;
  // Our own events come back with an event id we have used; one with our
  // instance id and an event id we have not used yet is a forger's copy.
  const auto event_id = static_cast<std::int64_t>(readBe(b + 16, 8));
  const auto id = static_cast<std::int64_t>(readBe(b + at, 8));
  otherPublisher(id, ut, ctx_.ch.alarm, id == ctx_.instance_id && event_id >= out_.nextAlarmId());
}

void ShaftInputs::otherPublisher(std::int64_t id, std::uint64_t ut, const std::string& channel, bool unpublished) {
  // Our own instance id with a utime far from our clock is not us: a
  // recording of this twin played back (lcm-logplayer) beside it, which
  // would mix old and new states in every client.
  const double skew = static_cast<double>(static_cast<std::int64_t>(ut) - bus::wallUtime()) * 1e-6;
  const bool replayed = id == ctx_.instance_id && std::abs(skew) > kReplaySkew;
  if (id == ctx_.instance_id && !replayed && !unpublished) return;
  const double wall = ctx_.wallNow();
  if (!(other_seen_wall_ >= 0.0) || id != other_id_) {
    if (unpublished && !replayed)
      ctx_.log.error("{}an alarm event with this twin's instance id {} that it never published on {} (event id "
                     "beyond its last): somebody copies the instance id", ctx_.tag, id, channel);
    else if (replayed)
      ctx_.log.error("{}a recording of this twin is being played on {} (our instance {}, utime {:.0f} s from our "
                     "clock): replay beside a live twin on another LCM URL or channel prefix", ctx_.tag,
                     channel, id, skew);
    else
      ctx_.log.error("{}another publisher (instance {}) on {}: a second twin with the same channels, or a forger? "
                     "(this one is instance {})", ctx_.tag, id, channel, ctx_.instance_id);
  }
  other_id_ = id;
  other_seen_wall_ = wall;
  core_.setDuplicatePublisher(true, static_cast<double>(id));
  out_.publishAlarmEvents();
}

}  // namespace hoist::service::app
