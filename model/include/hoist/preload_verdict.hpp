// hoist/preload_verdict.hpp -- MODEL_MISMATCH's trip-end test: does the
// whole trip's tilt agree with the guide-rope preload the twin runs?
//
// The load estimator's own model check (hoist/load_estimator.hpp) looks at
// seconds of data: its constancy test sees a load that seems to change with
// depth.  A uniformly weak (or strong) preload scales the cage's torsional
// stiffness, so theta = M / k reads as a steady, wrong moment: with the
// accelerometer's offset free (the default) the offset absorbs what little
// depth shape is left within ten seconds, and the estimate is confidently
// wrong (a 30 % loss: M 50-70 % high at 15 sigma, no word; issue 30).  The
// whole trip can tell: identifyPreload (hoist/preload_identification.hpp)
// fits the preload scale s jointly with M and the offset over the depth
// range, where the offset is one constant and s bends the tilt's depth shape.
//
// The rule: the trip's identified s +- sigma(s) against the scale the twin
// runs (1, or the one an operator adopted: hoist-alarm-ack --adopt-preload):
//     z = (s - s_twin) / sigma(s),   mismatch when |z| > limit
// ([condition] model_check_sigma, default 4).  Two-sided: a stiffer shaft
// than the twin's biases M low just as a weaker one biases it high.  A trip
// that did not identify s (no IMU, no motion, M within 3 sigma of zero)
// judges nothing: the last verdict stands until a trip that judges, or until
// the twin's model changes (an adoption).  The same rule on the shaft's
// memory (judgeTrendPreload: the preload trend over the informative trips,
// hoist/preload_trend.hpp) sees what one uncalibrated trip cannot: a 30 %
// loss is 2-7 sigma per trip with the offset free, several trips add up.
// The daemon raises MODEL_MISMATCH when either fires.  docs/estimation.md,
// "The model check" (test 3), has the false-alarm and detection table.
//
// Pure math, no allocation: describe() writes into a caller's buffer.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hoist/preload_trend.hpp"
#include "hoist/trip_record.hpp"

namespace hoist {

struct PreloadVerdict {
  bool judged = false;        ///< the trip identified s (sigma(s) > 0)
  bool mismatch = false;      ///< |z| > limit
  double z = 0.0;             ///< (s - twin_scale) / sigma(s)
  double limit = 4.0;         ///< [condition] model_check_sigma
  double scale = 1.0;         ///< s identified from the trip
  double sigma_scale = -1.0;  ///< its sigma (< 0: not judged)
  double twin_scale = 1.0;    ///< the scale the twin ran during the trip
  double moment = 0.0;        ///< M of the trip's joint fit (at s) [N m]; not for a trend
  double sigma_moment = -1.0;
  /// 0: one trip's fit.  Otherwise the trend over the shaft's informative
  /// trips, which rests on trips first_trip .. last_trip (weight >= 5 %).
  int trend_trips = 0;
  std::int64_t first_trip = 0, last_trip = 0;
};

/// The verdict of one trip's identification `id` on a twin running the
/// guide-rope preloads times `twin_scale`.  `limit` > 0.
PreloadVerdict judgeTripPreload(const PreloadIdentification& id, double twin_scale, double limit);

/// The verdict of the shaft's preload trend `d` (PreloadTrend::decision(),
/// the shaft's memory) on a twin running `twin_scale`: judged once the trend
/// is valid.  `limit` > 0.
PreloadVerdict judgeTrendPreload(const PreloadDecision& d, double twin_scale, double limit);

/// One sentence for the alarm text and the logs, at most about 200 bytes
/// ("whole-trip fit: preload x0.71 +- 0.05, 5.8 sigma from the twin's x1
/// (bound 4): shaft softer, moment reads high (fit: M = 912 +- 40 N m);
/// adopt (hoist-alarm-ack --adopt-preload) or re-tension"), into buf[0..n)
/// (terminated; no allocation).
void describe(const PreloadVerdict& v, char* buf, std::size_t n);

}  // namespace hoist
