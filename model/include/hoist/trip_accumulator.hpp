// hoist/trip_accumulator.hpp -- fills one TripRecord (hoist/trip_record.hpp)
// from the trip's per-tick samples (issue 32).
//
// Fed, in time order, with what the twin knows at each tick: the winder's
// kinematics and the measured sensors (MeasurementSample) and the load
// estimate of that tick (TripEstimate, the record's fields of a LoadEstimate:
// the loads with sigmas, the state they imply, the model check).  begin() takes the departure sample (at rest),
// add() every later one up to the arrival confirmed (the rest after it
// included), finish() builds the record:
//   * kinematics: direction, start and end depth, peak |v| and |a|;
//   * the loads at departure and at the last sample (sigma -1 where the
//     estimate had not observed them);
//   * the model check: largest windowed NIS / dof, largest drift, MODEL_MISMATCH;
//   * min clearance (cageClearance of the estimate's y_c, theta and the
//     guide-rope deflection the caller passes) and its depth; lambda_0 min and
//     max, max |lambda_1..4|; the alarms the caller reports (addAlarm);
//   * per depth bin of the top sleeves' depth l, [k bin, (k + 1) bin): the
//     measured f_y split by a causal first-order low-pass at band_hz into the
//     model's band and above it; the residual = measured f_y minus the
//     identified model's prediction (identifyPreload: the twin's n-mode model
//     with the trip's identified moment and preload), so a preload that
//     changed shows in s and not as a residual at every depth, and what is
//     left is what the model cannot carry at that depth (SHAFT_FINGERPRINT);
//     y_c and theta of the estimate;
//   * the preload identification (identifyPreload).
// band_hz = 0 takes the twin's highest guide-rope mode,
//   f_n = n / (2 L) sqrt((max(Tb1, Tb2) + rho2 g L) / rho2),
// capped at a quarter of the sample rate.
//
// Who calls it: TripRecorder (hoist/trip_pipeline.hpp), offline and on the
// daemon's low-priority trip worker.  Not real-time: add() appends to
// buffers reserved for reserve_seconds at 100 Hz (beyond that it grows),
// finish() allocates and costs the identification (about 1 s CPU at n = 25).
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "hoist/load_estimator.hpp"
#include "hoist/trip_pipeline.hpp"
#include "hoist/trip_record.hpp"

namespace hoist {

/// The band split's corner [Hz] for `twin` (band_hz when > 0, else the highest guide-rope mode).
double conditionBandHz(const ShaftParams& twin, double band_hz);

/// What a trip record takes from one tick's LoadEstimate: the loads with
/// their sigmas, the state they imply, the model check.  The one list of
/// those fields -- a third of a LoadEstimate, so that the daemon's per-tick
/// copy into its trip rooms (service/app/trip_room.hpp) carries no more.
struct TripEstimate {
  double Fa = 0.0, sigma_Fa = -1.0, moment = 0.0, sigma_moment = -1.0, b = 0.0, sigma_b = -1.0;
  bool fa_observed = false, moment_observed = false, mismatch = false;
  int nis_dof = 0;
  double nis_window = 0.0, drift = 0.0;
  double y_c = 0.0, theta = 0.0;
  std::array<double, 5> lambda{};
};
/// The record's fields of `e`.
TripEstimate tripEstimate(const LoadEstimate& e);

class TripAccumulator {
 public:
  /// Throws std::invalid_argument for bad settings (cond.validate(), est.validate()).
  TripAccumulator(const ShaftParams& twin, const EstimatorSettings& est, const ConditionSettings& cond,
                  double max_step, double reserve_seconds = 300.0);

  /// Start a trip at its departure sample (at rest).  Forgets the previous trip.
  void begin(const MeasurementSample& m, const TripEstimate& e, double guide_deflection = 0.0);
  /// The next sample of the trip (after begin()).
  void add(const MeasurementSample& m, const TripEstimate& e, double guide_deflection = 0.0);
  /// An alarm kind raised during the trip (kept once).
  void addAlarm(std::string_view kind);
  /// Drop the trip under way (a motion that was not a trip, a new stream).
  void abandon() { active_ = false; }
  bool active() const { return active_; }
  std::size_t samples() const { return samples_.size(); }

  /// The record of the trip that arrived at t_arrival (the detector's
  /// arrivalTime(), <= the last sample's time): everything but shaft, trip
  /// number and wall-clock times.  Ends the trip (active() false).
  TripRecord finish(double t_arrival, const Kinematics& arrival);

 private:
  void take(const MeasurementSample& m, const TripEstimate& e, double guide_deflection);
  ShaftParams twin_;
  EstimatorSettings est_;
  ConditionSettings cond_;
  double max_step_;
  bool active_ = false;
  std::vector<MeasurementSample> samples_;
  std::vector<double> y_c_, theta_;
  TripRecord rec_;  // the running part (loads, peaks, model check, clearance)
  TripEstimate last_;
};

}  // namespace hoist
