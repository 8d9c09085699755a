// TwinCore's side of the load estimator's sensors: samples offered at their
// own time (SensorTiming), SENSOR_FAULT, the estimator's step with the due
// samples, whether the estimate may judge the alarms, the live calibration.
// See hoist/service/twin/twin_core.hpp; the rest of TwinCore is twin_core.cpp.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hoist/service/twin/twin_core.hpp"

namespace hoist::service::inline twin {

SensorVerdict TwinCore::onCageImu(std::int64_t utime, double f_y, double omega, double wall_now,
                                  std::int64_t wall_utime) {
  return offerSensor(SensorId::CageImu, utime, f_y, omega, wall_now, wall_utime);
}

SensorVerdict TwinCore::onRopeLoad(std::int64_t utime, double force, double wall_now, std::int64_t wall_utime) {
  if (!std::isfinite(force)) return SensorVerdict::NoClock;
  return offerSensor(SensorId::RopeLoad, utime, force, 0.0, wall_now, wall_utime);
}

SensorVerdict TwinCore::offerSensor(SensorId s, std::int64_t utime, double a, double b, double wall_now,
                                    std::int64_t wall_utime) {
  if (!est_) return SensorVerdict::NoClock;
  double offset = 0.0;
  const double ts = clock_->sensorTime(*this, utime, wall_now, wall_utime, offset);
  sensor_offset_ = offset;
  const SensorVerdict v = s == SensorId::CageImu ? timing_.offerImu(utime, offset, ts, a, b)
                                                 : timing_.offerRope(utime, offset, ts, a);
  if (v == SensorVerdict::ClockOffset)
    noteSensorFault(s, SensorFaultReason::ClockOffset, offset, timing_.maxClockOffset());
  else if (v == SensorVerdict::TimeBackwards)
    noteSensorFault(s, SensorFaultReason::TimeBackwards, offset, 0.0);
  return v;
}

bool TwinCore::calibrate(double Fa, double b, double duration) {
  if (!est_ || !std::isfinite(Fa) || !std::isfinite(b) || !(duration > 0.0)) return false;
  // The estimator pins the declared load and learns the accelerometer's
  // offset from it (LoadEstimator::declareKnownLoad: allocation-free).
  try {
    est_->declareKnownLoad(Fa, b, t_ + duration);
  } catch (const std::invalid_argument&) {
    return false;  // Fa < 0: refused, as the contract refuses it
  }
  known_Fa_ = Fa;
  known_b_ = b;
  known_until_ = t_ + duration;
  return true;
}

bool TwinCore::setAccelOffset(double offset, double sigma) {
  if (!est_) return false;
  try {
    est_->setAccelOffset(offset, sigma);
  } catch (const std::invalid_argument&) {
    return false;
  }
  return true;
}

void TwinCore::noteSensorFault(SensorId s, SensorFaultReason r, double value, double limit) {
  sensor_fault_ = SensorFaultInfo{s, r, value, limit};
  sensor_fault_until_ = t_ + kSensorFaultHold;
  alarms_.setSensorFault(t_, true, value, limit, events_);
  out_.alarm_level = alarms_.highestActive();
}

void TwinCore::estimatorStep(const CageResponse& r) {
  // The same sequence as hoist::estimateRecorded (hoist-estimate): predict,
  // the IMU, the rope load, finish -- each sample at its own time, aligned
  // to this step (hoist/sensor_alignment.hpp).
  est_->predict(r);
  const double g = cfg_.shaft.g;
  const SensorPrediction now{t_, sensorModel(r, g), sensorModel(est_->sensitivity(), g)};
  timing_.record(now);
  const LoadEstimate& e = est_->estimate();
  const double Fa_c = cfg_.shaft.Fa, M_c = cfg_.shaft.Fa * cfg_.shaft.b;
  const DueSamples d = timing_.take(now, e.Fa - Fa_c, e.moment - M_c);
  if (d.accel && d.rate) est_->updateImu(d.f_y, d.omega);
  else if (d.accel) est_->updateImuAccel(d.f_y);
  else if (d.rate) est_->updateImuRate(d.omega);
  if (d.rope) est_->updateRopeLoad(d.force);
  // A tick we flag degraded (fell behind, stale, fault hold, ...) is no
  // evidence against the model: its NIS stays out of MODEL_MISMATCH's window.
  if (degradedNow()) est_->excludeTickFromModelCheck();
  est_->finish();
  // What the sensors read at this step (the trip room's record, issue 32).
  meas_.t = t_;
  meas_.z = SensorValues{d.accel ? d.f_y : 0.0, d.rate ? d.omega : 0.0, d.rope ? d.force : 0.0};
  meas_.present = (d.accel ? kSensorImuAccel : 0u) | (d.rate ? kSensorImuRate : 0u) | (d.rope ? kSensorRopeLoad : 0u);
}

unsigned TwinCore::estimateNotUsed(const LoadEstimate& e) {
  unsigned why = 0;
  if (e.sensors == 0) why |= kNotUsedNoSensors;
  if (e.mismatch || preload_mismatch_) why |= kNotUsedMismatch;
  if (!(std::isfinite(e.y_c) && std::isfinite(e.theta) && std::isfinite(e.lambda[0]) && std::isfinite(e.Fa) &&
        std::isfinite(e.moment)))
    return why | kNotUsedNonFinite;
  // Physical bounds: the state the estimate implies within the twin's own
  // plausibility bounds, and no negative payload (beyond its 3 sigma).
  const double h = cfg_.shaft.h;
  const double lateral = std::max(std::abs(e.y_c - h * e.theta), std::abs(e.y_c + h * e.theta));
  double value = 0.0, limit = 0.0;
  if (lateral > bounds_.lateral) value = lateral, limit = bounds_.lateral;
  else if (std::abs(e.theta) > bounds_.theta) value = e.theta, limit = bounds_.theta;
  else if (e.fa_observed && e.Fa + 3.0 * std::max(e.sigma_Fa, 0.0) < 0.0) value = e.Fa, limit = 0.0;
  else
    for (double l : e.lambda)
      if (std::abs(l) > bounds_.force) value = l, limit = bounds_.force;
  if (value != 0.0 || limit != 0.0) {
    why |= kNotUsedImplausible;
    noteSensorFault(SensorId::Estimate, SensorFaultReason::Implausible, value, limit);
  } else if (!e.plausible) {
    // The estimator's own physical bounds ([load] max_payload, max_offset;
    // reported as Fa against the payload limit).
    why |= kNotUsedImplausible;
    noteSensorFault(SensorId::Estimate, SensorFaultReason::Implausible, e.Fa, cfg_.shaft.payloadLimit());
  }
  // A sensor the estimator's monitor finds quiet, stuck or noisy
  // (hoist/sensor_monitor.hpp): its channel lies, the estimate is not used.
  if (e.faulty != 0) {
    why |= kNotUsedSensorFault;
    const bool imu = (e.fault_imu_accel | e.fault_imu_rate) != 0;
    const unsigned bits = imu ? (e.fault_imu_accel | e.fault_imu_rate) : e.fault_rope_load;
    const SensorFaultReason r = (bits & kFaultQuiet)   ? SensorFaultReason::Quiet
                                : (bits & kFaultStuck) ? SensorFaultReason::Stuck
                                : (bits & kFaultNoisy) ? SensorFaultReason::Noisy
                                                       : SensorFaultReason::Rejected;
    const double learned = imu ? e.noise_imu_accel : e.noise_rope_load;
    const double sheet = imu ? est_->settings().noise.imu_accel : est_->settings().noise.rope_load;
    noteSensorFault(imu ? SensorId::CageImu : SensorId::RopeLoad, r, learned, sheet);
  }
  return why;
}

}  // namespace hoist::service::twin
