// One shaft of hoist-twind: see shaft_twin.hpp.
#include "shaft_twin.hpp"

#include <algorithm>

#include "hoist/bus/lcm_util.hpp"
#include "hoist/rt/clock.hpp"

namespace hoist::service::inline app {

using rt::nanos;
using rt::ScopedSpan;
using std::chrono::duration;

ShaftTwin::ShaftTwin(const TwinConfig& cfg, std::string label, ::lcm::LCM& lcm, RtLog& log, TestHooks hooks,
                     std::int64_t instance_id, ::lcm::LCM* lcm_out)
    : ctx_(cfg, std::move(label), log, hooks, instance_id),
      in_(lcm),
      outputs_(ctx_, ctx_.core, output_stats_, input_stats_, lcm_out ? *lcm_out : lcm),
      forecast_(ctx_.cfg.forecast.enabled ? std::make_unique<ForecastScheduler>(ctx_, ctx_.core, ctx_.clock,
                                                                                  forecast_stats_, outputs_)
                                          : nullptr),
      inputs_(ctx_, ctx_.core, input_stats_, peers_, lcm, outputs_, forecast_.get()),
      health_(ctx_, stats(), peers_) {
  log_limit_.setLimit(ctx_.cfg.service.log_rate_limit);
  // Wall clock: the first input's (and a new stream's) static solve waits
  // for the daemon's per-tick start budget ([service] max_starts_per_tick).
  ctx_.core.deferStarts(ctx_.cfg.service.clock == ClockMode::Wall && ctx_.cfg.service.max_starts_per_tick > 0);
  // Likewise the exact guide-rope envelopes, per tick across the schedule.
  envelope_budget_ = ctx_.cfg.service.clock == ClockMode::Wall && ctx_.cfg.service.max_exact_envelopes_per_tick > 0;
}

void ShaftTwin::attachLoop(LoopSplit* split, const MissLog* misses, int phase) {
  split_ = split;
  health_.setMissLog(misses);
  outputs_.setPhase(phase);
}

void ShaftTwin::startWithinBudget(double t, double wall, int& starts_left, int* envelope_budget) {
  if (starts_left <= 0) return;  // waits for a later tick: "starting"
  --starts_left;
  TickStats& st = tick_stats_;
  {
    const ScopedSpan span(&st.ns_model, &st.ns_start, split_ ? &split_->start : nullptr);
    ctx_.core.completeStart(t - 1.0 / ctx_.cfg.service.rate, wall, envelope_budget);
  }
  ++st.starts;
  st.start_tick = st.ticks;
  st.start_wall = wall;
}

void ShaftTwin::slowTickHook(double wall) {
  if (slow_tick_done_ || ctx_.hooks.slow_tick_at < 0.0 || wall < ctx_.hooks.slow_tick_at) return;
  slow_tick_done_ = true;
  // Busy (not asleep): the time is the loop's, as a slow model step's would be.
  const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                        duration<double, std::milli>(ctx_.hooks.slow_tick_ms));
  while (Clock::now() < until) {
  }
}

void ShaftTwin::enableTrips(const TripHistoryConfig& hist) {
  trips_ = std::make_unique<TripRoom>(ctx_.cfg, hist, hist.shaft);
  peers_.trips = trips_.get();
}

void ShaftTwin::setTripPool(TripPool* pool) {
  if (trips_ && pool) pool->add(trips_.get());
}

void ShaftTwin::applyCondition() {
  const ConditionState* c = trips_->takeCondition();
  if (!c) return;
  outputs_.setConditionTexts(c->preload_text, c->fingerprint_text);
  outputs_.setDetectability(TripDetectability{c->detect_trip, c->loss30_separation, c->loss30_visible});
  ctx_.core.setCondition(c->preload, c->upper95, c->warning, c->critical, c->fingerprint, c->z, c->z_limit);
  // MODEL_MISMATCH's trip-end preload test: each verdict once (an adoption
  // drops the one in force; a re-publication of it must not raise it again),
  // and only on the preload it judged (one that arrives after an adoption
  // judged the replaced model).
  if (c->verdict_trip != verdict_applied_ && c->verdict_twin_scale == ctx_.core.preloadScale()) {
    verdict_applied_ = c->verdict_trip;
    outputs_.setPreloadVerdictText(c->verdict_text);
    ctx_.core.setPreloadVerdict(c->verdict_mismatch, c->verdict_z, c->verdict_limit);
  }
}

void ShaftTwin::stopTrips() {
  if (!trips_) return;
  const TripCounters& c = trips_->counters();
  const std::int64_t trips = c.trips.load();
  ctx_.log.info("{}trip history: {} trips recorded, {} stored, {} queued, {} failed, {} ticks dropped (ring full), "
                "{} motions shorter than a trip; worker CPU {:.1f} ms ({:.1f} ms per trip)",
                ctx_.tag, trips, c.stored.load(), c.queued.load(), c.failed.load(), c.dropped.load(),
                c.not_a_trip.load(), c.cpu_ns.load() * 1e-6, trips > 0 ? c.cpu_ns.load() * 1e-6 / trips : 0.0);
}

