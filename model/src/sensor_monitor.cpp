#include "hoist/sensor_monitor.hpp"

#include <algorithm>
#include <cmath>

namespace hoist {

const char* sensorFaultReason(unsigned bits) {
  if (bits & kFaultStuck) return "stuck";
  if (bits & kFaultQuiet) return "quiet";
  if (bits & kFaultNoisy) return "noisy";
  return "";
}

void SensorMonitor::HighPass::add(double t1, double x, double lp_time, double memory) {
  if (!started) {
    started = true;
    lp = x;
    t = t1;
    return;
  }
  const double dt = t1 - t;
  if (!(dt > 0.0)) return;  // not newer: nothing to learn
  t = t1;
  const double a = 1.0 - std::exp(-dt / lp_time);
  const double hp = x - lp;
  // white noise: var(x_k - lp_{k-1}) = sigma^2 (1 + a / (2 - a)) = sigma^2 2 / (2 - a)
  const double w = 1.0 - std::exp(-dt / memory);
  var += w * (hp * hp * (2.0 - a) / 2.0 - var);
  lp += a * hp;
}

void SensorMonitor::reset(const SensorMonitorSettings& s) {
  s_ = s;
  raw_ = {};
  inn_ = {};
  raw_.var = inn_.var = s.sigma * s.sigma;  // healthy until the data say otherwise
  var_z_ = var_nu_ = s.sigma * s.sigma;
  rel_sd_ = 0.0;
  last_z_ = 0.0;
  same_since_ = 0.0;
  same_run_ = 0;
  faults_ = 0;
}

void SensorMonitor::sample(double t, double z) {
  raw_.add(t, z, s_.lp_time, s_.quiet_memory);
  var_z_ = raw_.var;
  const double s2 = s_.sigma * s_.sigma;
  const double q2 = s_.quiet_ratio * s_.quiet_ratio;
  if (var_z_ < q2 * s2) faults_ |= kFaultQuiet;
  else if (var_z_ > 4.0 * q2 * s2) faults_ &= ~kFaultQuiet;
  if (same_run_ > 0 && z == last_z_) {
    ++same_run_;
  } else {
    same_run_ = 1;
    same_since_ = t;
    last_z_ = z;
  }
  if (same_run_ >= 5 && t - same_since_ >= s_.stuck_time) faults_ |= kFaultStuck;
  else if (same_run_ == 1) faults_ &= ~kFaultStuck;
}

void SensorMonitor::innovation(double t, double nu) {
  const double dt = t - inn_.t;
  if (inn_.started && dt > 0.0) rel_sd_ = std::min(0.5, std::sqrt(dt / s_.noise_memory));
  inn_.add(t, nu, s_.lp_time, s_.noise_memory);
  var_nu_ = inn_.var;
  const double f2 = s_.noisy_factor * s_.noisy_factor * s_.sigma * s_.sigma;
  if (var_nu_ > f2) faults_ |= kFaultNoisy;
  else if (var_nu_ < 0.5 * f2) faults_ &= ~kFaultNoisy;
}

}  // namespace hoist
