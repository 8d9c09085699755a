// hoist/service/core/alarms.hpp -- clearance alarms of the twin (pure: no I/O, no
// clock, no allocation after construction).
//
// What is measured (docs/model.md conventions; y lateral, theta cage rotation, h
// cage half height):
//   top-sleeve excursion      y_top    = y_c - h theta
//   bottom-sleeve excursion   y_bottom = y_c + h theta
//   toward +y                 e_pos    = max(y_top, y_bottom)
//   toward -y                 e_neg    = max(-y_top, -y_bottom)
//   guide ropes               e_guide  = largest |y_1(x)|, |y_2(x)| over the shaft
// and compared with configured gaps ([alarms] gap_pos_y, gap_neg_y,
// guide_rope_gap, metres).  Remaining clearance = gap - excursion.
//
// Alarm model (ISA-18.2 / OPC UA Part 9 AlarmConditionType practice):
//   * every (kind, level) is one binary alarm: CAGE_POS_Y, CAGE_NEG_Y and
//     GUIDE_ROPE each have a WARNING (warning_fraction * gap) and a CRITICAL
//     (critical_fraction * gap) alarm; INPUT_STALE is a WARNING, MODEL_FAULT a
//     CRITICAL, MODEL_DOMAIN (rope length outside the model's valid range) a
//     CRITICAL, DUPLICATE_PUBLISHER (another process publishes on this
//     twin's output channels) a WARNING; ROPE_SLACK (lambda_0 at or below
//     slack_fraction x the static rope force) and ROPE_OVERLOAD (at or above
//     overload_fraction x it) are CRITICAL, their deadband force_deadband x
//     the static force (ShaftModel::staticRopeForce);
//     PREDICTED_CLEARANCE and PREDICTED_SLACK (a look-ahead
//     scenario crosses the CRITICAL clearance threshold / brings lambda_0
//     below the slack threshold within the forecast horizon) are WARNINGs,
//     never latched, raised at once (no on-delay: the forecast itself is the
//     early warning); MODEL_MISMATCH and SENSOR_FAULT (the load estimator's
//     model check, and a sensor refused or not believed) are WARNING flags;
//     GUIDE_PRELOAD_LOW (WARNING and CRITICAL) and SHAFT_FINGERPRINT (WARNING)
//     are the shaft's memory's verdicts over its recorded trips (flags set
//     after each trip; the CRITICAL one latches);
//   * the condition comes on when value >= threshold has held for on_delay
//     and goes off when value < threshold - deadband has held for off_delay
//     (so a value hovering at the threshold cannot chatter); a low alarm
//     (ROPE_SLACK) mirrors it: on at value <= threshold, off above
//     threshold + deadband;
//   * a CRITICAL alarm latches (with latch_critical): it stays active after
//     its condition is gone until an operator acknowledges it;
//   * an operator can shelve an alarm for a time (at most max_shelve): while
//     shelved it raises and clears silently; on unshelve (or expiry) the
//     current state is announced.  Only effective commands change state and
//     emit events: acknowledging an acknowledged alarm, unshelving an
//     unshelved one, or re-shelving a shelved one with an expiry that moves
//     by less than kReshelveResolution does nothing (a flood of identical
//     commands produces no events);
//   * active, unshelved alarms are re-announced every `reannounce` seconds.
// Time `now` is whatever monotonic clock the caller uses, in seconds (the
// daemon passes model time).  Each call appends the resulting events to an
// AlarmEvents buffer of fixed capacity; the caller publishes and logs them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "hoist/contract/alarm_vocabulary.hpp"

