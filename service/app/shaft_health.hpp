// ShaftHealth: the room of one shaft that turns its statistics
// (ShaftStats) and the model's counters into HOIST_HEALTH and the final log
// lines; it also reads the process's resident memory and keeps the health
// schedule.  The run report (run_report.hpp) writes the final HOIST_HEALTH
// this room filled, so every counter has one name, health_t's.
//
// Real time: fill() and the resident-memory read (pread of
// /proc/self/statm into a stack buffer) do not allocate.
#pragma once

#include <cstdint>
#include <string>

#include "hoist/health_t.hpp"
#include "miss_record.hpp"
#include "shaft_context.hpp"
#include "shaft_stats.hpp"

namespace hoist::service::inline app {

class ShaftHealth {
 public:
  /// Reads the statistics in `stats` and the trip room in `peers` (never
  /// writes them: each slice's owner ends its own window); every reference
  /// must outlive this room (all are ShaftTwin's, as this room is).
  ShaftHealth(const ShaftContext& ctx, ShaftStatsView stats, const ShaftPeers& peers);
  ~ShaftHealth();
  ShaftHealth(const ShaftHealth&) = delete;
  ShaftHealth& operator=(const ShaftHealth&) = delete;

  /// The daemon's miss record, for HOIST_HEALTH (nullptr: none).
  void setMissLog(const MissLog* misses) { misses_ = misses; }
  /// Process-wide count of ignored datagrams, reported in HOIST_HEALTH.
  void setIgnoredCounter(const std::int64_t* n) { ignored_counter_ = n; }
  /// The loop starts: the next report is due `phase` s earlier than a full
  /// period after the first one (the shafts of one daemon spread them out).
  void start(double phase) { last_wall_ = -phase; }
  /// A report is due at wall time `wall`.
  bool due(double wall) const;
  /// Fills `m` for wall time `wall` (this window's figures).
  void fill(hoist::health_t& m, double wall) const;
  /// After `m` was published: the debug line (unless final); the next
  /// window starts.  (The slices' owners end their histograms' windows.)
  void endWindow(const hoist::health_t& m, double wall, bool final_report);
  /// The final health line and per-reason rejection counts, in the log.
  void logFinal() const;

 private:
  std::int64_t rssKb() const;
  /// HOIST_HEALTH's starting / miss-record fields (the latest misses this
  /// shaft took part in, from the daemon's miss record).
  void fillStartsAndMisses(hoist::health_t& m) const;

  const ShaftContext& ctx_;                     ///< the shaft's shared, read-only state
  ShaftStatsView st_;                           ///< every statistics slice of the shaft, read-only
  const ShaftPeers& peers_;                     ///< the trip room, if any (its counters)
  const MissLog* misses_ = nullptr;             ///< setMissLog()
  double last_wall_ = 0.0;                      ///< wall time of the last report [s]
  int statm_fd_ = -1;                           ///< /proc/self/statm, open for the run
  const std::int64_t* ignored_counter_ = nullptr;  ///< the daemon's ignored-datagram count
};

}  // namespace hoist::service::app
