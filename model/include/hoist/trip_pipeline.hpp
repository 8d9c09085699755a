// hoist/trip_pipeline.hpp -- the shaft's memory, offline and live (issue 32,
// docs/condition-identification.md): a recorded run split into trips, one
// TripRecord per trip with the guide-rope preload identified.
//
// Who calls it: hoist-trips ingest (tools/trips) on a measurement CSV.  The
// daemon's trip worker runs the same sequence tick by tick with TripRecorder
// (hoist/trip_recorder.hpp: TripDetector + TripAccumulator, which calls
// identifyPreload), so a recording gives the same records live and offline.
// The trend and the condition alarms' decisions over many records live in
// hoist/preload_trend.hpp (GUIDE_PRELOAD_LOW) and hoist/shaft_fingerprint.hpp
// (SHAFT_FINGERPRINT).
//
// Pure math: no files, no LCM, no logging.  Not real-time code: it allocates
// and costs up to about 1 s of CPU per trip at n = 25 (the identification);
// run it off the loop.
#pragma once

#include <functional>
#include <vector>

#include "hoist/clearance.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/params.hpp"
#include "hoist/trip_record.hpp"

namespace hoist {

/// [condition] in the daemon's config (and hoist-trips).  validate() names
/// the key at fault ("condition.depth_bin: must be > 0 (got -1)").
struct ConditionSettings {
  double depth_bin = 10.0;          ///< condition.depth_bin: depth-bin size of the record [m]
  double max_sigma = 0.1;           ///< condition.max_sigma: a trip with sigma(s) above this is not informative
  double band_hz = 0.0;             ///< condition.band_hz: model band for the f_y split [Hz] (0: from the twin's highest mode)
  int baseline_trips = 10;          ///< condition.baseline_trips: commissioning fingerprint, trips per direction
  double fingerprint_sigma = 4.0;   ///< condition.fingerprint_sigma: SHAFT_FINGERPRINT threshold [baseline sd]
  double preload_warning = 0.85;    ///< condition.preload_warning: GUIDE_PRELOAD_LOW WARNING below (95 % confidence)
  double preload_critical = 0.70;   ///< condition.preload_critical: ... CRITICAL below (95 % confidence)
  double trend_walk = 0.05;         ///< condition.trend_walk: random walk of s between trips (sigma per trip)
  /// condition.model_check_sigma: MODEL_MISMATCH when a trip's whole-trip fit
  /// puts the preload scale more than this many of its sigmas from the scale
  /// the twin runs (hoist/preload_verdict.hpp).
  double model_check_sigma = 4.0;
  /// condition.seed_trips: the newest stored trips a judge reads at start
  /// (plus the baseline before them; hoist/history/judged_history.hpp); 0: all.
  int seed_trips = 500;
  /// Prior sigma of the accelerometer's offset [m/s^2] in the preload fit:
  /// not a [condition] key -- the caller copies [sensors] imu_accel_offset_sigma
  /// here (issue 30); 0 declares a calibrated accelerometer (no offset fitted).
  double accel_offset_sigma = 0.0;
  /// Gaps for the record's min clearance ([alarms] gap_*; not [condition] keys).
  /// The offline pipeline counts the cage's excursions only (no guide-rope envelope).
  ClearanceLimits clearance;
  /// Throws std::invalid_argument naming the [condition] key of the first bad value.
  void validate() const;
};

/// Split a recorded run into trips (rest -> moving -> rest, TripDetector with
/// est.rest_speed) and build one TripRecord each: everything but the wall-clock
/// times, the shaft name and the alarms (the caller knows those; the trip
/// number counts from 1 in this run), with the preload identified
/// (identifyPreload).  The loads and the model check come from the load
/// estimator run over the whole recording exactly as estimateRecorded runs it
/// (`twin`, `est`, `max_step`), so they match hoist-estimate.  A run that ends
/// while moving yields no record for the unfinished trip.  `progress`
/// (optional) gets the fraction done.  Throws std::invalid_argument for bad
/// settings, std::domain_error as the solver does.
std::vector<TripRecord> recordTrips(const ShaftParams& twin, const EstimatorSettings& est,
                                    const ConditionSettings& cond, double max_step,
                                    const std::vector<MeasurementSample>& samples,
                                    const std::function<void(double)>& progress = {});

}  // namespace hoist
