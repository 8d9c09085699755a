// hoist/history/condition_judge.hpp -- the shaft's condition alarms decided
// over its trip records, the one rule for hoist-twind's trip room and
// hoist-trips ingest (issue 32; docs/condition.md).
//
// A ConditionJudge holds the preload trend (hoist/preload_trend.hpp,
// GUIDE_PRELOAD_LOW) and the fingerprint (hoist/shaft_fingerprint.hpp,
// SHAFT_FINGERPRINT) of one shaft.  seed() reads the shaft's stored trips
// (with their depth bins) and the operator's baseline marks from a Store, in
// trip order; judge() adds each new record and appends the condition alarms
// it raises to the record's `alarms` (each name once).
//
// Who calls: one thread (the trip room's worker; hoist-trips).  seed() does
// database reads (never on the real-time loop) and throws StoreError as the
// Store does.  Not thread-safe.
#pragma once

#include <cstdint>
#include <string>

#include "hoist/history/store.hpp"
#include "hoist/preload_trend.hpp"
#include "hoist/shaft_fingerprint.hpp"

namespace hoist::history {

class ConditionJudge {
 public:
  /// Throws std::invalid_argument for bad settings (cond.validate()).
  explicit ConditionJudge(const ConditionSettings& cond);
  /// The shaft's history so far: every stored trip of `shaft` (with bins),
  /// the marked baseline trips first marked.  Returns how many trips.
  std::int64_t seed(Store& db, const std::string& shaft);
  /// The next record (trip order; r.trip set).  Appends MODEL_MISMATCH (when
  /// r.mismatch), GUIDE_PRELOAD_LOW and SHAFT_FINGERPRINT to r.alarms when
  /// they are active after it, each only if not there already.
  void judge(TripRecord& r);
  PreloadDecision preload() const { return trend_.decision(); }
  FingerprintDecision fingerprint() const { return finger_.decision(); }
  /// The trips seen (seeded and judged), and the last trip number.
  std::int64_t trips() const { return trips_; }
  std::int64_t lastTrip() const { return last_trip_; }
  /// One line: the preload's text, and the fingerprint's when it is active.
  std::string summary() const;

 private:
  void add(const TripRecord& r);
  PreloadTrend trend_;
  ShaftFingerprint finger_;
  std::int64_t trips_ = 0, last_trip_ = 0;
};

}  // namespace hoist::history
