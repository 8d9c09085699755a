// The miss record: every deadline miss of hoist-twind's loop, with what the
// loop spent its time on before it (docs/service.md, "Deadline misses").
//
//   LoopSplit   cumulative steady-clock time of the loop thread by phase
//               (receive, model step, envelope, publish, forecast hand-over,
//               deferred starts, health, the rest of the tick); the rooms
//               of each shaft and the daemon add to it as they work.
//   MissRecord  one miss: when (model and wall time), which schedule and
//               tick, how many deadlines were skipped, how late the tick
//               and its shafts were, and the split of the loop's time since
//               the schedule's previous tick began.
//   MissLog     a ring of the latest kCapacity records, preallocated: the
//               tick writes a record by assignment (no allocation, no lock,
//               no I/O); readers (health, the report, the log line at the
//               miss-log second) run on the same loop thread.
//
// Kept separate from the loop (daemon.cpp) so that the record's definition
// and its reading stay in one place.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace hoist::service::inline app {

/// Cumulative steady-clock nanoseconds of the loop thread, by phase.
struct LoopSplit {
  std::int64_t receive = 0;   ///< draining the input socket (decode, validate, store: the input handlers)
  std::int64_t step = 0;      ///< model step and housekeeping, without the envelope
  std::int64_t envelope = 0;  ///< the guide-rope deflection envelope
  std::int64_t publish = 0;   ///< encode + send of HOIST_CAGE / _GUIDE_SHAPE / _ESTIMATE / alarms, flushes
  std::int64_t forecast = 0;  ///< forecast hand-over: taking results, publishing them, saving snapshots
  std::int64_t start = 0;     ///< deferred starts (first-input static solves) done in the tick
  std::int64_t health = 0;    ///< HOIST_HEALTH (fill, encode, send)
  std::int64_t other = 0;     ///< the rest of the tick handlers (alarms, bookkeeping, the loop around the shafts)
  std::int64_t sum() const { return receive + step + envelope + publish + forecast + start + health + other; }
};

/// One deadline miss (a tick that started more than one period late).
struct MissRecord {
  std::int64_t seq = 0;        ///< miss number in this process, from 0
  std::int64_t utime = 0;      ///< wall time of the late tick's start [us since the Unix epoch]
  double wall = 0.0;           ///< the same, seconds since the loop started
  double model_t = 0.0;        ///< the schedule's model time of the late tick, tick / rate [s]
  int group = 0;               ///< the schedule (rate group) index
  double rate = 0.0;           ///< its rate [Hz]
  std::int64_t tick = 0;       ///< deadline index the tick was scheduled for
  std::int64_t skipped = 0;    ///< deadlines skipped (each shaft of the schedule missed this many)
  double late_us = 0.0;        ///< the tick's start minus its deadline [us]
  int shafts = 0;              ///< shafts on the schedule (all of them missed the skipped deadlines)
  int shafts_late = 0;         ///< shafts whose own step began more than a period after the deadline
  int first_shaft = -1;        ///< daemon index of the schedule's first shaft (least late)
  int worst_shaft = -1;        ///< daemon index of the latest shaft
  double first_late_us = 0.0;  ///< the first shaft's lateness [us]
  double worst_late_us = 0.0;  ///< the latest shaft's lateness [us]
  /// The loop's time from the schedule's previous tick start to this one:
  double window_us = 0.0;      ///< length of that interval [us]
  LoopSplit work;              ///< [ns] the loop's work in it, by phase
  double idle_us = 0.0;        ///< idle before the deadline (the loop had finished its work) [us]
  /// Time neither worked nor idle before the deadline: the timer's wake-up,
  /// the kernel, Asio, and any stall of the machine itself [us].
  double timer_us = 0.0;
  /// The loop thread's CPU time in that interval [us].  The phases are
  /// steady-clock spans: a thread preempted inside one (another process on
  /// its CPU, a stall of the machine) counts the wait in that phase, and the
  /// work then exceeds this CPU time by as much.
  double cpu_us = 0.0;
};

/// The latest kCapacity miss records (a ring; older ones are dropped and
/// counted).  Preallocated; record() never allocates.
class MissLog {
 public:
  static constexpr std::size_t kCapacity = 512;

  /// A new record (the tick fills it in place before commit()).
  MissRecord& begin() {
    MissRecord& r = ring_[static_cast<std::size_t>(total_ % static_cast<std::int64_t>(kCapacity))];
    r = MissRecord{};
    r.seq = total_;
    return r;
  }
  /// The record begun last is complete.
  void commit() { ++total_; }

  std::int64_t total() const { return total_; }
  std::size_t kept() const {
    return total_ < static_cast<std::int64_t>(kCapacity) ? static_cast<std::size_t>(total_) : kCapacity;
  }
  std::int64_t dropped() const { return total_ - static_cast<std::int64_t>(kept()); }
  /// The i-th kept record, oldest first (i < kept()).
  const MissRecord& at(std::size_t i) const {
    const std::int64_t first = total_ - static_cast<std::int64_t>(kept());
    return ring_[static_cast<std::size_t>((first + static_cast<std::int64_t>(i)) %
                                          static_cast<std::int64_t>(kCapacity))];
  }
  /// The kept record with the largest lateness, or nullptr.
  const MissRecord* worst() const;

 private:
  std::array<MissRecord, kCapacity> ring_{};
  std::int64_t total_ = 0;
};

}  // namespace hoist::service::app