namespace hoist::service::inline core {

// The alarm vocabulary (kinds, levels, event types, their names) is the
// contract with the daemon's clients: hoist/contract/alarm_vocabulary.hpp.
using contract::AlarmEventType;
using contract::AlarmKind;
using contract::AlarmLevel;
using contract::kAlarmKinds;
using contract::parseAlarmKind;
using contract::toString;

/// A re-shelve that moves the expiry by less than this [s] is not effective.
inline constexpr double kReshelveResolution = 1.0;

/// The [alarms] section (see docs/service.md).  Lengths in metres, times in seconds.
struct AlarmConfig {
  double gap_pos_y = 0.30;         ///< cage to shaft wall / neighbour on the +y side [m]
  double gap_neg_y = 0.30;         ///< ... on the -y side [m]
  double guide_rope_gap = 0.30;    ///< allowed guide-rope lateral deflection [m]
  double warning_fraction = 0.5;   ///< WARNING threshold = fraction * gap, in (0, critical_fraction)
  double critical_fraction = 0.8;  ///< CRITICAL threshold = fraction * gap, in (warning_fraction, 1]
  double deadband = 0.02;          ///< hysteresis as a fraction of the gap, in [0, warning_fraction)
  double on_delay = 0.1;           ///< value must stay over threshold this long to raise [s]
  double off_delay = 1.0;          ///< value must stay under threshold - deadband this long to clear [s]
  double reannounce = 10.0;        ///< re-announce active alarms every ... [s]; 0 = never
  bool latch_critical = true;      ///< CRITICAL stays active until acknowledged
  double max_shelve = contract::kDefaultMaxShelve;  ///< longest shelve an operator may set [s]
  /// Rope-force alarms, as fractions of the static rope force at
  /// the current length (ShaftModel::staticRopeForce, m g + Fa); see
  /// docs/service.md for the defaults' reasons.
  double slack_fraction = 0.5;     ///< ROPE_SLACK at lambda_0 <= fraction x static, in (0, 1)
  double overload_fraction = 1.5;  ///< ROPE_OVERLOAD at lambda_0 >= fraction x static, in (1, 100]
  /// Hysteresis of both, as a fraction of the static force, in [0, 1):
  /// below slack_fraction and 1 - slack_fraction, and below overload_fraction - 1.
  double force_deadband = 0.05;

  /// Throws std::invalid_argument("alarms.<key>: ...") for the first bad value.
  void validate() const;
};

/// Settings of one binary alarm.
struct AlarmSettings {
  double threshold = 1.0;
  bool low = false;        ///< a low alarm: on at value <= threshold, off above threshold + deadband
  double deadband = 0.0;   ///< absolute, in the value's unit
  double on_delay = 0.0;
  double off_delay = 0.0;
  bool latch = false;
  double reannounce = 0.0;
};

struct AlarmEvent {
  AlarmKind kind = AlarmKind::CagePosY;
  AlarmLevel level = AlarmLevel::Warning;
  AlarmEventType type = AlarmEventType::Raise;
  double t = 0.0;          ///< time of the event [s]
  double value = 0.0;      ///< last value fed to the alarm
  double threshold = 0.0;
  bool active = false;     ///< state after the event
  bool acked = false;
  bool shelved = false;
  bool latched = false;    ///< active only because of the latch
  double shelved_for = 0.0;  ///< remaining shelve time [s]
  bool from_estimate = false;  ///< raised from the load estimator's state, not the open-loop twin's
};

/// Fixed-capacity event list (no allocation).  Events beyond the capacity
/// are dropped and counted in `dropped`.
class AlarmEvents {
 public:
  static constexpr std::size_t kCapacity = 64;
  void clear() { n_ = 0; dropped_ = 0; }
  void push(const AlarmEvent& e) {
    if (n_ < kCapacity) ev_[n_++] = e; else ++dropped_;
  }
  std::size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  std::size_t dropped() const { return dropped_; }
  const AlarmEvent& operator[](std::size_t i) const { return ev_[i]; }
  /// Mark the events from index `first` on as raised from the estimate.
  void markFromEstimate(std::size_t first) {
    for (std::size_t i = first; i < n_; ++i) ev_[i].from_estimate = true;
  }
  const AlarmEvent* begin() const { return ev_.data(); }
  const AlarmEvent* end() const { return ev_.data() + n_; }

 private:
  std::array<AlarmEvent, kCapacity> ev_{};
  std::size_t n_ = 0, dropped_ = 0;
};

/// One binary alarm with deadband, on-/off-delay, latching, acknowledgement,
/// shelving and re-announcement.
class BinaryAlarm {
 public:
  BinaryAlarm() = default;
  BinaryAlarm(AlarmKind kind, AlarmLevel level, const AlarmSettings& s) { configure(kind, level, s); }
  void configure(AlarmKind kind, AlarmLevel level, const AlarmSettings& s);

