// TripDetector: rest -> moving -> rest with hysteresis (hoist/trip_detector.hpp).
#include "hoist/trip_detector.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hoist {

void TripDetectorSettings::validate() const {
  auto bad = [](const char* key, double v, const char* rule) {
    throw std::invalid_argument(std::string(key) + ": " + rule + " (got " + std::to_string(v) + ")");
  };
  if (!(std::isfinite(rest_speed) && rest_speed > 0.0)) bad("rest_speed", rest_speed, "must be > 0");
  if (!(std::isfinite(leave_factor) && leave_factor >= 1.0)) bad("leave_factor", leave_factor, "must be >= 1");
  if (!(std::isfinite(rest_hold) && rest_hold >= 0.0)) bad("rest_hold", rest_hold, "must be >= 0");
  if (!(std::isfinite(min_travel) && min_travel >= 0.0)) bad("min_travel", min_travel, "must be >= 0");
}

TripDetector::TripDetector(const TripDetectorSettings& s) : set_(s) { set_.validate(); }

void TripDetector::reset() {
  state_ = State::Unknown;
  resting_ = false;
}

bool TripDetector::still(const Kinematics& k) const {
  return std::abs(k.v) <= set_.rest_speed && std::abs(k.a) <= set_.rest_speed;
}

TripEvent TripDetector::update(double t, const Kinematics& k) {
  const double leave = set_.leave_factor * set_.rest_speed;
  const bool departs = std::abs(k.v) > leave || std::abs(k.a) > leave;
  switch (state_) {
    case State::Unknown:
      if (still(k)) {
        state_ = State::Rest;
        t_rest_ = t;
        k_rest_ = k;
      }
      return TripEvent::None;
    case State::Rest:
      if (!departs) {
        if (still(k)) {  // between the thresholds: keep the last truly still sample
          t_rest_ = t;
          k_rest_ = k;
        }
        return TripEvent::None;
      }
      state_ = State::Moving;
      resting_ = false;
      t_dep_ = t_rest_;
      k_dep_ = k_rest_;
      return TripEvent::Departed;
    case State::Moving:
      if (!still(k)) {
        resting_ = false;
        return TripEvent::None;
      }
      if (!resting_) {
        resting_ = true;
        t_arr_ = t;
        k_arr_ = k;
      }
      if (t - t_arr_ < set_.rest_hold - 1e-9) return TripEvent::None;
      state_ = State::Rest;
      resting_ = false;
      t_rest_ = t;
      k_rest_ = k;
      return std::abs(k_arr_.l - k_dep_.l) < set_.min_travel ? TripEvent::NotATrip : TripEvent::Arrived;
  }
  return TripEvent::None;
}

}  // namespace hoist
