// TripPool: the worker threads of every shaft's trip room (issue 32,
// docs/condition.md "Live"): a few threads for the whole process, not one
// per shaft.  At 300 shafts a thread each was 300 threads (each stack
// locked by --mlockall) opening 300 databases in the same instant at
// start-up, where the loop missed its first two ticks.
//
//   TripWork  what a worker does for one room (TripRoom implements it):
//             open its database and seed its judge, drain its ring, close.
//             Every call for one room comes from one thread (the pool gives
//             each room to one worker for its whole life), never the loop.
//   TripPool  `workers` threads (SCHED_OTHER, nice 10: they give way to the
//             loop, hoist::rt::yieldToRealtimeLoop).  Room i belongs to
//             worker i mod workers.  A worker opens one of its rooms per
//             pass and drains every room it has opened on every pass
//             (kDrainPeriod apart), so opening hundreds of databases is
//             spread over the first passes while the first rooms already
//             record; a ring holds 30 s, far more than the passes take.
//             stop(): each worker opens what it had not yet, drains every
//             room once more (the loop has stopped pushing), closes them,
//             and is joined.
//
// Lifetimes: the rooms outlive the pool's stop(); add() only before start().
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <thread>
#include <vector>

namespace hoist::service::inline app {

/// One room's work, called by the one worker thread that serves it.
class TripWork {
 public:
  virtual ~TripWork() = default;
  virtual void workerOpen() = 0;   ///< the database opened, the judge seeded (once, first)
  virtual void workerDrain() = 0;  ///< everything the room's ring holds
  virtual void workerClose() = 0;  ///< the store flushed (once, last)
};

class TripPool {
 public:
  static constexpr int kWorkerNice = 10;
  static constexpr std::chrono::milliseconds kDrainPeriod{20};

  /// `workers` >= 1 threads at most (fewer when there are fewer rooms).
  explicit TripPool(int workers);
  ~TripPool();
  TripPool(const TripPool&) = delete;
  TripPool& operator=(const TripPool&) = delete;

  /// Before start(): `room` is served by this pool from then on.
  void add(TripWork* room) { rooms_.push_back(room); }
  void start();
  /// Every room drained once more and closed; the workers joined.  Idempotent.
  void stop();

  std::size_t rooms() const { return rooms_.size(); }
  /// The threads start() runs (0 before start()).
  int workers() const { return static_cast<int>(threads_.size()); }

 private:
  void workerMain(std::size_t k, std::size_t n);

  int max_workers_;
  std::vector<TripWork*> rooms_;
  std::vector<std::thread> threads_;
  std::atomic<bool> quit_{false};
};

}  // namespace hoist::service::app
