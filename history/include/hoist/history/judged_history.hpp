// hoist/history/judged_history.hpp -- the stored trips a shaft's condition is
// judged from, read in bounded time whatever the history's length (issue 32;
// docs/condition.md "The condition alarms, live").
//
// The preload trend forgets: with a random walk of trend_walk per trip, a
// trip's weight in the combined s falls by the filter's (1 - gain) per later
// informative trip (gain 0.2-0.8), so trips more than a few hundred back
// weigh nothing (0.8^500 < 1e-48).  The fingerprint needs its baseline (the
// operator's marked trips, or the first baseline_trips trips of each
// direction) and the last 3 trips of each direction.  So a judge started on
// a shaft with years of trips reads the newest [condition] seed_trips trips
// (with their depth bins) and, when the baseline lies before them, the
// baseline trips: a bounded read instead of every trip ever stored.  A
// shaft with at most seed_trips trips (or seed_trips = 0) is read whole:
// the decisions are then exactly those of a full read.
//
// Who calls: ConditionJudge::seed (the daemon's trip room worker, hoist-trips)
// and hoist-dash's condition view.  Database reads: never on the real-time
// loop.  Throws StoreError as the Store does.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hoist/history/store.hpp"
#include "hoist/shaft_fingerprint.hpp"
#include "hoist/trip_pipeline.hpp"

namespace hoist::history {

struct JudgedHistory {
  /// Baseline trips older than the window, in trip order: the fingerprint's
  /// baseline only (marked ones via markBaseline, else add).
  std::vector<TripRecord> baseline;
  /// The window: the newest seed_trips trips (or all), in trip order.
  std::vector<TripRecord> trips;
  /// The operator's marked baseline trips of the shaft, ascending.
  std::vector<std::int64_t> marks;
  /// The newest stored trip number (0: none), and whether older trips were left out.
  std::int64_t last_trip = 0;
  bool windowed = false;
};

JudgedHistory readJudgedHistory(Store& db, const std::string& shaft, const ConditionSettings& cond);

/// The fingerprint's part before the window's trips are added in order: the
/// baseline trips before the window (marked ones marked, the others added:
/// they build the automatic baseline), then the window's marked trips.
/// `baseline` and `window` are JudgedHistory's (or a validated subset).
void primeFingerprint(const std::vector<TripRecord>& baseline, const std::vector<TripRecord>& window,
                      const std::vector<std::int64_t>& marks, ShaftFingerprint& finger);

}  // namespace hoist::history
