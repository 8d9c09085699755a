// hoist/trip_detector.hpp -- where a trip of the cage begins and ends, from
// the winder's kinematics alone (issue 32).
//
// A trip leaves rest, moves, and arrives and rests.  Rest is |v| <= rest_speed
// and |a| <= rest_speed (the load estimator's [estimator] rest_speed, so the
// two agree on "at rest").  With hysteresis against a winder signal that
// hovers near the threshold:
//   * departure: |v| or |a| above leave_factor x rest_speed; the trip starts
//     at the last rest sample before it (the cage's static state);
//   * arrival: rest held for rest_hold seconds without a break; the trip ends
//     at the first sample of that rest (Arrived is reported rest_hold later,
//     so the trip's samples include rest_hold of rest at the end depth).
// A motion shorter than min_travel (an inching of the winder) is not a trip:
// NotATrip is reported instead of Arrived.  A run that starts moving waits
// for the first rest (its first motion has no known departure).
//
// Who calls it: recordTrips (offline) and the daemon's trip worker, once per
// sample in time order.  Allocation-free, O(1) per sample.
#pragma once

#include "hoist/profile.hpp"

namespace hoist {

struct TripDetectorSettings {
  double rest_speed = 0.01;   ///< [m/s] and [m/s^2]: at rest at or below (the estimator's rest_speed)
  double leave_factor = 2.0;  ///< departure when |v| or |a| > leave_factor x rest_speed (>= 1)
  double rest_hold = 1.0;     ///< rest held this long is an arrival [s]
  double min_travel = 0.5;    ///< a shorter motion is not a trip [m]
  /// Throws std::invalid_argument naming the field at fault.
  void validate() const;
};

enum class TripEvent {
  None,      ///< nothing new
  Departed,  ///< a trip began (departureTime(), departure())
  Arrived,   ///< the trip ended (arrivalTime(), arrival())
  NotATrip,  ///< the motion ended at rest, but moved less than min_travel
};

class TripDetector {
 public:
  explicit TripDetector(const TripDetectorSettings& s);
  /// Forget everything (a new recording / winder stream): wait for rest.
  void reset();
  /// The next sample (t increasing).  Returns what it completed.
  TripEvent update(double t, const Kinematics& k);

  bool moving() const { return state_ == State::Moving; }
  /// |v| and |a| at or below rest_speed (the rest of a departure and an arrival).
  bool still(const Kinematics& k) const;
  double departureTime() const { return t_dep_; }
  const Kinematics& departure() const { return k_dep_; }
  double arrivalTime() const { return t_arr_; }
  const Kinematics& arrival() const { return k_arr_; }
  const TripDetectorSettings& settings() const { return set_; }

 private:
  enum class State { Unknown, Rest, Moving };
  TripDetectorSettings set_;
  State state_ = State::Unknown;
  double t_rest_ = 0.0;          // last rest sample (the candidate departure)
  Kinematics k_rest_;
  bool resting_ = false;         // in a rest run while Moving
  double t_dep_ = 0.0, t_arr_ = 0.0;
  Kinematics k_dep_, k_arr_;
};

}  // namespace hoist
