// hoist/service/twin/estimate_gate.hpp -- which state the clearance and
// rope-force alarms judge, the load estimate's or the open-loop twin's, and
// the rule that a false sensor cannot silence an alarm.
//
// Every step TwinCore says whether the estimate may judge (usable: sensors
// in use, no MODEL_MISMATCH, finite, plausible, no sensor fault) and gives
// both candidate judgements.  The gate:
//   * judges on the estimate when usable, else on the open-loop twin;
//   * after a switch between the two, or a load change the estimator
//     detected, holds for clear_hold seconds of model time: meanwhile each
//     alarm gets the more alarming of the new value and the value judged
//     just before the switch/change (the larger excursions, the lower force
//     for ROPE_SLACK, the higher for ROPE_OVERLOAD), so the new estimate can
//     raise an alarm at once but clear one only once it has held;
//   * records every switch and load change (and, when its hold ends, the
//     load change's size) in a small ring of GateEvents that the daemon
//     logs off the real-time path (ShaftOutputs).
// Who calls: TwinCore::finishStep.  Real time: no allocation, no I/O.
#pragma once

#include <array>
#include <cstdint>

#include "hoist/service/core/alarms.hpp"

namespace hoist::service::inline twin {

/// Why the estimate does not judge the alarms (estimate_t.not_used bits).
enum NotUsedBits : unsigned {
  kNotUsedNoSensors = 1u,    ///< no sensor in use
  kNotUsedMismatch = 2u,     ///< MODEL_MISMATCH
  kNotUsedImplausible = 4u,  ///< the estimate or its state outside the physical bounds
  kNotUsedNonFinite = 8u,    ///< a non-finite estimate
  kNotUsedSensorFault = 16u, ///< a sensor fault (SENSOR_FAULT)
  kNotUsedDisabled = 32u,    ///< no estimator, or not stepped with the twin
};

/// What the alarms judge at one step.
struct Judgement {
  Clearance clearance;
  double lambda0_slack = 0.0;     ///< fed to ROPE_SLACK [N]
  double lambda0_overload = 0.0;  ///< fed to ROPE_OVERLOAD [N]
};

/// A switch or a load change, for the log.
struct GateEvent {
  enum class Type : std::uint8_t { Switch, LoadChange, LoadSettled };
  Type type = Type::Switch;
  double t = 0.0;             ///< model time
  bool to_estimate = false;   ///< Switch: now judged on the estimate
  unsigned not_used = 0;      ///< Switch to the open loop: NotUsedBits
  double Fa0 = 0.0, M0 = 0.0; ///< the load before (LoadChange, LoadSettled) [N], [N m]
  double Fa1 = 0.0, M1 = 0.0; ///< ... and now
};

class EstimateGate {
 public:
  EstimateGate(const AlarmConfig& alarms, double clear_hold) : alarms_(alarms), hold_(clear_hold) {}

  /// One step at model time t.  `load_changes`: the estimator's count; Fa, M
  /// its current load.  Returns what the alarms judge.
  const Judgement& step(double t, bool usable, unsigned not_used, const Judgement& estimate,
                        const Judgement& open_loop, std::int64_t load_changes, double Fa, double M);
  /// The twin restarted: no hold, the next step judges afresh.
  void reset() { first_ = true; }

  bool inUse() const { return in_use_; }           ///< the last step judged the estimate
  bool holding(double t) const { return t < hold_until_; }
  unsigned notUsed() const { return not_used_; }   ///< NotUsedBits of the last step
  std::int64_t switches() const { return switches_; }
  double lastChangeFa() const { return dFa_; }     ///< size of the last settled load change [N]
  double lastChangeM() const { return dM_; }       ///< [N m]

  /// The event ring: events() counts every event since construction;
  /// event(i) is event number i if it is still kept (i > events() - kEvents).
  static constexpr int kEvents = 16;
  std::int64_t events() const { return n_events_; }
  const GateEvent& event(std::int64_t i) const { return ring_[static_cast<std::size_t>(i % kEvents)]; }

 private:
  void push(const GateEvent& e) { ring_[static_cast<std::size_t>(n_events_++ % kEvents)] = e; }
  /// A LoadChange or LoadSettled event: the load before the change, and now.
  void pushLoad(GateEvent::Type type, double t, double Fa, double M);
  Judgement worse(const Judgement& a, const Judgement& b) const;

  AlarmConfig alarms_;
  double hold_;
  bool first_ = true;
  bool in_use_ = false;
  unsigned not_used_ = kNotUsedDisabled;
  double hold_until_ = -1e300;
  bool change_pending_ = false;   // a load change whose size is logged when its hold ends
  std::int64_t changes_ = 0;
  double Fa_prev_ = 0.0, M_prev_ = 0.0, Fa0_ = 0.0, M0_ = 0.0;
  double dFa_ = 0.0, dM_ = 0.0;
  std::int64_t switches_ = 0;
  Judgement held_, judged_;
  std::array<GateEvent, kEvents> ring_{};
  std::int64_t n_events_ = 0;
};

}  // namespace hoist::service::twin
