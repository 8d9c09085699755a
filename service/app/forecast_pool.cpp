// Look-ahead forecasts off the real-time loop: see forecast_pool.hpp.
#include "forecast_pool.hpp"

#include <chrono>
#include <cmath>
#include <exception>

#include "hoist/rt/realtime.hpp"

namespace hoist::service::inline app {

namespace {

ForecastOptions optionsFor(const TwinConfig& cfg) {
  ForecastOptions fo;
  fo.horizon = cfg.forecast.horizon;
  fo.dt = 1.0 / cfg.service.rate;
  fo.max_step = cfg.service.max_step;
  fo.envelope_points = cfg.service.envelope_points;
  fo.series_points = cfg.forecast.series_points;
  fo.limits = {cfg.alarms.gap_pos_y, cfg.alarms.gap_neg_y, cfg.alarms.guide_rope_gap,
               cfg.alarms.warning_fraction, cfg.alarms.critical_fraction};
  // The twin's own step (exact) or the economical forecast (the default).
  return cfg.forecast.exact ? fo : economicalForecast(fo, cfg.shaft.n, cfg.forecast.modes);
}

ForecastResult resultPrototype() { return ForecastResult{}; }

}  // namespace

ForecastJob::ForecastJob(std::shared_ptr<const ShaftModel> model, const TwinConfig& cfg, double preload_scale)
    : fc_(cfg.forecast),
      max_length_(cfg.shaft.maxRopeLength()),
      cfg_(cfg),
      ws_(std::make_unique<ForecastWorkspace>(model, optionsFor(cfg))),
      ws_scale_(preload_scale),
      in_(ForecastSnapshot(model->n())),
      out_(resultPrototype()) {}

void ForecastJob::compute(const ForecastSnapshot& s, ForecastResult& r) {
  const auto c0 = std::chrono::steady_clock::now();
  const FastSolverState& st = s.state;
  r.utime = s.utime;
  r.t_published = s.t_published;
  r.kin = st.kin;
  r.from_estimate = s.from_estimate;
  r.Fa = st.Fa;
  r.moment = st.moment;
  r.plan_seq = -1;
  r.plan_error = PlanError::None;
  r.failed = false;
  try {
    if (s.preload_scale != ws_scale_) {
      // An operator adopted another preload: forecast with the twin's model.
      ws_ = std::make_unique<ForecastWorkspace>(
          std::make_shared<const ShaftModel>(withPreloadScale(cfg_.shaft, s.preload_scale)), optionsFor(cfg_));
      ws_scale_ = s.preload_scale;
    }
    const bool finite = std::isfinite(st.t) && std::isfinite(st.kin.l) && std::isfinite(st.kin.v) &&
                        std::isfinite(st.kin.a);
    if (!finite) {
      // Never forecast from a broken state: both scenarios say so.
      for (ForecastSummary& f : r.scenario) {
        f = ForecastSummary{};
        f.status = ForecastStatus::NonFinite;
        f.t_start = st.t;
        f.horizon = fc_.horizon;
      }
    } else {
      forecast(*ws_, st, estopProfile(st.t, st.kin, fc_.estop_decel, fc_.estop_jerk), r.scenario[0]);
      bool planned = false;
      if (s.has_plan) {
        const PlanCheck pc = planProfile(st.t, st.kin, s.plan, max_length_, plan_profile_);
        if (pc.ok()) {
          planned = true;
          r.plan_seq = s.plan_seq;
        } else {
          r.plan_error = pc.error;
        }
      }
      if (planned)
        forecast(*ws_, st, plan_profile_, r.scenario[1]);
      else
        forecast(*ws_, st, continueProfile(st.t, st.kin, fc_.vmax, fc_.amax, max_length_), r.scenario[1]);
    }
  } catch (const std::exception&) {
    r.failed = true;
  }
  r.compute_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
}

const ForecastResult& ForecastJob::runNow() {
  // The loop filled in_.writeSlot(); compute from it without handing it over
  // (no other thread takes part with --clock input).
  compute(in_.writeSlot(), direct_result_);
  return direct_result_;
}

bool ForecastJob::runPending() {
  if (!in_.pending()) return false;
  bool expected = false;
  if (!busy_.compare_exchange_strong(expected, true, std::memory_order_acquire)) return false;
  bool ran = false;
  if (const ForecastSnapshot* s = in_.take()) {
    compute(*s, out_.writeSlot());
    out_.publish();
    ran = true;
  }
  busy_.store(false, std::memory_order_release);
  return ran;
}

void ForecastPool::start() {
  if (jobs_.empty() || !threads_.empty()) return;
  quit_.store(false);
  for (int i = 0; i < workers_; ++i) threads_.emplace_back([this] { workerMain(); });
}

void ForecastPool::stop() {
  if (threads_.empty()) return;
  quit_.store(true, std::memory_order_release);
  wake_.fetch_add(1, std::memory_order_release);
  wake_.notify_all();
  for (auto& t : threads_) t.join();
  threads_.clear();
}

void ForecastPool::workerMain() {
  // Created by the loop thread, this thread has inherited its SCHED_FIFO
  // priority: at equal priority a forecast of milliseconds would hold the
  // loop off its deadline on a shared CPU.  Give way first.
  if (hoist::rt::yieldToRealtimeLoop(kWorkerNice)) yielded_.fetch_add(1, std::memory_order_release);
  while (!quit_.load(std::memory_order_acquire)) {
    const std::uint32_t seen = wake_.load(std::memory_order_acquire);
    bool ran = false;
    for (ForecastJob* j : jobs_) {
      if (quit_.load(std::memory_order_relaxed)) return;
      ran = j->runPending() || ran;
    }
    if (!ran) wake_.wait(seen, std::memory_order_acquire);
  }
}

}  // namespace hoist::service::app
