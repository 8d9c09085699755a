// hoist/dash condition.hpp -- the "Shaft condition" view's data: the trip
// records of the history database (hoist/history/store.hpp, issue 32,
// docs/condition.md), read-only, as one JSON snapshot the server hands out
// at GET /api/condition.
//
// Who calls: hoist-dash's main() makes one ConditionView (when --history is
// given); the server's I/O thread calls snapshot() per request (a copy of a
// string under a mutex held only for that copy: never a database call).  A
// worker thread of its own opens the store read-only (SQLite: never created
// or migrated; PostgreSQL: the Store's own connection, reads only) and polls
// it every `poll_s`: the cheap change check is Store::nextTrip(shaft) (one
// MAX query); the full snapshot is rebuilt when it moved, and every
// `rebuild_s` anyway (pruned trips, baseline marks).  A database that is
// missing, refused (newer schema, not ours) or unreachable is a snapshot
// with ok = false and the message, logged once per change of message; the
// worker retries at the next poll.  Never throws out of the thread.
//
// Validation (any value from a database is file input): the Store checks
// every column's kind and range when reading (schema.hpp valueError); here
// each record also passes history::recordError (finite numbers, direction,
// bins in order) and the identification must be plausible (0 < s <= 5,
// sigma <= 5); a record that fails is left out of the view and counted
// ("rejected", with its reason).
//
// The snapshot (build()): {"ok", "error", "db", "shaft", "generation",
// "updated_us", "trips", "rejected", "rejected_notes", "thresholds"
// {warning, critical, max_sigma}, "trend" [{trip, direction, attempted,
// informative, s, sigma, combined, combined_sigma}], "preload" (the
// GUIDE_PRELOAD_LOW decision of hoist/preload_trend.hpp: level, valid,
// scale, sigma, upper95, trips, text), "fingerprint" (the SHAFT_FINGERPRINT
// decision of hoist/shaft_fingerprint.hpp: active, text, hits), "heatmap"
// {value: "resid_rms", bin, trips [n], depths [m], cells [trip][depth]
// (null: no samples)}, "last" (the last trip's record as
// history::recordToJson, with its bins)}.  At most `max_trips` (the latest)
// enter the trend and the heat map.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "hoist/history/store.hpp"
#include "hoist/trip_pipeline.hpp"

namespace hoist::dash {

struct ConditionOptions {
  history::StoreOptions store;  ///< read_only is forced on
  std::string shaft;            ///< the shaft's name in the database ("" = the default shaft)
  ConditionSettings cond;       ///< thresholds, max_sigma, trend_walk, fingerprint
  double poll_s = 2.0;          ///< change check period [s]
  double rebuild_s = 60.0;      ///< full rebuild at least this often [s]
  std::size_t max_trips = 500;  ///< latest trips in the trend and heat map
};

/// The options of hoist-dash's --history URL, --config FILE (hoist-twind's
/// configuration: its [history] url when --history is not given, relative
/// to the file's folder, its password settings, and its [condition]
/// thresholds) and --history-shaft NAME.  Throws std::invalid_argument
/// naming the option ("--history: ...", "FILE: history.url: ...") and
/// io::ConfigError (file:line) for a bad configuration file.
ConditionOptions conditionOptions(const std::string& history_url, const std::string& config,
                                  const std::string& shaft);

class ConditionView {
 public:
  /// Starts the worker (the first snapshot says "loading" until it ran).
  explicit ConditionView(ConditionOptions o);
  ~ConditionView();  ///< stops and joins the worker
  ConditionView(const ConditionView&) = delete;
  ConditionView& operator=(const ConditionView&) = delete;

  /// The latest snapshot as JSON text (thread-safe, no database access).
  std::string snapshot() const;
  /// Snapshots built so far (tests wait on it).
  std::uint64_t generation() const { return generation_.load(); }

  /// The snapshot of `store` now (throws history::StoreError on a database
  /// error).  Pure apart from the store's reads: the unit tests call it.
  static nlohmann::json build(history::Store& store, const std::string& shaft, const ConditionSettings& cond,
                              std::size_t max_trips);

 private:
  void run();
  void publish(nlohmann::json j);
  ConditionOptions opt_;
  mutable std::mutex mu_;
  std::string json_;
  std::atomic<std::uint64_t> generation_{0};
  std::mutex wake_mu_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread worker_;
};

}  // namespace hoist::dash
