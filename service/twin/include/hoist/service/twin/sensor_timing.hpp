// hoist/service/twin/sensor_timing.hpp -- the load estimator's sensor samples
// applied at their own time (utime), not at their arrival.
//
// Each sample of HOIST_CAGE_IMU / HOIST_ROPE_LOAD carries the time it was
// taken.  TwinCore maps it to model time ts (its clock policy: --clock
// wall from the wall clock at arrival, --clock input from the winder
// stream's utime) and offers it here with its clock offset (the sample's
// utime minus the daemon's clock at arrival [s]; a late sample has a
// negative offset).  A sample is
//   * refused (ClockOffset) if |offset| > max_clock_offset: the sensor's
//     clock disagrees with the daemon's; TwinCore raises SENSOR_FAULT;
//   * refused (TimeBackwards) if its utime is not after the sensor's last
//     accepted one (a replay or a sender whose clock went back);
//   * else queued (a fixed ring per sensor) until the model reaches ts.
// At every model step take() hands out, per sensor, the oldest queued
// sample with ts <= now (at most one per step, as the estimator takes them;
// the others wait for the next steps, each aligned from its own time: a
// burst after a gap keeps its samples; more than kMaxDue due at once: the
// oldest are dropped, counted as superseded), aligned to the step with hoist::alignToNow through the
// recent predictions (record()).  A due sample older than the kept
// predictions cannot be aligned: dropped, counted as too late.
//
// Who calls: TwinCore only.  Real time: no allocation after construction,
// no I/O; the caller logs.
#pragma once

#include <array>
#include <cstdint>

#include "hoist/sensor_alignment.hpp"

namespace hoist::service::inline twin {

/// The estimator's sensor channels (SENSOR_FAULT names one of them).
enum class SensorId : std::uint8_t { CageImu = 1, RopeLoad = 2, Estimate = 3 };
const char* toString(SensorId s);  ///< "HOIST_CAGE_IMU", "HOIST_ROPE_LOAD", "the load estimate"

/// Why SENSOR_FAULT was raised (TwinCore::lastSensorFault()).
enum class SensorFaultReason : std::uint8_t {
  ClockOffset,    ///< the sample's utime further from the daemon's clock than max_clock_offset (refused)
  TimeBackwards,  ///< a utime not after the sensor's last accepted one (refused)
  Implausible,    ///< the estimate or the state it implies outside the physical bounds (not used)
  Quiet,          ///< far quieter than its datasheet noise: flat, zeroed or held (the estimator's sensor monitor)
  Stuck,          ///< the very same value repeated
  Noisy,          ///< far noisier than its datasheet
  Rejected,       ///< most of its samples rejected by the estimator's gate (it contradicts the model)
};
const char* toString(SensorFaultReason r);

/// What became of an offered sample.
enum class SensorVerdict : std::uint8_t { Queued, ClockOffset, TimeBackwards, NoClock };

/// Counts since construction.
struct SensorTimingCounters {
  std::int64_t queued = 0;          ///< samples accepted into the queues
  std::int64_t applied = 0;         ///< handed to the estimator
  std::int64_t clock_refused = 0;   ///< |offset| > max_clock_offset
  std::int64_t time_backwards = 0;  ///< utime not after the last accepted one
  std::int64_t too_late = 0;        ///< older than the kept predictions (or no model time yet)
  std::int64_t superseded = 0;      ///< dropped from a backlog (or a full queue)
};

/// The samples due at one step, aligned to it.
struct DueSamples {
  bool accel = false, rate = false, rope = false;
  double f_y = 0.0, omega = 0.0, force = 0.0;
  double imu_lag = 0.0, rope_lag = 0.0;  ///< now - ts of the applied samples [s]
};

class SensorTiming {
 public:
  /// `max_clock_offset` [s] ([sensors]); `history` steps of predictions kept
  /// (cover max_clock_offset at the step rate).
  SensorTiming(double max_clock_offset, std::size_t history);

  /// Offer a sample taken at model time `ts` with clock offset `offset` [s]
  /// (ts = -inf: before the model has a time; applied at its first step).
  /// f_y / omega: NaN = that channel absent.
  SensorVerdict offerImu(std::int64_t utime, double offset, double ts, double f_y, double omega);
  SensorVerdict offerRope(std::int64_t utime, double offset, double ts, double force);
  /// The model was (re-)initialized: the predictions are of the old stream;
  /// `drop_queued`: so are the queued samples (a restart; at the first start
  /// the samples that came first are applied at the first step).
  void reset(bool drop_queued);
  /// The prediction at a new model step (before take()).
  void record(const SensorPrediction& p) { hist_.push(p); }
  /// The samples due at `now` (the step just recorded), aligned to it with
  /// the current load's offsets dFa, dM from the configured load.
  DueSamples take(const SensorPrediction& now, double dFa, double dM);

  const SensorTimingCounters& counters() const { return counts_; }
  double maxClockOffset() const { return max_offset_; }
  /// Most samples due at one step that are kept for the next steps.
  static constexpr int kMaxDue = 32;
  /// Queue length per sensor.
  static constexpr int kQueue = 64;

 private:
  struct Sample {
    double ts = 0.0;
    double a = 0.0, b = 0.0;  // IMU: f_y, omega (NaN: absent); rope: force
  };
  struct Queue {
    std::array<Sample, kQueue> s{};
    int head = 0, count = 0;  // head: oldest
    std::int64_t last_utime = 0;
    bool have_utime = false;
    void push(const Sample& x, std::int64_t& superseded);
    const Sample& front() const { return s[static_cast<std::size_t>(head)]; }
    void pop() { head = (head + 1) % kQueue; --count; }
  };
  SensorVerdict offer(Queue& q, std::int64_t utime, double offset, double ts, double a, double b);
  /// The oldest due sample of `q` at `t`, or nullptr; drops backlog and too-late ones.
  const Sample* due(Queue& q, double t, Sample& out);

  double max_offset_;
  PredictionHistory hist_;
  Queue imu_, rope_;
  SensorTimingCounters counts_;
};

}  // namespace hoist::service::twin
