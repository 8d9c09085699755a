// ForecastScheduler: the room of one shaft that runs its look-ahead
// forecasts (docs/lookahead.md): it keeps the trip plan in force (accepted
// by ShaftInputs), takes a snapshot of the model at each forecast instant
// and hands it to the daemon's ForecastPool (wall clock) or forecasts at
// once (--clock input), judges each result (PREDICTED_* alarms) and has
// ShaftOutputs publish it.  Exists only with [forecast] enabled.
//
// Real time: the snapshot is a copy into a preallocated mailbox slot; the
// result is read from another; nothing allocates after construction.
#pragma once

#include <cstdint>
#include <memory>

#include "forecast_pool.hpp"
#include "hoist/fast_solver.hpp"
#include "shaft_context.hpp"
#include "shaft_outputs.hpp"
#include "shaft_stats.hpp"

namespace hoist::service::inline app {

class ForecastScheduler {
 public:
  /// Throws std::invalid_argument when the twin does not run the fast solver.
  /// Writes `stats` (its own), the forecasts' predictions into `core` (the
  /// PREDICTED_* alarms) and pauses `clock` while it forecasts synchronously
  /// (--clock input).  Every reference must outlive this room (all are
  /// ShaftTwin's, as this room is).
  ForecastScheduler(const ShaftContext& ctx, TwinCore& core, ShaftClock& clock, ForecastStats& stats,
                    ShaftOutputs& out);
  ForecastScheduler(const ForecastScheduler&) = delete;
  ForecastScheduler& operator=(const ForecastScheduler&) = delete;

  /// This shaft's forecast job (the daemon adds it to its one pool).
  ForecastJob* job() { return job_.get(); }
  /// `pool` runs the job (nullptr: forecast synchronously); `phase` in [0, 1):
  /// this shaft forecasts at published times (k + phase) / rate.
  void setPool(ForecastPool* pool, double phase);
  /// After a model step stamped `utime`: at a forecast instant, hand a
  /// snapshot over (wall clock) or forecast now (input clock).
  void afterStep(std::int64_t utime);
  /// --clock wall, once per tick: the result of an earlier snapshot, if the
  /// worker finished one.
  void pollResult();

  // ---- the trip plan in force (ShaftInputs decides what is accepted) ----
  /// Whether a plan is in force at model time `t`: one expires
  /// [forecast] plan_timeout after it was accepted (logged once).
  bool hasPlan(double t);
  std::int64_t planSeq() const { return plan_seq_; }
  /// `plan` with sequence number `seq` is in force from model time `t`.
  /// True if no plan was in force.
  bool acceptPlan(const TripPlan& plan, std::int64_t seq, double t);

 private:
  void onResult(const ForecastResult& r);

  const ShaftContext& ctx_;           ///< the shaft's shared, read-only state
  TwinCore& core_;                    ///< the model: snapshots from it, predictions into it
  ShaftClock& clock_;                 ///< paused while a synchronous forecast runs
  ForecastStats& stats_;              ///< this room's statistics
  ShaftOutputs& out_;                 ///< publishes HOIST_FORECAST and the PREDICTED_* events
  std::unique_ptr<ForecastJob> job_;  ///< workspace and mailboxes of this shaft's forecasts
  FastSolverState unit_;              ///< the estimator's unit-load state (sized once; estimator only)
  ForecastPool* pool_ = nullptr;      ///< the daemon's pool (nullptr: synchronous)
  double phase_ = 0.0;                ///< this shaft's offset in the forecast period, [0, 1)
  double next_t_ = 0.0;               ///< published time of the next forecast instant
  static constexpr int kLogPlan = 0;  ///< log limiter key: plans that no longer fit
  LogRateLimiter<1> log_limit_{5};    ///< rate limit of this room's log lines
  bool have_plan_ = false;            ///< a trip plan is in force
  TripPlan plan_;                     ///< the trip plan in force
  std::int64_t plan_seq_ = -1;        ///< its sequence number
  double plan_t_ = 0.0;               ///< model time it was accepted [s]
};

}  // namespace hoist::service::app
