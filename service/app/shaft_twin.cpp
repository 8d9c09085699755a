// One shaft of hoist-twind: see shaft_twin.hpp.
#include "shaft_twin.hpp"

#include <algorithm>

#include "hoist/bus/lcm_util.hpp"
#include "hoist/rt/clock.hpp"

namespace hoist::svc {

using rt::nanos;
using std::chrono::duration;

ShaftTwin::ShaftTwin(const TwinConfig& cfg, std::string label, lcm::LCM& lcm, RtLog& log, TestHooks hooks,
                     std::int64_t instance_id, lcm::LCM* lcm_out)
    : ctx_(cfg, std::move(label), log, hooks, instance_id),
      in_(lcm),
      outputs_(ctx_, lcm_out ? *lcm_out : lcm),
      forecast_(ctx_.cfg.forecast.enabled ? std::make_unique<ForecastScheduler>(ctx_, outputs_) : nullptr),
      inputs_(ctx_, lcm, outputs_, forecast_.get()),
      health_(ctx_) {
  log_limit_.setLimit(ctx_.cfg.service.log_rate_limit);
}

void ShaftTwin::subscribe(InputRouter* router) {
  // Our own health channel is watched here when outputs share the input URL.
  inputs_.subscribe(router, &outputs_.lcm() == &in_);
}

void ShaftTwin::setForecastPool(ForecastPool* pool, double phase) {
  if (forecast_) forecast_->setPool(pool, phase);
}

void ShaftTwin::start(Clock::time_point start, double health_phase) {
  ctx_.start = start;
  publishHealth();  // announce ourselves at once
  // Shafts of one daemon spread their later health messages over the period.
  health_.start(health_phase);
}

void ShaftTwin::publishHealth(bool final_report) {
  const double wall = ctx_.wallNow();
  hoist::health_t& m = outputs_.health();
  health_.fill(m, wall);
  outputs_.publishHealth();
  health_.endWindow(m, wall, final_report);
}

void ShaftTwin::tick(std::int64_t k, Clock::time_point deadline, std::int64_t skipped) {
  ShaftStats& st = ctx_.stats;
  TwinCore& core = ctx_.core;
  const auto now = Clock::now();
  st.late_hist.add(std::max(0.0, duration<double, std::micro>(now - deadline).count()));
  ++st.ticks;
  st.deadline_misses += skipped;
  inputs_.beginTick();
  const double wall = ctx_.wallAt(now);
  if (ctx_.hooks.inject_fault_at >= 0.0 && !fault_injected_ && wall >= ctx_.hooks.inject_fault_at) {
    fault_injected_ = true;
    ctx_.log.warn("{}test: injecting a model fault (non-finite state) at wall time {:.3f} s", ctx_.tag, wall);
    core.injectFault();
  }

  if (core.clock() == ClockMode::Wall) {
    const double t = static_cast<double>(k) / ctx_.cfg.service.rate;
    const auto t0 = Clock::now();
    const TickResult r = core.tick(t, wall);
    core.housekeeping(wall);
    const auto t1 = Clock::now();
    st.ns_model += nanos(t1 - t0);
    if (r.stepped) st.step_hist.add(duration<double, std::micro>(t1 - t0).count());
    if (r.catchup_limited) {
      std::int64_t suppressed = 0;
      if (log_limit_.allow(kLogCatchup, wall, suppressed))
        ctx_.log.warn("{}the loop fell behind: a tick had to cross more than service.max_catchup_periods = {} "
                      "periods; crossed with longer substeps, output flagged degraded [{} similar suppressed]",
                      ctx_.tag, ctx_.cfg.service.max_catchup_periods, suppressed);
    }
    // Results of earlier snapshots (the worker posts them when done).
    if (forecast_) forecast_->pollResult();
    if (r.stepped && core.hasInput()) {
      const auto p0 = Clock::now();
      const std::int64_t utime = bus::wallUtime();
      outputs_.publishTick(k, utime);
      st.ns_publish += nanos(Clock::now() - p0);
      if (forecast_) forecast_->afterStep(utime);
    }
  } else {
    core.housekeeping(wall);
  }
  inputs_.forgetSilentPublisher(wall);
  outputs_.publishAlarmEvents();

  if (health_.due(wall)) {
    const auto p0 = Clock::now();
    publishHealth();
    st.ns_publish += nanos(Clock::now() - p0);
  }
  st.ns_tick += nanos(Clock::now() - now);
}

}  // namespace hoist::svc
