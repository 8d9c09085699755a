// The pure parts of hoist-twind's LCM shell: see hoist/service/lcm/messages.hpp.
#include "hoist/service/lcm/messages.hpp"
#include "hoist/bus/lcm_util.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace hoist::service::inline lcm {

void toCageMessage(const CageOutput& o, hoist::cage_state_t& m) {
  m.input_seq = o.input_seq;
  m.t = o.t;
  m.l = o.kin.l;
  m.v = o.kin.v;
  m.a = o.kin.a;
  m.x_c = o.x_c;
  m.y_c = o.y_c;
  m.theta = o.theta;
  for (int i = 0; i < 5; ++i) m.lambdas[i] = o.lambda[static_cast<std::size_t>(i)];
  m.y_top = o.clearance.y_top;
  m.y_bottom = o.clearance.y_bottom;
  m.guide_deflection = o.clearance.guide_deflection;
  m.clearance_pos_y = o.clearance.clearance_pos;
  m.clearance_neg_y = o.clearance.clearance_neg;
  m.clearance_guide = o.clearance.clearance_guide;
  m.min_clearance = o.clearance.min_clearance;
  m.alarm_level = static_cast<int8_t>(o.alarm_level);
  m.degraded = o.degraded;
  m.rope_slack_threshold = o.rope_slack_threshold;
  m.rope_overload_threshold = o.rope_overload_threshold;
}

void toEstimateMessage(const LoadEstimate& e, const EstimatorCounters& c, double t, double imu_age,
                       double rope_load_age, const EstimateGate& gate, double model_t, bool calibrating,
                       hoist::estimate_t& m) {
  m.in_use = gate.inUse();
  m.not_used = static_cast<int32_t>(gate.notUsed());
  m.holding = gate.holding(model_t);
  m.use_switches = gate.switches();
  m.load_change_Fa = gate.lastChangeFa();
  m.load_change_moment = gate.lastChangeM();
  m.calibrating = calibrating;
  m.t = t;
  m.l = e.kin.l;
  m.v = e.kin.v;
  m.a = e.kin.a;
  // estimate_t's contract: a sigma < 0 means not observed (the filter's
  // prior sigma of an unobserved load is no measurement uncertainty).
  m.Fa = e.Fa;
  m.sigma_Fa = e.fa_observed ? e.sigma_Fa : -1.0;
  m.b = e.b;
  m.sigma_b = e.fa_observed && e.moment_observed ? e.sigma_b : -1.0;
  m.moment = e.moment;
  m.sigma_moment = e.moment_observed ? e.sigma_moment : -1.0;
  m.x_c = e.x_c;
  m.sigma_x_c = e.sigma_x_c;
  m.y_c = e.y_c;
  m.sigma_y_c = e.sigma_y_c;
  m.theta = e.theta;
  m.sigma_theta = e.sigma_theta;
  m.theta_open = e.theta_open;
  for (int i = 0; i < 5; ++i) {
    m.lambdas[i] = e.lambda[static_cast<std::size_t>(i)];
    m.sigma_lambdas[i] = e.sigma_lambda[static_cast<std::size_t>(i)];
  }
  m.nis = e.nis;
  m.nis_window = e.nis_window;
  m.nis_dof = e.nis_dof;
  m.nis_lower = e.nis_lower;
  m.nis_upper = e.nis_upper;
  m.nis_bound = e.nis_bound;
  m.drift = e.drift;
  // The estimator's own tests, or the trip-end preload test (TwinCore::
  // setPreloadVerdict), which keeps the estimate out of the alarms as they do.
  m.mismatch = e.mismatch || (gate.notUsed() & kNotUsedMismatch) != 0;
  m.nis_exceeded = e.nis_exceeded;
  m.drift_exceeded = e.drift_exceeded;
  m.sensors = static_cast<int32_t>(e.sensors);
  m.imu_age = imu_age;
  m.rope_load_age = rope_load_age;
  m.fa_observed = e.fa_observed;
  m.moment_observed = e.moment_observed;
  m.accepted = c.accepted;
  m.gated = c.gated;
  m.load_changes = c.load_changes;
  m.implausible = c.implausible;
}

namespace {

void describeAlarmWhole(const AlarmEvent& e, const AlarmTextContext& ctx, char* buf, std::size_t n);

}  // namespace

