// Look-ahead forecasts off the real-time loop (docs/lookahead.md).
//
//   ForecastJob   one shaft's forecast machinery: the ForecastWorkspace (its
//                 own solver, sized once), an input mailbox of state
//                 snapshots (loop -> worker) and an output mailbox of results
//                 (worker -> loop), both LatestMailbox (single-slot,
//                 lock-free: the newest snapshot replaces an unread one, so a
//                 late worker never builds a backlog).
//   ForecastPool  ONE per process: `workers` threads shared by every shaft's
//                 job.  A worker sleeps on an atomic counter (futex) until
//                 the loop posts a snapshot, then runs every job with a
//                 fresh snapshot (a job is claimed by one worker at a time).
//                 The shafts post at staggered instants (ShaftTwin), so one
//                 worker serves them in turn.
//
// Threads: the loop thread fills a snapshot (FastSolver::saveState into a
// preallocated FastSolverState: no allocation, no lock), publishes it, and
// wakes the pool (one atomic increment and a futex wake).  The worker never
// touches LCM nor the log: the loop takes the result, publishes forecast_t
// and feeds the alarms on its own thread (LCM publish stays single-threaded).
// With --clock input the loop runs the job itself, synchronously, at the
// forecast instants (runNow): the outputs then depend on the inputs only.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "hoist/forecast.hpp"
#include "hoist/service/core/config.hpp"
#include "hoist/service/twin/twin_model.hpp"
#include "hoist/rt/latest_mailbox.hpp"

namespace hoist::service::inline app {

/// What the loop hands over: the twin's state at one instant, and the plan.
struct ForecastSnapshot {
  FastSolverState state;        ///< FastSolver::saveState (t, kinematics, every coordinate)
  std::int64_t utime = 0;       ///< utime of the state (as its HOIST_CAGE)
  double t_published = 0.0;     ///< published time of the state (HOIST_CAGE.t)
  bool from_estimate = false;   ///< `state` is the load estimator's (hoist::addLoadResponse)
  /// The guide-rope preload scale of the twin's model (TwinCore::preloadScale):
  /// the worker forecasts with the same model (rebuilt, off the loop, when
  /// an operator adopted another).
  double preload_scale = 1.0;
  bool has_plan = false;        ///< a validated trip plan is known
  TripPlan plan;
  std::int64_t plan_seq = -1;

  ForecastSnapshot() = default;
  explicit ForecastSnapshot(int n) : state(n) {}
};

/// What comes back.  Scenario 0 is "estop", 1 is "continue".
struct ForecastResult {
  static constexpr int kScenarios = 2;
  static constexpr const char* kNames[kScenarios] = {"estop", "continue"};

  std::int64_t utime = 0;
  double t_published = 0.0;
  Kinematics kin;
  std::int64_t plan_seq = -1;        ///< plan followed by "continue" (-1: the no-plan rule)
  PlanError plan_error = PlanError::None;  ///< why a known plan could not be followed now
  bool from_estimate = false;        ///< started from the estimator's state and load (ForecastSnapshot)
  double Fa = 0.0, moment = 0.0;     ///< the load the forecasts assumed [N], [N m]
  bool failed = false;               ///< the engine threw (never expected; nothing is published)
  double compute_s = 0.0;            ///< wall time of both scenarios [s]
  ForecastSummary scenario[kScenarios];
};

class ForecastJob {
 public:
  /// `dt` is the shaft's tick (1 / [service] rate); allocates everything
  /// here, and again (on the worker; on the loop with --clock input) when a
  /// snapshot's preload_scale differs from the model's.  `model` is `cfg`'s
  /// shaft with its preloads times `preload_scale` (TwinCore::preloadScale).
  ForecastJob(std::shared_ptr<const ShaftModel> model, const TwinConfig& cfg, double preload_scale = 1.0);
  ForecastJob(const ForecastJob&) = delete;
  ForecastJob& operator=(const ForecastJob&) = delete;

  // ---- loop thread ----
  ForecastSnapshot& snapshotSlot() { return in_.writeSlot(); }
  /// True if the previous snapshot was still unread (it is dropped).
  bool postSnapshot() { return in_.publish(); }
  /// The newest result if one arrived since the last call, else nullptr.
  const ForecastResult* takeResult() { return out_.take(); }
  /// --clock input: compute the snapshot just filled, here, now; returns the result.
  const ForecastResult& runNow();

  // ---- worker threads ----
  /// If a snapshot is waiting and no other worker holds this job: compute
  /// it and post the result.  True if it computed one.
  bool runPending();

  const ForecastOptions& options() const { return ws_->options(); }
  /// The preload scale the workspace's model runs (worker; tests).
  double preloadScale() const { return ws_scale_; }

 private:
  void compute(const ForecastSnapshot& s, ForecastResult& r);

  ForecastConfig fc_;
  double max_length_;
  TwinConfig cfg_;                           ///< the shaft as configured (a new scale rebuilds from it)
  std::unique_ptr<ForecastWorkspace> ws_;
  double ws_scale_ = 1.0;                    ///< the preload scale of ws_'s model
  MotionProfile plan_profile_;
  rt::LatestMailbox<ForecastSnapshot> in_;
  rt::LatestMailbox<ForecastResult> out_;
  std::atomic<bool> busy_{false};
  ForecastResult direct_result_;  ///< --clock input: runNow()'s result
};

class ForecastPool {
 public:
  explicit ForecastPool(int workers) : workers_(workers < 1 ? 1 : workers) {}
  ~ForecastPool() { stop(); }
  ForecastPool(const ForecastPool&) = delete;
  ForecastPool& operator=(const ForecastPool&) = delete;

  /// Before start(): the jobs the workers serve.
  void add(ForecastJob* job) { jobs_.push_back(job); }
  bool empty() const { return jobs_.empty(); }
  std::size_t jobs() const { return jobs_.size(); }
  int workers() const { return workers_; }
  /// Workers that have given way to the loop (hoist::rt::yieldToRealtimeLoop:
  /// SCHED_OTHER, nice kWorkerNice) -- each does so first thing.
  int workersYielded() const { return yielded_.load(std::memory_order_acquire); }
  /// The workers' nice value: below the loop (SCHED_FIFO, or nice 0 without).
  static constexpr int kWorkerNice = 10;
  void start();
  void stop();
  /// Loop thread, after posting a snapshot: wake a worker (lock-free).
  void notify() {
    wake_.fetch_add(1, std::memory_order_release);
    wake_.notify_one();
  }

 private:
  void workerMain();
  int workers_;
  std::vector<ForecastJob*> jobs_;
  std::vector<std::thread> threads_;
  std::atomic<std::uint32_t> wake_{0};
  std::atomic<bool> quit_{false};
  std::atomic<int> yielded_{0};
};

}  // namespace hoist::service::app
