// TripRoom: one shaft's memory (issue 32, docs/condition.md "Live").
//
// The loop thread copies one compact TripTick per model step (afterStep:
// the winder's kinematics, the sensor values applied with their presence
// bits, the load estimate, the guide-rope deflection, the wall clock and the
// active alarm kinds) into a preallocated single-producer single-consumer
// ring: no allocation, no lock, no I/O, a fixed copy.  A full ring drops
// the tick (counted: the trip's record then misses samples) -- the loop
// never waits.
//
// A worker of the daemon's TripPool (trip_pool.hpp: a few threads for
// every shaft) opens the history database (hoist::history::Store) off the loop (pruning
// trips older than [history] keep_days then and after each trip), drains the
// ring every kDrainPeriod, runs the trip pipeline (hoist::TripRecorder: TripDetector,
// TripAccumulator, identifyPreload) and, at each trip's end, fills in the
// shaft's name, the wall-clock times and the alarms raised during the trip
// and puts the record into the store.  A store that cannot be opened or a
// put that fails is logged and counted; the twin runs on.  The worker logs
// through spdlog directly (not the loop's RtLog).
//
// The shaft's condition (GUIDE_PRELOAD_LOW, SHAFT_FINGERPRINT): the worker
// keeps a hoist::history::ConditionJudge, seeded from the shaft's stored
// trips when the database opens, and judges each new record before it is
// stored (the record's alarms then name the condition alarms too).  After
// the seeding and after each trip it hands a ConditionState to the loop
// through a LatestMailbox; the loop takes it (takeCondition: no allocation,
// no lock) and sets the alarms.  So a daemon restarted on a shaft whose
// preload is low raises the alarm again from its history; a database that
// cannot be read is logged as an error (the alarm cannot be judged) and the
// judge goes on from the trips this run records.
//
// Lifetimes: owned by ShaftTwin; outlives the pool's TripPool::stop(), which
// drains the ring a last time and closes the store (a trip under way at stop
// is not recorded: it did not end).  counters() may
// be read from any thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "condition_text.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/preload_verdict.hpp"
#include "hoist/trip_accumulator.hpp"
#include "hoist/rt/latest_mailbox.hpp"
#include "hoist/service/core/config.hpp"
#include "hoist/service/cfg/history_config.hpp"
#include "hoist/service/twin/twin_core.hpp"
#include "trip_pool.hpp"

namespace hoist::service::inline app {

/// What the loop copies per step.
struct TripTick {
  MeasurementSample m;             ///< t (model), kinematics, sensors applied, present bits
  TripEstimate e;                  ///< the record's fields of the estimate (the twin's state with the estimator off)
  double guide_deflection = 0.0;   ///< the guide-rope envelope's deflection [m]
  std::int64_t wall_us = 0;        ///< wall clock of the step [us since the epoch]
  std::uint32_t alarms = 0;        ///< bit k: AlarmKind k active
  double twin_preload_scale = 1.0; ///< the guide-rope preload scale the twin ran (TwinCore::preloadScale)
};

/// The condition alarms' inputs, from the worker to the loop (fixed size).
struct ConditionState {
  AlarmLevel preload = AlarmLevel::None;  ///< GUIDE_PRELOAD_LOW's level
  double upper95 = 0.0;                   ///< the combined preload scale's 95 % upper bound
  double warning = 0.85, critical = 0.70; ///< [condition] preload_warning, preload_critical
  bool fingerprint = false;               ///< SHAFT_FINGERPRINT active
  double z = 0.0, z_limit = 4.0;          ///< the strongest hit's last z; fingerprint_sigma
  std::int64_t trips = 0;                 ///< the trips judged (stored ones included)
  /// The last trip recorded by this run (estimate_t.detect_trip etc.):
  /// its number (0: none yet), 0.3 / sigma(s), informative.
  std::int64_t detect_trip = 0;
  double loss30_separation = -1.0;
  bool loss30_visible = false;
  ConditionText preload_text{};   ///< the trend's text (cut to fit)
  ConditionText fingerprint_text{};
  /// MODEL_MISMATCH's trip-end preload test (hoist/preload_verdict.hpp): the
  /// last trip that judged it.  verdict_trip counts the verdicts (0: none
  /// yet): the loop applies a verdict once, so one it dropped after an
  /// adoption is not raised again by the next publication.
  std::int64_t verdict_trip = 0;
  bool verdict_mismatch = false;
  double verdict_z = 0.0, verdict_limit = 4.0;
  double verdict_twin_scale = 1.0;  ///< the twin's preload scale the verdict judged
  ConditionText verdict_text{};
};

/// Fixed-capacity SPSC ring of TripTick (lock-free; one producer thread,
/// one consumer thread).
class TripRing {
 public:
  explicit TripRing(std::size_t capacity);
  /// Producer: false when full (nothing written).
  bool push(const TripTick& t);
  /// Consumer: false when empty.
  bool pop(TripTick& out);
  std::size_t capacity() const { return buf_.size(); }

