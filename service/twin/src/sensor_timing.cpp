// Sensor samples at their own time: see hoist/service/twin/sensor_timing.hpp.
#include "hoist/service/twin/sensor_timing.hpp"

#include <cmath>
#include <limits>

namespace hoist::service::inline twin {

const char* toString(SensorId s) {
  switch (s) {
    case SensorId::CageImu: return "HOIST_CAGE_IMU";
    case SensorId::RopeLoad: return "HOIST_ROPE_LOAD";
    case SensorId::Estimate: return "the load estimate";
  }
  return "?";
}

const char* toString(SensorFaultReason r) {
  switch (r) {
    case SensorFaultReason::ClockOffset: return "clock_offset";
    case SensorFaultReason::TimeBackwards: return "time_backwards";
    case SensorFaultReason::Implausible: return "implausible";
    case SensorFaultReason::Quiet: return "quiet";
    case SensorFaultReason::Stuck: return "stuck";
    case SensorFaultReason::Noisy: return "noisy";
    case SensorFaultReason::Rejected: return "rejected";
  }
  return "?";
}

SensorTiming::SensorTiming(double max_clock_offset, std::size_t history)
    : max_offset_(max_clock_offset), hist_(history) {}

void SensorTiming::Queue::push(const Sample& x, std::int64_t& superseded) {
  if (count == kQueue) {  // full: the oldest leaves
    pop();
    ++superseded;
  }
  s[static_cast<std::size_t>((head + count) % kQueue)] = x;
  ++count;
}

SensorVerdict SensorTiming::offer(Queue& q, std::int64_t utime, double offset, double ts, double a, double b) {
  if (!std::isfinite(offset) || !(std::abs(offset) <= max_offset_)) {
    ++counts_.clock_refused;
    return SensorVerdict::ClockOffset;
  }
  if (q.have_utime && utime <= q.last_utime) {
    ++counts_.time_backwards;
    return SensorVerdict::TimeBackwards;
  }
  if (std::isnan(ts)) {
    ++counts_.too_late;
    return SensorVerdict::NoClock;
  }
  q.last_utime = utime;
  q.have_utime = true;
  // Queued in time order (two clocks' jitter cannot reorder a sensor's own samples).
  if (q.count > 0) {
    const Sample& last = q.s[static_cast<std::size_t>((q.head + q.count - 1) % kQueue)];
    if (ts < last.ts) ts = last.ts;
  }
  q.push(Sample{ts, a, b}, counts_.superseded);
  ++counts_.queued;
  return SensorVerdict::Queued;
}

SensorVerdict SensorTiming::offerImu(std::int64_t utime, double offset, double ts, double f_y, double omega) {
  return offer(imu_, utime, offset, ts, f_y, omega);
}

SensorVerdict SensorTiming::offerRope(std::int64_t utime, double offset, double ts, double force) {
  return offer(rope_, utime, offset, ts, force, 0.0);
}

void SensorTiming::reset(bool drop_queued) {
  hist_.clear();
  if (drop_queued) imu_.count = rope_.count = 0;
}

const SensorTiming::Sample* SensorTiming::due(Queue& q, double t, Sample& out) {
  // Count the due samples; keep at most kMaxDue of them.
  int n = 0;
  while (n < q.count && q.s[static_cast<std::size_t>((q.head + n) % kQueue)].ts <= t) ++n;
  for (; n > kMaxDue; --n) {
    q.pop();
    ++counts_.superseded;
  }
  while (n > 0) {
    out = q.front();
    q.pop();
    --n;
    if (out.ts == -std::numeric_limits<double>::infinity()) out.ts = t;  // taken before the model had a time
    if (out.ts >= hist_.oldest()) return &out;
    ++counts_.too_late;  // before the kept predictions: cannot be aligned
  }
  return nullptr;
}

DueSamples SensorTiming::take(const SensorPrediction& now, double dFa, double dM) {
  DueSamples d;
  Sample s;
  SensorPrediction then;
  if (due(imu_, now.t, s) && hist_.at(s.ts, then)) {
    const SensorValues z = alignToNow(SensorValues{std::isfinite(s.a) ? s.a : 0.0, std::isfinite(s.b) ? s.b : 0.0, 0.0},
                                      then, now, dFa, dM);
    d.accel = std::isfinite(s.a);
    d.rate = std::isfinite(s.b);
    d.f_y = z.f_y;
    d.omega = z.omega;
    d.imu_lag = now.t - s.ts;
    ++counts_.applied;
  }
  if (due(rope_, now.t, s) && hist_.at(s.ts, then)) {
    d.rope = true;
    d.force = alignToNow(SensorValues{0.0, 0.0, s.a}, then, now, dFa, dM).rope_load;
    d.rope_lag = now.t - s.ts;
    ++counts_.applied;
  }
  return d;
}

}  // namespace hoist::service::twin
