// hoist/shaft_fingerprint.hpp -- the shaft's commissioning fingerprint and
// the SHAFT_FINGERPRINT decision (issue 32; docs/condition-identification.md).
//
// What is compared: each record's depth bins' residual mean (measured f_y
// minus the identified model's prediction, hoist/trip_accumulator.hpp): what
// the twin cannot carry at that depth, with the trip's load and preload
// already fitted.  Per direction (down and up trips see different dynamics):
//   * baseline: the first baseline_trips trips of that direction, or the
//     trips an operator marks (markBaseline; once one is marked, only marked
//     trips form that direction's baseline).  Per bin: mean and sample
//     standard deviation of resid_mean over the baseline trips;
//   * every later trip: z = (resid_mean - baseline mean) / sd with
//     sd = sqrt(baseline variance + the trip's own standard error
//     resid_rms^2 / samples) (a 10-trip spread can be low by chance; the
//     trip's own noise bounds it from below);
//   * SHAFT_FINGERPRINT (WARNING): a bin with |z| > fingerprint_sigma on at
//     least 2 of the last 3 trips in the same direction.  The text names the
//     depth (the bin [depth_lo, depth_lo + depth_bin) of the top sleeves), the
//     direction and the z values, strongest first: a local disturbance also
//     leaves weaker hits where the oscillation it excites is still seen
//     (after it in the direction of travel), named after it with "also".
// Bins with fewer than min_samples samples in the trip or in fewer than two
// baseline trips are not tested.  Pure: no I/O; the caller owns alarm state.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "hoist/trip_pipeline.hpp"

namespace hoist {

struct FingerprintHit {
  TripDirection direction = TripDirection::Down;
  double depth_lo = 0.0;  ///< the bin [depth_lo, depth_lo + depth_bin) [m]
  int trips_over = 0;     ///< of the last 3 trips in that direction
  double z_last = 0.0;    ///< z of the last trip in that direction
  double strength = 0.0;  ///< mean |z| over the trips beyond the threshold (orders the hits)
};

struct FingerprintDecision {
  bool active = false;
  std::vector<FingerprintHit> hits;  ///< every bin that meets the rule, strongest first
  std::string text;
};

class ShaftFingerprint {
 public:
  static constexpr int kMinSamples = 10;
  /// Throws std::invalid_argument for bad settings (cond.validate()).
  explicit ShaftFingerprint(const ConditionSettings& cond);
  /// An operator marks `r` as a baseline trip of its direction.
  void markBaseline(const TripRecord& r);
  /// The next trip: joins the baseline while it is being built (and no
  /// operator baseline exists), else is tested.  Returns true when tested.
  bool add(const TripRecord& r);
  bool baselineComplete(TripDirection d) const;
  /// z per bin of the last tested trip in direction d (depth_lo -> z).
  const std::map<long, double>& lastZ(TripDirection d) const { return dir(d).last_z; }
  FingerprintDecision decision() const;

 private:
  struct BinStat {
    int n = 0;
    double sum = 0.0, sum2 = 0.0;
  };
  struct Direction {
    std::map<long, BinStat> base;
    int base_trips = 0;
    bool operator_marked = false;
    std::vector<std::map<long, double>> recent;  // z of the last 3 tested trips
    std::map<long, double> last_z;
  };
  Direction& dir(TripDirection d) { return d == TripDirection::Down ? down_ : up_; }
  const Direction& dir(TripDirection d) const { return d == TripDirection::Down ? down_ : up_; }
  void addToBaseline(Direction& d, const TripRecord& r);
  long binIndex(double depth_lo) const;
  ConditionSettings cond_;
  Direction down_, up_;
};

}  // namespace hoist