 private:
  std::vector<TripTick> buf_;
  alignas(64) std::atomic<std::size_t> head_{0};  // next write (producer)
  alignas(64) std::atomic<std::size_t> tail_{0};  // next read (consumer)
};

/// The room's figures (atomics: the loop and the worker write, the final
/// log line and HOIST_HEALTH read them: shaft_health.cpp).
struct TripCounters {
  std::atomic<std::int64_t> ticks{0};        ///< ticks copied into the ring (loop side)
  std::atomic<std::int64_t> trips{0};        ///< trips recorded (records built)
  std::atomic<std::int64_t> stored{0};       ///< records written to the database
  std::atomic<std::int64_t> queued{0};       ///< records put into the PostgreSQL outage queue
  std::atomic<std::int64_t> failed{0};       ///< records the store refused or could not write
  std::atomic<std::int64_t> dropped{0};      ///< ticks dropped: the ring was full (loop side)
  std::atomic<std::int64_t> not_a_trip{0};   ///< motions shorter than a trip
  std::atomic<std::int64_t> cpu_ns{0};       ///< worker CPU time, all of it [ns]
  std::atomic<std::int64_t> cpu_ns_last{0};  ///< worker CPU time of the last trip's record [ns]
  std::atomic<bool> store_open{false};       ///< the database is open
  std::atomic<bool> judged{false};           ///< the condition has been judged once (after the seeding)
};

class TripRoom : public TripWork {
 public:
  /// Ring of `capacity` ticks (default: 30 s at the step rate, at least 1024).
  /// Throws std::invalid_argument for bad [condition] settings.
  TripRoom(const TwinConfig& cfg, const TripHistoryConfig& hist, std::string shaft_name, std::size_t capacity = 0);
  ~TripRoom() override;
  TripRoom(const TripRoom&) = delete;
  TripRoom& operator=(const TripRoom&) = delete;

  /// Loop thread, after each model step: one tick copied into the ring.
  /// Allocation-free; never blocks.
  void afterStep(const TwinCore& core, std::int64_t wall_us);
  /// Loop thread: the newest condition since the last call, or nullptr.
  /// Valid until the next call.  Allocation-free; never blocks.
  const ConditionState* takeCondition() { return condition_.take(); }
  // The worker's side (TripWork: its TripPool worker, one thread for the
  // room's life, never the loop).
  void workerOpen() override;
  void workerDrain() override;
  void workerClose() override;

  const TripCounters& counters() const { return counts_; }
  /// The store's description ("sqlite /path"), known once open ("" before).
  std::string describeStore() const;

 private:
  void take(const TripTick& t);  // worker: one tick into the recorder
  void finishTrip();             // worker: the record to the store
  void pruneOld(std::int64_t now_us);  // worker: [history] keep_days (at open and after each trip)
  void publishCondition();             // worker: the judge's verdicts to the loop
  /// Worker: MODEL_MISMATCH's trip-end preload verdict from this trip's own
  /// (`trip`) and the shaft's trend (`trend`), logged; false: neither judged.
  bool noteVerdict(const PreloadVerdict& trip, const PreloadVerdict& trend, std::int64_t number);
  std::int64_t roomCpu() const;        // worker, inside workerDrain: this room's CPU so far [ns]

  TwinConfig cfg_;
  TripHistoryConfig hist_;
  std::string shaft_;
  std::string tag_;  ///< "[shaft] " before the worker's log lines ("" for the default shaft)
  TripRing ring_;
  TripTick scratch_;  // the loop's staging copy (no stack copy of a large struct per step)
  TripCounters counts_;
  struct Worker;                  // the worker's state (recorder, store): worker thread only
  std::unique_ptr<Worker> w_;
  rt::LatestMailbox<ConditionState> condition_{ConditionState{}};  // worker -> loop
  std::string store_desc_;        // written by the worker before store_open is set
};

}  // namespace hoist::service::app
