// ShaftHealth: the room of one shaft that turns its statistics
// (ShaftStats) and the model's counters into HOIST_HEALTH, the final log
// lines and the whole-run figures of the report (ShaftRunStats); it also
// reads the process's resident memory and keeps the health schedule.
//
// Real time: fill() and the resident-memory read (pread of
// /proc/self/statm into a stack buffer) do not allocate.
#pragma once

#include <cstdint>
#include <string>

#include "hoist/health_t.hpp"
#include "shaft_context.hpp"

namespace hoist::svc {

/// Whole-run figures of one shaft (for --report and the final health line).
struct ShaftRunStats {
  std::string label;                 ///< the shaft's label, its channel prefix, or "default"
  std::int64_t ticks = 0;            ///< ticks run
  std::int64_t steps = 0;            ///< model steps
  std::int64_t deadline_misses = 0;  ///< deadlines the schedule skipped
  std::int64_t accepted = 0;         ///< winder inputs accepted
  std::int64_t rejected = 0;         ///< winder inputs rejected
  std::int64_t seq_gaps = 0;         ///< winder sequence gaps
  std::int64_t alarm_events = 0;     ///< HOIST_ALARM events published
  std::int64_t model_faults = 0;     ///< model re-initializations after a fault
  std::int64_t publish_failures = 0; ///< failed publishes
  std::int64_t nonfinite_blocked = 0;  ///< messages withheld (non-finite)
  std::int64_t forecasts = 0;          ///< forecasts done
  std::int64_t forecasts_dropped = 0;  ///< snapshots the worker never took
  std::int64_t forecasts_skipped = 0;  ///< forecast instants skipped (degraded)
  std::int64_t forecasts_from_estimate = 0;  ///< forecasts started from the load estimate
  std::int64_t plans_accepted = 0;     ///< trip plans accepted
  std::int64_t plans_rejected = 0;     ///< trip plans rejected
  std::int64_t commands_applied = 0;   ///< effective operator commands
  std::int64_t commands_dropped = 0;   ///< operator commands dropped (budget or decode bound)
  std::int64_t commands_invalid = 0;   ///< undecodable or invalid operator commands
  const LatencyHistogram* forecast = nullptr;  ///< forecast compute time [us]
  const LatencyHistogram* step = nullptr;      ///< model step time [us]
  const LatencyHistogram* late = nullptr;      ///< tick lateness [us]
  // Cost split, whole run [ns of steady clock]: the model (core tick +
  // housekeeping, the envelope included), of which the deflection envelope;
  // publishing (encode + sendmsg of every output); the whole tick() call.
  std::int64_t ns_model = 0, ns_envelope = 0, ns_publish = 0, ns_tick = 0;
  std::int64_t envelope_exact = 0, envelope_bounded = 0;  ///< envelope evaluations
  /// Envelope evaluations deferred by the per-tick budget (a wider bound,
  /// [service] max_exact_envelopes_per_tick), and the longest run of them.
  std::int64_t envelope_deferred = 0;
  int envelope_longest_deferral = 0;
  std::int64_t starts_deferred = 0;    ///< starts that waited for the start budget
  std::int64_t ns_start = 0;           ///< steady-clock ns in deferred starts (in ns_model too)
};

class ShaftHealth {
 public:
  explicit ShaftHealth(ShaftContext& ctx);
  ~ShaftHealth();
  ShaftHealth(const ShaftHealth&) = delete;
  ShaftHealth& operator=(const ShaftHealth&) = delete;

  /// Process-wide count of ignored datagrams, reported in HOIST_HEALTH.
  void setIgnoredCounter(const std::int64_t* n) { ignored_counter_ = n; }
  /// The loop starts: the next report is due `phase` s earlier than a full
  /// period after the first one (the shafts of one daemon spread them out).
  void start(double phase) { last_wall_ = -phase; }
  /// A report is due at wall time `wall`.
  bool due(double wall) const;
  /// Fills `m` for wall time `wall` (this window's figures).
  void fill(hoist::health_t& m, double wall) const;
  /// After `m` was published: the debug line (unless final), the window's
  /// histograms merged into the whole run and reset.
  void endWindow(const hoist::health_t& m, double wall, bool final_report);
  /// The final health line and per-reason rejection counts, in the log.
  void logFinal() const;
  ShaftRunStats runStats() const;

 private:
  std::int64_t rssKb() const;
  /// HOIST_HEALTH's starting / miss-record fields (the latest misses this
  /// shaft took part in, from the daemon's miss record).
  void fillStartsAndMisses(hoist::health_t& m) const;

  ShaftContext& ctx_;                           ///< the shaft's shared state
  double last_wall_ = 0.0;                      ///< wall time of the last report [s]
  int statm_fd_ = -1;                           ///< /proc/self/statm, open for the run
  const std::int64_t* ignored_counter_ = nullptr;  ///< the daemon's ignored-datagram count
};

}  // namespace hoist::svc