  /// Feed the measured value at time `now` (non-decreasing).  A non-finite
  /// value counts as over the threshold (fail safe).
  void update(double now, double value, AlarmEvents& out);
  /// Flag alarms: the value and limit their events report (e.g. the rope
  /// length and the range limit of MODEL_DOMAIN) instead of the 0/1 flag.
  void setDetail(double value, double limit) {
    detail_ = true;
    detail_value_ = value;
    detail_limit_ = limit;
  }
  /// Move the threshold and deadband (e.g. with the rope length); the
  /// condition's state and timers are kept.  No allocation.
  void setThreshold(double threshold, double deadband) {
    s_.threshold = threshold;
    s_.deadband = deadband;
  }
  /// Operator acknowledgement of an active alarm, or of one that returned
  /// to normal unacknowledged (RTN UNACK: its CLEAR carried acked = false;
  /// the ACK event with active = false, acked = true ends the row); false
  /// if there was nothing to acknowledge.
  bool acknowledge(double now, AlarmEvents& out);
  /// Shelve for `duration` seconds (> 0).  Re-shelving extends/shortens.
  bool shelve(double now, double duration, AlarmEvents& out);
  bool unshelve(double now, AlarmEvents& out);
  /// Whether the alarm has a state to tell a client: it emitted an event
  /// since it was configured (raised, cleared, acknowledged, shelved, ...).
  bool hasState() const { return touched_; }
  /// Append an EVENT_REANNOUNCE of the current state, active or not; no
  /// state changes (an operator's re-announce request, alarm_ack_t
  /// ACTION_REANNOUNCE).
  void reportState(double now, AlarmEvents& out) const { out.push(event(AlarmEventType::Reannounce, now)); }

  AlarmKind kind() const { return kind_; }
  AlarmLevel level() const { return level_; }
  const AlarmSettings& settings() const { return s_; }
  bool condition() const { return cond_; }  ///< debounced condition
  bool active() const { return active_; }
  bool acked() const { return acked_; }
  /// Returned to normal unacknowledged (ISA-18.2 RTN UNACK).
  bool rtnUnacked() const { return !active_ && raised_ && !acked_; }
  bool shelved() const { return shelved_; }
  bool latched() const { return active_ && !cond_; }
  double value() const { return value_; }

 private:
  AlarmEvent event(AlarmEventType type, double now) const;
  void emit(AlarmEventType type, double now, AlarmEvents& out);
  void announce(double now, AlarmEvents& out);  // publish active_ if it differs from announced_
  void expireShelve(double now, AlarmEvents& out);

  AlarmKind kind_ = AlarmKind::CagePosY;
  AlarmLevel level_ = AlarmLevel::Warning;
  AlarmSettings s_;
  bool cond_ = false;
  double pending_since_ = -1.0;  // < 0: raw state agrees with cond_
  bool pending_valid_ = false;
  bool active_ = false, acked_ = false, shelved_ = false, announced_ = false;
  bool touched_ = false;  // emitted an event since configure()
  bool raised_ = false;   // became active since configure() (with acked_: RTN UNACK)
  double shelved_until_ = 0.0;
  double last_announce_ = 0.0;
  double value_ = 0.0;
  bool detail_ = false;
  double detail_value_ = 0.0, detail_limit_ = 0.0;
};

/// Clearance figures of one cage state.
struct Clearance {
  double y_top = 0.0;            ///< y_c - h theta [m]
  double y_bottom = 0.0;         ///< y_c + h theta [m]
  double excursion_pos = 0.0;    ///< max(y_top, y_bottom) [m]
  double excursion_neg = 0.0;    ///< max(-y_top, -y_bottom) [m]
  double guide_deflection = 0.0; ///< [m]
  double clearance_pos = 0.0;    ///< gap_pos_y - excursion_pos [m]
  double clearance_neg = 0.0;    ///< gap_neg_y - excursion_neg [m]
  double clearance_guide = 0.0;  ///< guide_rope_gap - guide_deflection [m]
  double min_clearance = 0.0;    ///< smallest of the three [m]
};

Clearance computeClearance(double y_c, double theta, double h, double guide_deflection,
                           const AlarmConfig& cfg);

/// All alarms of the twin.
class AlarmEngine {
 public:
  /// The number of binary alarms; which ones, in which order, is the slot
  /// table in alarms.cpp (kSlotTable).
  static constexpr int kSlots = 19;

  explicit AlarmEngine(const AlarmConfig& cfg = {});
  const AlarmConfig& config() const { return cfg_; }

