// hoist/sensor_alignment.hpp -- a sensor sample applied at its own time.
//
// A sample of the cage IMU or the rope load cell arrives some time after it
// was taken (gateway, network, the daemon's tick).  The load estimator
// (hoist/load_estimator.hpp) predicts each measurement at the twin's current
// step as
//     z_pred(t) = base(t) + (load - load_configured) h(t),
// base = what the sensors read on the open-loop twin, h = the sensitivity of
// the reading to the load (per N of Fa, per N m of M).  The load is constant
// between changes, so a sample z taken at ts < t carries the same innovation
// as the sample
//     z' = z + [base(t) - base(ts)] + dload [h(t) - h(ts)]
// taken at t: alignToNow() forms z', and the estimator updates with it at its
// current step.  The innovation is then exactly the one at ts; the gain uses
// h(t) instead of h(ts) (h moves with depth: about 0.1 % per 50 ms at 10 m/s,
// docs/service.md "The estimator's sensors").
//
// PredictionHistory keeps (t, base, h) of the recent steps in a ring sized
// once (the late samples it can align: at most its span), interpolated
// linearly between steps.
//
// Who calls: TwinCore (service/twin) after every model step it hands the
// estimator; the daemon's sensor handlers only time-stamp samples.
// Real time: no allocation after construction.
#pragma once

#include <cstddef>
#include <vector>

#include "hoist/load_estimator.hpp"

namespace hoist {

/// The sensors' open-loop reading and its sensitivity to the load at one step.
struct SensorPrediction {
  double t = 0.0;
  SensorValues base;  ///< sensorModel(twin response)
  SensorValues h;     ///< sensorModel(sensitivity response): per N (rope_load) and per N m (f_y, omega)
};

/// The predictions at the recent steps.
class PredictionHistory {
 public:
  /// Keeps the last `capacity` steps (>= 2).
  explicit PredictionHistory(std::size_t capacity);
  /// Forget everything (the twin was re-initialized: earlier samples are of another stream).
  void clear() { count_ = 0; }
  /// The prediction of a new step; its t must exceed the last one's (else the history restarts at it).
  void push(const SensorPrediction& p);
  /// The prediction at ts, interpolated; false if ts is outside [oldest, newest].
  bool at(double ts, SensorPrediction& out) const;
  bool empty() const { return count_ == 0; }
  double oldest() const;
  double newest() const;
  std::size_t capacity() const { return ring_.size(); }

 private:
  const SensorPrediction& get(std::size_t i) const;  // 0 = oldest
  std::vector<SensorPrediction> ring_;
  std::size_t head_ = 0, count_ = 0;  // head_: next slot to write
};

/// The sample `z` taken when the prediction was `then` moved to the step
/// `now` (see above); dFa, dM: the current load estimate minus the configured load.
SensorValues alignToNow(const SensorValues& z, const SensorPrediction& then, const SensorPrediction& now, double dFa,
                        double dM);

}  // namespace hoist