void ShaftTwin::subscribe(InputRouter* router) {
  // Our own health channel is watched here when outputs share the input URL.
  inputs_.subscribe(router, &outputs_.lcm() == &in_);
}

void ShaftTwin::setForecastPool(ForecastPool* pool, double phase) {
  if (forecast_) forecast_->setPool(pool, phase);
}

void ShaftTwin::keepAccelOffset(const std::string& path, std::shared_ptr<spdlog::logger> log) {
  if (!ctx_.cfg.estimator.enabled) return;
  offsets_ = std::make_unique<OffsetKeeper>(path, ctx_.tag, std::move(log));
  if (const auto r = offsets_->load()) {
    if (!ctx_.core.setAccelOffset(r->offset, r->sigma))
      ctx_.log.warn("{}accelerometer offset: {} holds a value the estimator refused ({} +- {} m/s^2): ignored",
                    ctx_.tag, path, r->offset, r->sigma);
  }
  peers_.offsets = offsets_.get();
}

void ShaftTwin::keepPreload(const std::string& path, std::shared_ptr<spdlog::logger> log) {
  preload_ = std::make_unique<PreloadKeeper>(ctx_.cfg, path, ctx_.tag, std::move(log), ctx_.log);
  if (auto m = preload_->loadKept()) ctx_.core.adoptModel(m);  // start-up: the old model is freed here
  peers_.preload = preload_.get();
}

void ShaftTwin::stopOffsetKeeper() {
  if (offsets_) offsets_->stop();
}

void ShaftTwin::start(Clock::time_point start, double health_phase) {
  ctx_.clock.start(start);
  if (offsets_) offsets_->start();
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
  // Each slice's owner ends its window (the whole-run histograms take it).
  tick_stats_.endWindow();
  input_stats_.endWindow();
  forecast_stats_.endWindow();
}

void ShaftTwin::tick(std::int64_t k, Clock::time_point deadline, std::int64_t skipped, TickAllowance& left) {
  TickStats& st = tick_stats_;
  TwinCore& core = ctx_.core;
  LoopSplit* split = split_;
  const auto now = Clock::now();
  st.last_late_us = std::max(0.0, duration<double, std::micro>(now - deadline).count());
  st.late.add(st.last_late_us);
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
    // This tick's budget of exact envelopes, shared by the schedule's shafts.
    int* const envelopes = envelope_budget_ ? &left.exact_envelopes : nullptr;
    if (core.startPending()) startWithinBudget(t, wall, left.starts, envelopes);
    const auto t0 = Clock::now();
    const std::int64_t env0 = core.envelopeNanos();
    if (ctx_.hooks.slow_tick_at >= 0.0) [[unlikely]] slowTickHook(wall);
    const TickResult r = core.tick(t, wall, envelopes);
    core.housekeeping(wall);
    const auto t1 = Clock::now();
    st.ns_model += nanos(t1 - t0);
    if (split) {
      const std::int64_t env = core.envelopeNanos() - env0;
      split->envelope += env;
      split->step += nanos(t1 - t0) - env;
    }
    if (r.stepped) st.step.add(duration<double, std::micro>(t1 - t0).count());
    if (r.catchup_limited) {
      std::int64_t suppressed = 0;
      if (log_limit_.allow(kLogCatchup, wall, suppressed))
        ctx_.log.warn("{}the loop fell behind: a tick had to cross more than service.max_catchup_periods = {} "
                      "periods; crossed with longer substeps, output flagged degraded [{} similar suppressed]",
                      ctx_.tag, ctx_.cfg.service.max_catchup_periods, suppressed);
    }
    // Results of earlier snapshots (the worker posts them when done).
    if (forecast_) {
      const ScopedSpan span(split ? &split->forecast : nullptr);
      forecast_->pollResult();
    }
    // No HOIST_CAGE before the trip started (no input yet, or the start
    // still waits for the start budget).
    if (r.stepped && core.hasOutput()) {
      const std::int64_t utime = bus::wallUtime();
      {
        const ScopedSpan span(&st.ns_publish, split ? &split->publish : nullptr);
        outputs_.publishTick(k, utime);
      }
      if (forecast_) {
        const ScopedSpan span(split ? &split->forecast : nullptr);
        forecast_->afterStep(utime);
      }
      if (trips_) trips_->afterStep(core, utime);
    }
    if (r.stepped && offsets_) offsets_->afterTick(core);
  } else {
    core.housekeeping(wall);
  }
  if (preload_) preload_->afterTick(core);
  inputs_.forgetSilentPublisher(wall);
  if (trips_) applyCondition();
  outputs_.publishAlarmEvents();

  if (health_.due(wall)) {
    const ScopedSpan span(&st.ns_publish, split ? &split->health : nullptr);
    publishHealth();
  }
  st.ns_tick += nanos(Clock::now() - now);
}

}  // namespace hoist::service::app
