// hoist/mqtt/trip_feed.hpp -- hoist-mqtt's view of the history database
// (issue 32, docs/condition.md): the last trip record of each bridged shaft
// as the retained `hoist/<shaft>/trip/last` JSON, and the shaft's condition
// (the preload trend's GUIDE_PRELOAD_LOW decision) for the Sparkplug
// Condition/... metrics.  The daemon publishes no trip message on LCM
// (msgs/ has none): the bridge reads the database the daemon writes.
//
// Who calls: the bridge makes one TripFeed when `[history] url` is set,
// watch()es each shaft it bridges and take()s what is new from its own loop
// (non-blocking: a copy under a mutex).  A worker thread of its own opens
// the Store read-only (SQLite: never created or migrated; PostgreSQL: reads
// only) and every `poll_s` checks each watched shaft's next trip number
// (one MAX query); when it moved, it reads the shaft's trips, leaves out
// those history::implausible() refuses (counted, logged), replays the
// trend (hoist/preload_trend.hpp) and queues one TripUpdate.  A database
// that is missing or unreachable is logged once per change of message and
// retried at every poll; nothing is published from it meanwhile.  Never
// throws out of the thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "hoist/history/store.hpp"
#include "hoist/mqtt/sparkplug_metrics.hpp"
#include "hoist/trip_pipeline.hpp"

namespace hoist::mqtt {

/// The Sparkplug Condition/... values of a shaft (sparkplug_metrics.hpp).
using ConditionMetrics = sparkplug::ConditionValues;

struct TripUpdate {
  std::string shaft;       ///< the MQTT shaft name it was watched under
  nlohmann::json last;     ///< the trip/last payload (tripSummary)
  ConditionMetrics cond;
};

/// The trip/last payload: the hoist-trips list columns (trip, direction,
/// t_start, t_end, Fa, sigma_Fa, moment, sigma_moment, preload_scale,
/// sigma_preload_scale, mismatch, alarms [kinds], shaft, wall_start,
/// wall_end (ISO 8601 UTC), depth_start, depth_end, peak_speed, informative,
/// imbalance, sigma_imbalance, nis_peak, min_clearance), the identification
/// ("identification": attempted, scale, sigma_scale, moment, sigma_moment,
/// imbalance, sigma_imbalance, informative, loss30_separation, note) and the
/// condition ("condition": preload_scale, sigma, level NONE/WARNING/CRITICAL,
/// trips_in_trend, text).  A sigma that was not observed is null.
nlohmann::json tripSummary(const TripRecord& r, const ConditionMetrics& c, const std::string& level_text);

/// The database shaft of an MQTT shaft name ("default" is the default shaft, "").
std::string dbShaft(const std::string& mqtt_shaft);

class TripFeed {
 public:
  TripFeed(history::StoreOptions store, ConditionSettings cond, double poll_s);
  ~TripFeed();
  TripFeed(const TripFeed&) = delete;
  TripFeed& operator=(const TripFeed&) = delete;

  /// Follow this shaft (an MQTT shaft name); its current last trip is
  /// reported at the next poll.
  void watch(const std::string& shaft);
  /// The updates since the last call (oldest first).
  std::vector<TripUpdate> take();
  std::int64_t rejected() const;  ///< records left out so far

  /// One shaft's update from `store` now (nullopt-like: empty shaft when the
  /// shaft has no trip).  Throws history::StoreError.  For the tests.
  static TripUpdate read(history::Store& store, const std::string& shaft, const ConditionSettings& cond,
                         std::int64_t* rejected = nullptr);

 private:
  void run();
  history::StoreOptions store_opt_;
  ConditionSettings cond_;
  double poll_s_;
  mutable std::mutex mu_;
  std::map<std::string, std::int64_t> watched_;  // shaft -> next trip seen (-1: not yet)
  std::vector<TripUpdate> out_;
  std::int64_t rejected_ = 0;
  bool stop_ = false;
  std::condition_variable wake_;
  std::thread worker_;
};

}  // namespace hoist::mqtt
