// The forecast scheduler of one shaft: see forecast_scheduler.hpp.
#include "forecast_scheduler.hpp"

#include <cmath>
#include <stdexcept>

#include "hoist/service/core/forecast_rules.hpp"

namespace hoist::service::inline app {

ForecastScheduler::ForecastScheduler(const ShaftContext& ctx, TwinCore& core, ShaftClock& clock, ForecastStats& stats,
                                     ShaftOutputs& out)
    : ctx_(ctx), core_(core), clock_(clock), stats_(stats), out_(out) {
  if (core_.solver().method() != Method::Fast)
    throw std::invalid_argument("forecast.enabled: the forecasts need the fast solver");
  job_ = std::make_unique<ForecastJob>(core_.solver().modelPtr(), ctx_.cfg, core_.preloadScale());
  if (core_.loadSensitivity()) unit_ = FastSolverState(core_.solver().model().n());
  log_limit_.setLimit(ctx_.cfg.service.log_rate_limit);
}

void ForecastScheduler::setPool(ForecastPool* pool, double phase) {
  pool_ = pool;
  phase_ = phase;
  next_t_ = phase / ctx_.cfg.forecast.rate;
}

bool ForecastScheduler::hasPlan(double t) {
  // Expired when not renewed within plan_timeout (either way: the model time
  // restarts with a new winder stream).
  if (have_plan_ && std::fabs(t - plan_t_) > ctx_.cfg.forecast.plan_timeout) {
    have_plan_ = false;
    ctx_.log.info("{}trip plan seq {} expired (not renewed for forecast.plan_timeout = {} s): the forecasts use the "
                  "no-plan rule, any sequence number is accepted again",
                  ctx_.tag, plan_seq_, ctx_.cfg.forecast.plan_timeout);
  }
  return have_plan_;
}

bool ForecastScheduler::acceptPlan(const TripPlan& plan, std::int64_t seq, double t) {
  const bool first = !have_plan_;
  have_plan_ = true;
  plan_ = plan;
  plan_seq_ = seq;
  plan_t_ = t;
  return first;
}

void ForecastScheduler::afterStep(std::int64_t utime) {
  TwinCore& core = core_;
  const ForecastConfig& fc = ctx_.cfg.forecast;
  const double tp = core.output().t;
  const double period = 1.0 / fc.rate;
  // The published time restarts at the first input (wall clock) or a new
  // stream: re-align the schedule when it went back.
  if (tp + period < next_t_) next_t_ = (std::floor(tp / period) + phase_) * period;
  if (tp + 1e-9 < next_t_) return;
  while (next_t_ <= tp + 1e-9) next_t_ += period;
  if (core.degraded() || !core.solver().finite()) {
    // A state just re-initialized after a fault, stale input, the domain
    // edge, a limited catch-up: not a state to forecast from.  The
    // predictions are withdrawn (MODEL_FAULT / INPUT_STALE / MODEL_DOMAIN
    // say what is wrong).
    ++stats_.forecasts_skipped;
    core.setPredictions(false, 0.0, false, 0.0, fc.horizon);
    return;
  }
  ForecastSnapshot& snap = job_->snapshotSlot();
  // The twin's solver now (an adopted preload replaces it: never cached;
  // TwinCore::adoptModel keeps the method, so it is a FastSolver).
  static_cast<const FastSolver&>(core.solver()).saveState(snap.state);
  // With the load estimator in use, forecast what the estimated load
  // implies: the twin's state plus the estimated load change times the unit
  // load's response (the model is linear in its load), continued under the
  // estimated load.  Else the open-loop twin's state and configured load.
  snap.from_estimate = false;
  snap.preload_scale = core_.preloadScale();
  if (const LoadEstimate* e = core.estimate(); e && core.estimateInUse()) {
    core.loadSensitivity()->saveState(unit_);
    snap.from_estimate =
        addLoadResponse(snap.state, unit_, e->Fa - snap.state.Fa, e->moment - snap.state.moment);
  }
  snap.utime = utime;
  snap.t_published = tp;
  snap.has_plan = hasPlan(core.modelTime());
  snap.plan = plan_;
  snap.plan_seq = snap.has_plan ? plan_seq_ : -1;
  if (core.clock() == ClockMode::Input || !pool_) {
    // Deterministic: the forecast runs here, at this instant, and its result
    // is published before the next input is read.
    const auto c0 = ShaftContext::Clock::now();
    const ForecastResult& r = job_->runNow();
    clock_.pause(ShaftContext::Clock::now() - c0);
    onResult(r);
    return;
  }
  if (job_->postSnapshot()) ++stats_.forecasts_dropped;
  pool_->notify();
}

void ForecastScheduler::pollResult() {
  if (const ForecastResult* r = job_->takeResult()) onResult(*r);
}

void ForecastScheduler::onResult(const ForecastResult& r) {
  ForecastStats& st = stats_;
  if (r.failed) {
    ++st.forecast_failures;
    return;
  }
  ++st.forecasts;
  if (r.from_estimate) ++st.forecasts_from_estimate;
  const double us = r.compute_s * 1e6;
  st.compute.add(us);
  if (r.plan_error != PlanError::None) {
    // The plan was valid when it came, but no longer fits the motion (e.g.
    // braking already, the target closer than the plan's stopping distance):
    // "continue" used the no-plan rule.
    ++st.plan_unusable;
    std::int64_t suppressed = 0;
    if (log_limit_.allow(kLogPlan, ctx_.wallNow(), suppressed))
      ctx_.log.info("{}trip plan seq {} no longer fits the motion at t = {:.2f} s ({}): the continue scenario uses "
                    "the no-plan rule [{} similar suppressed]",
                    ctx_.tag, plan_seq_, r.t_published, hoist::toString(r.plan_error), suppressed);
  }
  const ForecastSummary* sc[ForecastResult::kScenarios];
  for (int i = 0; i < ForecastResult::kScenarios; ++i) sc[i] = &r.scenario[i];
  const double slack_threshold = slackThreshold(ctx_.cfg, core_.solver().model(), r.kin.l);
  const ForecastVerdict v = judgeForecast(sc, ForecastResult::kScenarios, slack_threshold);
  out_.setForecastCause(v.clearance ? ForecastResult::kNames[v.clearance_scenario] : "",
                        v.slack ? ForecastResult::kNames[v.slack_scenario] : "", slack_threshold);
  core_.setPredictions(v.clearance, v.clearance_s, v.slack, v.slack_s, ctx_.cfg.forecast.horizon,
                           r.from_estimate);
  out_.publishForecast(r);
  out_.publishAlarmEvents();
}

}  // namespace hoist::service::app
