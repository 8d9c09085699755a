// hoist/service/lcm/messages.hpp -- the pure parts of hoist-twind's LCM shell:
// TwinCore output -> LCM message mapping, alarm text, validation of operator
// commands (alarm_ack_t), channel-name handling.  No I/O, no clock; the
// mapping and the alarm text do not allocate (preallocated messages).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "hoist/contract/alarm_command.hpp"
#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/service/twin/twin_core.hpp"

namespace hoist::service::inline lcm {

/// Fill `m` (preallocated) from the twin's output; utime, seq and
/// instance_id are the caller's.
void toCageMessage(const CageOutput& o, hoist::cage_state_t& m);

/// Fill `m` from the load estimate (utime, seq and instance_id are the
/// caller's).  `t` is the published time; the ages are seconds since each
/// sensor's last accepted sample (< 0: never).  A value that is not observed
/// (sigma < 0) is published as 0 with sigma -1, never as NaN.  `gate`: whether
/// the alarms judge it (in_use, not_used, holding at model time `model_t`);
/// `calibrating`: a declared known load is in force.
void toEstimateMessage(const LoadEstimate& e, const EstimatorCounters& c, double t, double imu_age,
                       double rope_load_age, const EstimateGate& gate, double model_t, bool calibrating,
                       hoist::estimate_t& m);

/// What the alarm text needs besides the event.
struct AlarmTextContext {
  const AlarmConfig* alarms = nullptr;
  double stale_timeout = 0.0;      ///< [s] in force
  LengthRange range;               ///< the model's valid range (MODEL_DOMAIN)
  const char* fault_what = "";     ///< MODEL_FAULT: "non-finite" or the implausible quantity
  double requested_shelve = 0.0;   ///< SHELVE events: the duration the operator asked for [s]
  double published_t = 0.0;        ///< unused by the text; kept with the event
  /// PREDICTED_CLEARANCE / PREDICTED_SLACK: the scenario that predicts it
  /// ("estop", "continue"; static strings) and the slack threshold [N].
  const char* predicted_clearance_scenario = "";
  const char* predicted_slack_scenario = "";
  double slack_threshold = 0.0;
  /// MODEL_MISMATCH: which test fired ("nis": the windowed NIS over its
  /// bound; "drift": a load drifting beyond drift_sigma; "preload": the
  /// trip-end preload test, whose sentence is preload_verdict_text; ""
  /// unknown).
  const char* mismatch_test = "";
  const char* preload_verdict_text = "";
  /// SENSOR_FAULT: which sensor and why (TwinCore::lastSensorFault()).
  SensorId sensor = SensorId::CageImu;
  SensorFaultReason sensor_reason = SensorFaultReason::ClockOffset;
  /// GUIDE_PRELOAD_LOW / SHAFT_FINGERPRINT: the condition's own text (the
  /// estimate, its sigma and the trips; the depth), as the trip room said it.
  const char* preload_text = "";
  const char* fingerprint_text = "";
};

/// A readable one-line description of an alarm event into buf[0..n)
/// (always terminated; no allocation).  A text longer than n - 1 bytes is
/// cut at the last word that fits and ends in "...".
void describeAlarm(const AlarmEvent& e, const AlarmTextContext& ctx, char* buf, std::size_t n);

// printable(): hoist/contract/alarm_command.hpp.

/// A validated operator command (the rule is validateAlarmCommand, shared with hoist-mqtt).
using AckCommand = AlarmCommand;
/// nullopt and `why` set (a static string) if `ack` is not a valid command.
std::optional<AckCommand> validateAck(const hoist::alarm_ack_t& ack, const char*& why);

/// `name` with every regular-expression metacharacter escaped: LCM's
/// subscribe() takes a regex, so a literal channel name needs this.
std::string regexEscape(const std::string& name);

}  // namespace hoist::service::lcm
