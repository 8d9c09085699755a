// The miss recorder: writes hoist-twind's deadline-miss records (the record
// itself, LoopSplit / MissRecord / MissLog, is in miss_record.hpp) and logs
// them once a second (docs/service.md, "Deadline misses").
//
// Who calls: Daemon (daemon.hpp) owns one.  On its loop thread, per schedule
// (rate group): startWindow() when the schedule starts and at every tick;
// begin() for a tick that skipped deadlines, noteShaft() for each shaft the
// late tick steps, commit() when the tick is done.  startLogging() arms the
// once-a-second log line (outside the ticks), stop() cancels it.  Shafts read
// the ring through log().
//
// Real time: begin/noteShaft/commit assign into the preallocated ring (no
// allocation, no lock, no I/O); the log line goes through the RtLog ring.
//
// Lifetimes: the io_context, the RtLog and the loop's LoopSplit are the
// Daemon's and outlive the recorder; the ring lives as long as the recorder
// (the shafts keep a pointer to it and read it on the loop thread only).
#pragma once

#include <utility>  // before Asio: Boost 1.74 awaitable.hpp uses std::exchange

#include <boost/asio.hpp>
#include <chrono>
#include <cstdint>
#include <memory>

#include "hoist/rt/rt_log.hpp"
#include "miss_record.hpp"

namespace hoist::service::inline app {

class ShaftTwin;

/// Per schedule: where the loop stood when the schedule's previous tick began.
struct MissWindow {
  LoopSplit split_at{};                                ///< the loop's split then
  std::chrono::steady_clock::time_point last_start{};  ///< that tick's start
  std::int64_t cpu_at = 0;                             ///< the loop thread's CPU time then [ns]
};

/// The schedule and tick a record is about.
struct MissTick {
  int group = 0;          ///< the schedule (rate group) index
  double rate = 0.0;      ///< its rate [Hz]
  std::int64_t tick = 0;  ///< the deadline index the tick was scheduled for
  int shafts = 0;         ///< shafts on the schedule
};

class MissRecorder {
 public:
  using Clock = std::chrono::steady_clock;

  /// `split`: the loop's cumulative split (read at each window and record).
  MissRecorder(boost::asio::io_context& io, rt::RtLog& log, const LoopSplit& split);

  /// CPU time of the calling thread [ns] (0 if unavailable).
  static std::int64_t threadCpuNanos();

  /// The schedule's window starts now (its tick began at `now`).
  void startWindow(MissWindow& w, Clock::time_point now, std::int64_t cpu_now) const {
    w.split_at = split_;
    w.last_start = now;
    w.cpu_at = cpu_now;
  }
  /// A tick that skipped deadlines: a record of when, which, and the split of
  /// the loop's time since the schedule's previous tick (`w`, not yet moved on).
  /// `start` is the loop's start, `deadline` the one the tick was scheduled for.
  MissRecord& begin(const MissTick& t, const MissWindow& w, Clock::time_point start, Clock::time_point now,
                    Clock::time_point deadline, std::int64_t skipped, std::int64_t cpu_now);
  /// Shaft `s` (daemon index `id`) ran its step in the late tick.
  static void noteShaft(MissRecord& r, ShaftTwin& s, int id, double period_us);
  /// The record begun last is complete.
  void commit() { ring_->commit(); }

  /// Arms the once-a-second log line for the misses since the previous line
  /// (their number and the worst one's split).
  void startLogging();
  /// Cancels the log line (the loop stops).
  void stop();

  const MissLog& log() const { return *ring_; }

 private:
  void arm();
  void onSecond(const boost::system::error_code& ec);

  rt::RtLog& rtlog_;
  const LoopSplit& split_;
  std::unique_ptr<MissLog> ring_;  ///< every deadline miss (preallocated ring)
  std::int64_t logged_ = 0;        ///< ring_->total() at the last log line
  boost::asio::steady_timer timer_;
  bool stopped_ = false;
};

}  // namespace hoist::service::app