  void updateClearance(double now, const Clearance& c, AlarmEvents& out);
  void setInputStale(double now, bool stale, AlarmEvents& out);
  /// `fault` true for the step where the model state became non-finite.
  void setModelFault(double now, bool fault, AlarmEvents& out);
  /// `outside` true while the requested rope length `l` is outside the
  /// model's valid range; `limit` is the range end it crossed.
  void setModelDomain(double now, bool outside, double l, double limit, AlarmEvents& out);
  /// `seen` true while another publisher is seen on the output channels;
  /// `other_id` its instance id (reported as the event's value).
  void setDuplicatePublisher(double now, bool seen, double other_id, AlarmEvents& out);
  /// ROPE_SLACK / ROPE_OVERLOAD: the hoisting-rope force `lambda0` [N]
  /// against slack_fraction / overload_fraction x `static_force` [N] (the
  /// static rope force at the current length).  A non-finite lambda0 counts
  /// as in alarm (fail safe), a non-finite or non-positive static_force
  /// leaves the thresholds as they were.
  void updateRopeForce(double now, double lambda0, double static_force, AlarmEvents& out);
  /// The same with a value of its own for each alarm (TwinCore's clear hold
  /// feeds each the more alarming of two sources: the lower force to
  /// ROPE_SLACK, the higher to ROPE_OVERLOAD).
  void updateRopeForce(double now, double lambda0_slack, double lambda0_overload, double static_force,
                       AlarmEvents& out);
  /// The thresholds in force [N] (HOIST_CAGE.rope_slack_threshold, _overload_threshold).
  double ropeSlackThreshold() const;
  double ropeOverloadThreshold() const;
  /// MODEL_FAULT events report `value` against `limit` (e.g. an implausible
  /// output and its bound; 1/0 for a non-finite state).
  void setModelFaultDetail(double value, double limit);
  /// Look-ahead result: `predicted` true while the latest
  /// forecast has a scenario that crosses the threshold within the horizon;
  /// `seconds` when (after the forecast's start), `horizon` the horizon
  /// (reported as the event's value and threshold).
  void setPredictedClearance(double now, bool predicted, double seconds, double horizon, AlarmEvents& out);
  void setPredictedSlack(double now, bool predicted, double seconds, double horizon, AlarmEvents& out);
  /// MODEL_MISMATCH (the load estimator, docs/estimation.md): `mismatch`
  /// true while the shaft does not behave like its model; `statistic` and
  /// `bound` are reported (the window's NIS and its bound, or the load's
  /// drift and drift_sigma).
  void setModelMismatch(double now, bool mismatch, double statistic, double bound, AlarmEvents& out);
  /// SENSOR_FAULT (WARNING): `fault` true while a sensor of the load
  /// estimator is refused or not believed (TwinCore says which and why:
  /// lastSensorFault()); `value` and `limit` are reported (e.g. the clock
  /// offset and max_clock_offset [s]).
  void setSensorFault(double now, bool fault, double value, double limit, AlarmEvents& out);
  /// GUIDE_PRELOAD_LOW (the shaft's memory, hoist/preload_trend.hpp): the
  /// trend's level (None, Warning, Critical) after the last recorded trip.
  /// The WARNING alarm is active at Warning and Critical (as a clearance's
  /// WARNING is while its CRITICAL is), the CRITICAL one at Critical (it
  /// latches with latch_critical).  `upper95` (the combined preload scale's
  /// 95 % upper bound) is reported against `warning` / `critical`.
  void setGuidePreloadLow(double now, AlarmLevel level, double upper95, double warning, double critical,
                          AlarmEvents& out);
  /// SHAFT_FINGERPRINT (WARNING; hoist/shaft_fingerprint.hpp): `active` while
  /// a depth bin left the commissioning fingerprint on 2 of the last 3 trips
  /// of a direction; `z` (the strongest hit's last z) against `limit`
  /// ([condition] fingerprint_sigma).
  void setShaftFingerprint(double now, bool active, double z, double limit, AlarmEvents& out);
  /// Runs shelve expiry and re-announcement without a new value.
  void poll(double now, AlarmEvents& out);

  /// Operator commands.  kind empty = all kinds; level None = all levels.
  /// Return the number of alarms affected.
  int acknowledge(double now, std::optional<AlarmKind> kind, AlarmLevel level, AlarmEvents& out);
  int shelve(double now, std::optional<AlarmKind> kind, AlarmLevel level, double duration,
             AlarmEvents& out);
  int unshelve(double now, std::optional<AlarmKind> kind, AlarmLevel level, AlarmEvents& out);
  /// Re-announce request: an EVENT_REANNOUNCE of the current state of every
  /// matching alarm that has one (BinaryAlarm::hasState), shelved or not,
  /// active or not; nothing changes.  Returns the number of events.
  int reannounce(double now, std::optional<AlarmKind> kind, AlarmLevel level, AlarmEvents& out);

  AlarmLevel highestActive() const;  ///< over unshelved active alarms
  int activeCount() const;
  int unackedCount() const;
  int shelvedCount() const;
  const std::array<BinaryAlarm, kSlots>& alarms() const { return alarms_; }
  /// The alarm of (kind, level), or nullptr if there is none.
  const BinaryAlarm* find(AlarmKind kind, AlarmLevel level) const;

 private:
  template <class F>
  int forMatching(std::optional<AlarmKind> kind, AlarmLevel level, F&& f);
  AlarmConfig cfg_;
  std::array<BinaryAlarm, kSlots> alarms_;
};

}  // namespace hoist::service::core
