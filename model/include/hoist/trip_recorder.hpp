// hoist/trip_recorder.hpp -- detector + accumulator: one TripRecord per trip
// from a stream of ticks (issue 32).  The one sequence both the offline
// pipeline (recordTrips, hoist/trip_pipeline.hpp) and the daemon's trip
// worker run, so a recording gives the same records live and offline.
//
// add() takes every tick in time order (sample + the estimate of that tick);
// it returns true when a trip has arrived: take the record with record()
// (valid until the next add()).  The departure sample is the last still
// sample before the motion (TripDetector): the recorder keeps the ticks since
// it, so the record starts at rest.  Not real-time (finish() identifies the
// preload): run it off the loop.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "hoist/trip_accumulator.hpp"
#include "hoist/trip_detector.hpp"

namespace hoist {

class TripRecorder {
 public:
  /// Throws std::invalid_argument for bad settings.
  TripRecorder(const ShaftParams& twin, const EstimatorSettings& est, const ConditionSettings& cond,
               double max_step);
  bool add(const MeasurementSample& m, const TripEstimate& e, double guide_deflection = 0.0);
  bool add(const MeasurementSample& m, const LoadEstimate& e, double guide_deflection = 0.0) {
    return add(m, tripEstimate(e), guide_deflection);
  }
  /// An alarm raised now: recorded in the trip under way (ignored at rest).
  void addAlarm(std::string_view kind) { acc_.addAlarm(kind); }
  TripRecord& record() { return rec_; }
  bool moving() const { return det_.moving(); }
  /// Trips recorded, and motions that ended shorter than the detector's min_travel.
  std::int64_t trips() const { return trips_; }
  std::int64_t notATrip() const { return not_a_trip_; }
  /// A new stream: the trip under way (if any) is dropped.
  void reset();

 private:
  TripDetector det_;
  TripAccumulator acc_;
  struct Pending {  // one tick since the last still sample, as add() got it
    MeasurementSample m;
    TripEstimate e;
    double guide_deflection;
  };
  std::vector<Pending> pending_;  // since the last still sample
  TripRecord rec_;
  std::int64_t trips_ = 0, not_a_trip_ = 0;
};

}  // namespace hoist
