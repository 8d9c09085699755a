// hoist/preload_trend.hpp -- the guide-rope preload over trips, and the
// GUIDE_PRELOAD_LOW decision (issue 32; docs/condition-identification.md).
//
// A scalar Kalman filter on the preload scale s with a random walk between
// trips: before each informative trip the variance grows by
// trend_walk^2 x (trips since the last update, counted by trip number), then
// the trip's s enters with its own variance sigma(s)^2 -- each trip weighted
// by its information.  Non-informative trips (sigma(s) > max_sigma, or not
// attempted) are ignored, except that their trip numbers let the walk grow.
// The first informative trip starts the filter (a flat prior: the configured
// preload is not assumed).  With trend_walk = 0.05 and per-trip sigmas of
// 0.03-0.1 the gain is 0.2-0.8: a step is followed within a trip or two,
// where a plain mean over N trips lags by N / 2.
//
// GUIDE_PRELOAD_LOW: the one-sided 95 % upper bound s + 1.645 sigma below
// preload_warning is WARNING, below preload_critical CRITICAL.  The text
// names the estimate, its sigma and the trips it rests on (those whose weight
// in the estimate is at least 5 %).  Pure: the daemon and hoist-trips decide
// on their own alarms' on/off and logging.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "hoist/trip_pipeline.hpp"

namespace hoist {

enum class ConditionLevel { None = 0, Warning = 1, Critical = 2 };

struct PreloadDecision {
  ConditionLevel level = ConditionLevel::None;
  bool valid = false;         ///< false until an informative trip was seen
  double scale = 1.0;         ///< combined s
  double sigma = -1.0;        ///< its sigma
  double upper95 = 0.0;       ///< s + 1.645 sigma
  std::vector<std::int64_t> trips;  ///< the trips it rests on (weight >= 5 %), oldest first
  std::string text;           ///< the alarm's text (or the state, when level is None)
};

class PreloadTrend {
 public:
  /// Throws std::invalid_argument for bad settings (cond.validate()).
  explicit PreloadTrend(const ConditionSettings& cond);
  /// The next trip (in trip order).  Returns true when its s was used.
  bool add(const TripRecord& r);
  bool valid() const { return valid_; }
  double scale() const { return s_; }
  double sigma() const { return valid_ ? std::sqrt(P_) : -1.0; }
  /// Weight of each trip in scale() (the filter's gains), oldest first.
  const std::vector<std::pair<std::int64_t, double>>& weights() const { return w_; }
  PreloadDecision decision() const;

 private:
  ConditionSettings cond_;
  bool valid_ = false;
  double s_ = 1.0, P_ = 0.0;
  std::int64_t last_trip_ = 0, seen_ = 0;
  std::vector<std::pair<std::int64_t, double>> w_;
};

}  // namespace hoist