void describeAlarm(const AlarmEvent& e, const AlarmTextContext& ctx, char* buf, std::size_t n) {
  if (n == 0) return;
  char whole[1024];  // every text fits (the longest is about 400 bytes)
  describeAlarmWhole(e, ctx, whole, sizeof whole);
  const std::size_t len = std::strlen(whole);
  if (len < n) {
    std::memcpy(buf, whole, len + 1);
    return;
  }
  // Cut at a word: the last space that leaves room for "...".
  static constexpr char kMore[] = "...";
  std::size_t cut = n > sizeof kMore ? n - sizeof kMore : 0;
  while (cut > 0 && whole[cut] != ' ') --cut;
  if (cut == 0) cut = n > sizeof kMore ? n - sizeof kMore : 0;  // one long word: cut in it
  while (cut > 0 && whole[cut - 1] == ' ') --cut;
  std::memcpy(buf, whole, cut);
  std::size_t k = cut;
  for (std::size_t i = 0; kMore[i] != '\0' && k + 1 < n; ++i) buf[k++] = kMore[i];
  buf[k] = '\0';
}

namespace {

void describeAlarmWhole(const AlarmEvent& e, const AlarmTextContext& ctx, char* buf, std::size_t n) {
  buf[0] = '\0';
  const char* verb = "";
  switch (e.type) {
    case AlarmEventType::Raise: verb = "raised"; break;
    case AlarmEventType::Clear: verb = "cleared"; break;
    case AlarmEventType::Ack: verb = "acknowledged"; break;
    case AlarmEventType::Shelve: verb = "shelved"; break;
    case AlarmEventType::Unshelve: verb = "unshelved"; break;
    case AlarmEventType::Reannounce: verb = "still active"; break;
  }
  char state[96];
  char shelve[128];
  if (e.type == AlarmEventType::Shelve) {
    // The verb states the effective duration, and the clamp if there was one.
    const double limit = ctx.alarms ? ctx.alarms->max_shelve : 0.0;
    if (limit > 0.0 && ctx.requested_shelve > limit)
      std::snprintf(shelve, sizeof shelve, "shelved for %.0f s (requested %g s, clamped to max_shelve = %g s)",
                    e.shelved_for, ctx.requested_shelve, limit);
    else
      std::snprintf(shelve, sizeof shelve, "shelved for %.0f s", e.shelved_for);
    verb = shelve;
  }
  std::snprintf(state, sizeof state, "%s%s%s%s", e.from_estimate ? " [from the load estimate]" : "",
                e.latched ? " [latched until acknowledged]" : "", e.shelved ? " [shelved]" : "",
                (e.active && !e.acked) ? " [unacknowledged]" : "");
  const char* kind = toString(e.kind);
  const char* level = toString(e.level);
  switch (e.kind) {
    case AlarmKind::CagePosY:
    case AlarmKind::CageNegY:
    case AlarmKind::GuideRope: {
      const AlarmConfig dflt{};
      const AlarmConfig& cfg = ctx.alarms ? *ctx.alarms : dflt;
      const bool guide = e.kind == AlarmKind::GuideRope;
      const double gap = e.kind == AlarmKind::CagePosY   ? cfg.gap_pos_y
                         : e.kind == AlarmKind::CageNegY ? cfg.gap_neg_y
                                                         : cfg.guide_rope_gap;
      std::snprintf(buf, n, "%s %s %s: %s %.1f mm (threshold %.1f mm of gap %.1f mm, clearance %.1f mm)%s",
                    kind, level, verb,
                    guide ? "guide-rope deflection"
                          : (e.kind == AlarmKind::CagePosY ? "cage excursion toward +y" : "cage excursion toward -y"),
                    e.value * 1e3, e.threshold * 1e3, gap * 1e3, (gap - e.value) * 1e3, state);
      break;
    }
    case AlarmKind::InputStale:
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: winder input is back%s", kind, level, state);
      else
        std::snprintf(buf, n, "%s %s %s: no valid winder input for more than %.3g s; outputs degraded (l held, v = a = 0)%s",
                      kind, level, verb, ctx.stale_timeout, state);
      break;
    case AlarmKind::ModelFault:
      if (std::strcmp(ctx.fault_what, "non-finite") == 0 || ctx.fault_what[0] == '\0')
        std::snprintf(buf, n, "%s %s %s: non-finite model state, model re-initialized at static equilibrium%s",
                      kind, level, verb, state);
      else
        std::snprintf(buf, n, "%s %s %s: implausible model state, %s = %.4g beyond the plausibility bound %.4g; "
                      "model re-initialized at static equilibrium%s",
                      kind, level, verb, ctx.fault_what, e.value, e.threshold, state);
      break;
    case AlarmKind::ModelDomain:
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: rope length back inside the model's valid range [%.3f, %.3f] m%s",
                      kind, level, ctx.range.lo, ctx.range.hi, state);
      else
        std::snprintf(buf, n, "%s %s %s: rope length %.3f m outside the model's valid range [%.3f, %.3f] m "
                      "(limit %.3f m); holding the last valid state, outputs degraded%s",
                      kind, level, verb, e.value, ctx.range.lo, ctx.range.hi, e.threshold, state);
      break;
    case AlarmKind::RopeSlack:
    case AlarmKind::RopeOverload: {
      const AlarmConfig dflt{};
      const AlarmConfig& cfg = ctx.alarms ? *ctx.alarms : dflt;
      const bool slack = e.kind == AlarmKind::RopeSlack;
      const double frac = slack ? cfg.slack_fraction : cfg.overload_fraction;
      std::snprintf(buf, n, "%s %s %s: hoisting-rope force lambda_0 %.0f N %s threshold %.0f N (%.3g x the static "
                    "rope force %.0f N)%s",
                    kind, level, verb, e.value, slack ? (e.value <= e.threshold ? "at or below" : "above")
                                                      : (e.value >= e.threshold ? "at or above" : "below"),
                    e.threshold, frac, frac > 0.0 ? e.threshold / frac : 0.0, state);
      break;
    }
    case AlarmKind::DuplicatePublisher:
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: no other publisher seen on this twin's output channels%s", kind,
                      level, state);
      else
        std::snprintf(buf, n, "%s %s %s: another process (instance %.0f) publishes on this twin's output "
                      "channels; its states interleave with ours (same channel_prefix twice?)%s",
                      kind, level, verb, e.value, state);
      break;
    case AlarmKind::PredictedClearance:
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: no forecast scenario crosses the CRITICAL clearance threshold within "
                      "the horizon%s", kind, level, state);
      else
        std::snprintf(buf, n, "%s %s %s: forecast scenario '%s' crosses the CRITICAL clearance threshold in %.1f s "
                      "(horizon %.0f s)%s",
                      kind, level, verb, ctx.predicted_clearance_scenario, e.value, e.threshold, state);
      break;
    case AlarmKind::ModelMismatch:
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: the shaft behaves like its model again%s", kind, level, state);
      else if (std::strcmp(ctx.mismatch_test, "nis") == 0)
        std::snprintf(buf, n, "%s %s %s: the shaft does not behave like its model: the estimator's windowed NIS "
                      "%.4g exceeds its bound %.4g; check guide-rope preloads, sleeves and the sensors%s",
                      kind, level, verb, e.value, e.threshold, state);
      else if (std::strcmp(ctx.mismatch_test, "drift") == 0)
        std::snprintf(buf, n, "%s %s %s: the shaft does not behave like its model: the estimated load drifted "
                      "%.3g sigma during the trip (bound %.3g); check the load, guide-rope preloads and the "
                      "sensors%s",
                      kind, level, verb, e.value, e.threshold, state);
      else if (std::strcmp(ctx.mismatch_test, "preload") == 0)
        std::snprintf(buf, n, "%s %s %s: %s%s", kind, level, verb, ctx.preload_verdict_text, state);
      else
        std::snprintf(buf, n, "%s %s %s: the shaft does not behave like its model (statistic %.4g, bound %.4g: "
                      "the windowed NIS or the load drift, see HOIST_ESTIMATE)%s",
                      kind, level, verb, e.value, e.threshold, state);
      break;
    case AlarmKind::SensorFault:
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: no sensor refused or disbelieved for %g s%s", kind, level,
                      TwinCore::kSensorFaultHold, state);
      else if (ctx.sensor_reason == SensorFaultReason::ClockOffset)
        std::snprintf(buf, n, "%s %s %s: %s: its clock is %+.3f s from the daemon's (sensors.max_clock_offset = "
                      "%g s); its samples are refused, the estimate goes on without them%s",
                      kind, level, verb, toString(ctx.sensor), e.value, e.threshold, state);
      else if (ctx.sensor_reason == SensorFaultReason::TimeBackwards)
        std::snprintf(buf, n, "%s %s %s: %s: a sample's utime went backwards (a replay, or the sensor's clock "
                      "stepped back); refused and counted (HOIST_HEALTH.sensor_time_backwards)%s",
                      kind, level, verb, toString(ctx.sensor), state);
      else if (ctx.sensor_reason == SensorFaultReason::Implausible)
        std::snprintf(buf, n, "%s %s %s: %s is implausible (%.4g beyond the physical bound %.4g): a sensor "
                      "lies or fails; the alarms judge the open-loop twin%s",
                      kind, level, verb, toString(ctx.sensor), e.value, e.threshold, state);
      else
        std::snprintf(buf, n, "%s %s %s: %s is %s (%s; its noise %.3g against the datasheet's %.3g): a sensor "
                      "that fails or lies; the alarms judge the open-loop twin%s",
                      kind, level, verb, toString(ctx.sensor), toString(ctx.sensor_reason),
                      ctx.sensor_reason == SensorFaultReason::Quiet   ? "far quieter than its own noise: flat, zeroed "
                                                                        "or held"
                      : ctx.sensor_reason == SensorFaultReason::Stuck ? "the very same value repeated"
                      : ctx.sensor_reason == SensorFaultReason::Noisy ? "far noisier than its datasheet"
                                                                      : "most of its samples contradict the model",
                      e.value, e.threshold, state);
      break;
    case AlarmKind::PredictedSlack:
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: no forecast scenario brings the hoisting-rope force below the slack "
                      "threshold within the horizon%s", kind, level, state);
      else
        std::snprintf(buf, n, "%s %s %s: forecast scenario '%s' brings the hoisting-rope force lambda_0 below the "
                      "slack threshold %.0f N within %.1f s (horizon %.0f s)%s",
                      kind, level, verb, ctx.predicted_slack_scenario, ctx.slack_threshold, e.value, e.threshold,
                      state);
      break;
    case AlarmKind::GuidePreloadLow:
      // The trend's own text names the estimate, its sigma and the trips.
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: the guide-rope preload's 95 %% upper bound %.3f is back above %.2f: "
                      "%s%s", kind, level, e.value, e.threshold, ctx.preload_text, state);
      else
        std::snprintf(buf, n, "%s %s %s: %s%s", kind, level, verb, ctx.preload_text, state);
      break;
    case AlarmKind::ShaftFingerprint:
      if (e.type == AlarmEventType::Clear)
        std::snprintf(buf, n, "%s %s cleared: %s%s", kind, level, ctx.fingerprint_text, state);
      else
        std::snprintf(buf, n, "%s %s %s: %s%s", kind, level, verb, ctx.fingerprint_text, state);
      break;
  }
}

}  // namespace

std::optional<AckCommand> validateAck(const hoist::alarm_ack_t& ack, const char*& why) {
  AckCommand c;
  switch (validateAlarmCommand(ack.kind, ack.level, ack.action, ack.shelve_duration, ack.known_fa, ack.known_b,
                               ack.calibrate_duration, ack.preload_scale, c)) {
    case CommandError::None: return c;
    case CommandError::UnknownKind: why = "unknown alarm kind"; break;
    case CommandError::BadLevel: why = "bad level (0 both, 1 warning, 2 critical)"; break;
    case CommandError::BadAction:
      why = "bad action (1 ack, 2 shelve, 3 unshelve, 4 re-announce, 5 calibrate, 6 adopt preload)";
      break;
    case CommandError::BadShelveDuration: why = "shelve_duration must be a finite number > 0 s"; break;
    case CommandError::BadCalibration:
      why = contract::kCalibrationRule;
      break;
    case CommandError::BadPreload: why = contract::kPreloadRule; break;
  }
  return std::nullopt;
}

std::string regexEscape(const std::string& name) { return bus::regexEscape(name); }

}  // namespace hoist::service::lcm
