// The inputs of one shaft, the load estimator's sensors (HOIST_CAGE_IMU,
// HOIST_ROPE_LOAD; [estimator] enabled): ShaftInputs' handlers of these two
// routes and their checks.  The rest of the room (routes, winder samples,
// operator commands, trip plans, our own outputs seen from another
// publisher) is in shaft_inputs.cpp; the contract is in shaft_inputs.hpp.
#include <cmath>
#include <cstdio>

#include "hoist/bus/lcm_util.hpp"
#include "hoist/msg/codec.hpp"
#include "shaft_inputs.hpp"

namespace hoist::service::inline app {

// ---- the load estimator's sensors ----------------------------------------------
// Decoded into flat scratch messages (no allocation), checked (finite, within
// what such a sensor can report, sequence not going back), and handed to the
// model room (TwinCore), which applies the latest sample at its next step.
// The estimator itself gates outliers against its prediction and counts them.

namespace {
constexpr double kMaxSpecificForce = 100.0;  // |f_y| a cage IMU can report [m/s^2]
constexpr double kMaxTiltRate = 20.0;        // |omega| [rad/s]
constexpr double kMaxRopeLoad = 1.0e8;       // |force| [N]
}  // namespace

void ShaftInputs::rejectSensor(const char* channel, const char* detail) {
  ++stats_.sensor_rejected;
  std::int64_t suppressed = 0;
  if (log_limit_.allow(kLogSensor, ctx_.wallNow(), suppressed))
    ctx_.log.warn("{}rejected {} sample: {} [{} similar suppressed]", ctx_.tag, channel, detail, suppressed);
}

template <class Msg>
bool ShaftInputs::decodeSensor(const ::lcm::ReceiveBuffer* rbuf, Msg& m, const char* channel) {
  const auto size = static_cast<std::size_t>(rbuf->data_size);
  const auto st = hoist::msg::checkedDecode(rbuf->data, size, m);
  if (st == hoist::msg::DecodeStatus::ok) return true;
  std::snprintf(text_, sizeof text_, "%zu bytes: %s", size, hoist::msg::toString(st));
  rejectSensor(channel, text_);
  return false;
}

bool ShaftInputs::sensorSeqNewer(std::int64_t seq, SensorSequence& sq, const char* channel) {
  const std::int64_t last = sq.last;
  switch (sq.next(seq)) {
    case SensorSequence::Verdict::Accept: return true;
    case SensorSequence::Verdict::Old:
      std::snprintf(text_, sizeof text_, "seq %lld not after %lld", static_cast<long long>(seq),
                    static_cast<long long>(last));
      rejectSensor(channel, text_);
      return false;
    case SensorSequence::Verdict::Restart: {
      std::int64_t suppressed = 0;
      if (log_limit_.allow(kLogSensor, ctx_.wallNow(), suppressed))
        ctx_.log.warn("{}{}: the sequence restarts at seq {} (after {}): a restarted sender, or {} samples in a row "
                      "behind one that was ahead [{} similar suppressed]",
                      ctx_.tag, channel, static_cast<long long>(seq), static_cast<long long>(last),
                      SensorSequence::kResyncAfter, suppressed);
      return true;
    }
  }
  return false;
}

void ShaftInputs::handleCageImu(const ::lcm::ReceiveBuffer* rbuf) {
  if (!decodeSensor(rbuf, imu_in_, bus::kChannelCageImu.data())) return;
  const cage_imu_t& m = imu_in_;
  const bool a_ok = std::isfinite(m.f_y) && std::abs(m.f_y) <= kMaxSpecificForce;
  const bool w_ok = std::isfinite(m.omega) && std::abs(m.omega) <= kMaxTiltRate;
  if (!a_ok && !w_ok) {
    std::snprintf(text_, sizeof text_, "f_y %g m/s^2 and omega %g rad/s implausible (|f_y| <= %g, |omega| <= %g)",
                  m.f_y, m.omega, kMaxSpecificForce, kMaxTiltRate);
    rejectSensor(bus::kChannelCageImu.data(), text_);
    return;
  }
  if (!sensorSeqNewer(m.seq, stats_.imu_seq, bus::kChannelCageImu.data())) return;
  // A channel that is implausible on its own is left out of this sample.
  const double wall = ctx_.wallNow();
  const SensorVerdict v = core_.onCageImu(m.utime, a_ok ? m.f_y : NAN, w_ok ? m.omega : NAN, wall,
                                               bus::wallUtime());
  if (!sensorTimeOk(v, m.utime, bus::kChannelCageImu.data())) return;
  stats_.last_imu_wall = wall;
  ++stats_.sensor_accepted;
}

bool ShaftInputs::sensorTimeOk(SensorVerdict v, std::int64_t utime, const char* channel) {
  // Refused by its time: counted (HOIST_HEALTH), logged (rate-limited), and
  // SENSOR_FAULT raised by the model room (published here).
  const double off = core_.lastSensorOffset();
  switch (v) {
    case SensorVerdict::Queued: return true;
    case SensorVerdict::NoClock: return false;  // no model time yet (--clock input before the winder)
    case SensorVerdict::ClockOffset:
      std::snprintf(text_, sizeof text_, "utime %lld is %+.3f s from the daemon's clock (%s), beyond "
                    "sensors.max_clock_offset = %g s: the sensor's clock is off; not used (SENSOR_FAULT)",
                    static_cast<long long>(utime), off,
                    core_.clock() == ClockMode::Wall ? "wall clock" : "the winder's utime",
                    ctx_.cfg.estimator.max_clock_offset);
      break;
    case SensorVerdict::TimeBackwards:
      std::snprintf(text_, sizeof text_, "utime %lld not after the last accepted sample's: time went backwards "
                    "(a replay, or the sensor's clock stepped back); not used (SENSOR_FAULT)",
                    static_cast<long long>(utime));
      break;
  }
  rejectSensor(channel, text_);
  out_.publishAlarmEvents();
  return false;
}

void ShaftInputs::handleRopeLoad(const ::lcm::ReceiveBuffer* rbuf) {
  if (!decodeSensor(rbuf, rope_in_, bus::kChannelRopeLoad.data())) return;
  const rope_load_t& m = rope_in_;
  if (!(std::isfinite(m.force) && std::abs(m.force) <= kMaxRopeLoad)) {
    std::snprintf(text_, sizeof text_, "force %g N implausible (|force| <= %g)", m.force, kMaxRopeLoad);
    rejectSensor(bus::kChannelRopeLoad.data(), text_);
    return;
  }
  if (!sensorSeqNewer(m.seq, stats_.rope_seq, bus::kChannelRopeLoad.data())) return;
  const double wall = ctx_.wallNow();
  const SensorVerdict v = core_.onRopeLoad(m.utime, m.force, wall, bus::wallUtime());
  if (!sensorTimeOk(v, m.utime, bus::kChannelRopeLoad.data())) return;
  stats_.last_rope_wall = wall;
  ++stats_.sensor_accepted;
}

}  // namespace hoist::service::app
