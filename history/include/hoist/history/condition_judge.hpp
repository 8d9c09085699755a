// hoist/history/condition_judge.hpp -- the shaft's condition alarms decided
// over its trip records, the one rule for hoist-twind's trip room and
// hoist-trips ingest (issue 32; docs/condition.md).
//
// A ConditionJudge holds the preload trend (hoist/preload_trend.hpp,
// GUIDE_PRELOAD_LOW) and the fingerprint (hoist/shaft_fingerprint.hpp,
// SHAFT_FINGERPRINT) of one shaft.  seed() reads the shaft's stored trips
// (with their depth bins) and the operator's baseline marks from a Store, in
// trip order -- at most the newest [condition] seed_trips and the baseline
// before them (hoist/history/judged_history.hpp: a bounded read) --;
// judge() adds each new record and appends the condition alarms it raises to
// the record's `alarms` (each name once).
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
  /// The shaft's history so far (readJudgedHistory: every stored trip of
  /// `shaft`, or the newest seed_trips and the baseline before them), the
  /// marked baseline trips first marked.  Returns how many trips were read.
  std::int64_t seed(Store& db, const std::string& shaft);
  /// After seed(): the newest stored trip number, and whether trips older
  /// than the window were left out.
  std::int64_t storedLastTrip() const { return stored_last_; }
  bool seededWindowed() const { return windowed_; }
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
  ConditionSettings cond_;
  PreloadTrend trend_;
  ShaftFingerprint finger_;
  std::int64_t trips_ = 0, last_trip_ = 0, stored_last_ = 0;
  bool windowed_ = false;
};

}  // namespace hoist::history
