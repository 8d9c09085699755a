// Statistics and health of one shaft: see shaft_health.hpp.
#include "shaft_health.hpp"

#include <algorithm>
#include <climits>
#include <cstdio>
#include <fcntl.h>
#include <unistd.h>

#include "hoist/bus/lcm_util.hpp"
#include "trip_room.hpp"

namespace hoist::service::inline app {

ShaftHealth::ShaftHealth(const ShaftContext& ctx, ShaftStatsView stats, const ShaftPeers& peers)
    : ctx_(ctx), st_(stats), peers_(peers) {
  statm_fd_ = ::open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
}

ShaftHealth::~ShaftHealth() {
  if (statm_fd_ >= 0) ::close(statm_fd_);
}

bool ShaftHealth::due(double wall) const {
  const ServiceConfig& s = ctx_.cfg.service;
  return wall - last_wall_ >= 1.0 / s.health_rate - 0.5 / s.rate;
}

void ShaftHealth::fill(hoist::health_t& m, double wall) const {
  const TwinCore& core = ctx_.core;
  const TickStats& tk = st_.tick;
  const InputStats& in = st_.in;
  const OutputStats& out = st_.out;
  const ForecastStats& fc = st_.forecast;
  const InputCounters& c = core.counters();
  const AlarmEngine& al = core.alarms();
  // Each room's counters of health_t (its `@group`), under health_t's names.
  tk.fillInto(m);
  in.fillInto(m);
  out.fillInto(m);
  fc.fillInto(m);
  m.utime = bus::wallUtime();
  m.uptime = std::max(0.0, wall);
  m.t = core.publishedTime(core.modelTime());
  m.window = std::max(0.0, wall - std::max(0.0, last_wall_));
  m.steps = core.steps();
  m.preload_scale = core.preloadScale();
  const LatencyHistogram& step = st_.stepWindow();
  m.step_p50_us = step.quantile(0.5);
  m.step_p99_us = step.quantile(0.99);
  m.step_max_us = step.max();
  m.late_p50_us = tk.late.window.quantile(0.5);
  m.late_p99_us = tk.late.window.quantile(0.99);
  m.late_max_us = tk.late.window.max();
  m.input_age = core.inputAge(wall);
  m.accepted = c.accepted;
  m.seq_gaps = c.seq_gaps;
  m.rejected_total = c.rejectedTotal();
  for (int i = 0; i < kRejectReasons; ++i) m.rejected[i] = c.rejected[i];
  m.rejected[kRejectReasons] = in.command_decode_rejects;
  m.rejected[kRejectReasons + 1] = in.handler_exceptions;
  for (int i = 0; i < kPlanRejectReasons; ++i)
    m.rejected[kRejectReasons + 2 + i] = in.plan_rejects[static_cast<std::size_t>(i)];
  const LatencyHistogram& fh = fc.compute.window;
  m.forecast_p50_us = fh.count() > 0 ? fh.quantile(0.5) : 0.0;
  m.forecast_p99_us = fh.count() > 0 ? fh.quantile(0.99) : 0.0;
  m.plans_rejected = in.plansRejected();
  if (const EstimatorCounters* ec = ctx_.core.estimatorCounters()) {
    m.sensor_gated = ec->gated;
    m.estimator_load_changes = ec->load_changes;
  }
  const LoadEstimate* est = ctx_.core.estimate();
  m.estimator_sensors = est ? static_cast<int32_t>(est->sensors) : 0;
  m.estimate_in_use = ctx_.core.estimateInUse();
  const SensorTimingCounters& tc = ctx_.core.sensorTiming();
  m.sensor_clock_refused = tc.clock_refused;
  m.sensor_time_backwards = tc.time_backwards;
  m.sensor_dropped = tc.too_late + tc.superseded;
  if (const TripRoom* room = peers_.trips) {  // relaxed reads of the room's atomics: no lock
    const TripCounters& c = room->counters();
    m.history_open = c.store_open.load(std::memory_order_relaxed);
    m.trips_recorded = c.trips.load(std::memory_order_relaxed);
    m.trips_stored = c.stored.load(std::memory_order_relaxed);
    m.trips_queued = c.queued.load(std::memory_order_relaxed);
    m.trips_failed = c.failed.load(std::memory_order_relaxed);
    m.trip_ticks_dropped = c.dropped.load(std::memory_order_relaxed);
    m.trip_cpu_ms_last = static_cast<double>(c.cpu_ns_last.load(std::memory_order_relaxed)) * 1e-6;
  }
  m.alarms_active = al.activeCount();
  m.alarms_unacked = al.unackedCount();
  m.alarms_shelved = al.shelvedCount();
  m.model_faults = core.modelFaults();
  m.model_resets = core.modelResets();
  m.degraded = core.degraded();
  m.rss_kb = rssKb();
  m.catchup_limited = core.catchupLimited();
  m.datagrams_ignored = ignored_counter_ ? *ignored_counter_ : 0;
  fillStartsAndMisses(m);
}

void ShaftHealth::fillStartsAndMisses(hoist::health_t& m) const {
  static_assert(TickStats::kMissesNoted == hoist::health_t::MAX_MISSES, "one noted miss per health_t slot");
  const TwinCore& core = ctx_.core;
  const TickStats& st = st_.tick;
  m.starting = core.startPending();
  m.starts_deferred = core.startsDeferred();
  const MissLog* log = misses_;
  m.misses_recorded = log ? log->total() : 0;
  // This shaft's latest misses whose records the ring still keeps, oldest first.
  int n = 0;
  if (log) {
    const std::int64_t noted = st.misses_noted;
    const std::int64_t from = std::max<std::int64_t>(0, noted - TickStats::kMissesNoted);
    const std::int64_t oldest_kept = log->total() - static_cast<std::int64_t>(log->kept());
    for (std::int64_t j = from; j < noted; ++j) {
      const auto slot = static_cast<std::size_t>(j % TickStats::kMissesNoted);
      const std::int64_t seq = st.miss_seq[slot];
      if (seq < oldest_kept || seq >= log->total()) continue;
      const MissRecord& r = log->at(static_cast<std::size_t>(seq - oldest_kept));
      const auto i = static_cast<std::size_t>(n++);
      m.miss_utime[i] = r.utime;
      m.miss_t[i] = core.publishedTime(r.model_t);
      m.miss_tick[i] = r.tick;
      m.miss_skipped[i] = static_cast<int32_t>(std::min<std::int64_t>(r.skipped, INT32_MAX));
      m.miss_late_us[i] = st.miss_late_us[slot];
      m.miss_shafts_late[i] = r.shafts_late;
      m.miss_receive_us[i] = 1e-3 * static_cast<double>(r.work.receive);
      m.miss_step_us[i] = 1e-3 * static_cast<double>(r.work.step);
      m.miss_envelope_us[i] = 1e-3 * static_cast<double>(r.work.envelope);
      m.miss_publish_us[i] = 1e-3 * static_cast<double>(r.work.publish);
      m.miss_forecast_us[i] = 1e-3 * static_cast<double>(r.work.forecast);
      m.miss_start_us[i] = 1e-3 * static_cast<double>(r.work.start);
      m.miss_health_us[i] = 1e-3 * static_cast<double>(r.work.health);
      m.miss_other_us[i] = 1e-3 * static_cast<double>(r.work.other);
      m.miss_timer_us[i] = r.timer_us;
    }
  }
  m.n_misses = n;
}

void ShaftHealth::endWindow(const hoist::health_t& m, double wall, bool final_report) {
  const InputCounters& c = ctx_.core.counters();
  if (!final_report)
    ctx_.log.debug("{}health: t={:.2f} s steps={} step p50/p99/max={:.0f}/{:.0f}/{:.0f} us late "
                   "p50/p99/max={:.0f}/{:.0f}/{:.0f} us misses={} inputs ok={} rejected={} gaps={} "
                   "alarms active={} faults={} publish failures={}{}",
                   ctx_.tag, m.t, m.steps, m.step_p50_us, m.step_p99_us, m.step_max_us, m.late_p50_us,
                   m.late_p99_us, m.late_max_us, st_.tick.deadline_misses, c.accepted, c.rejectedTotal(), c.seq_gaps,
                   m.alarms_active, m.model_faults, st_.out.publish_failures, m.degraded ? " DEGRADED" : "");
  last_wall_ = wall;
}

void ShaftHealth::logFinal() const {
  const TwinCore& core = ctx_.core;
  const TickStats& tk = st_.tick;
  const InputStats& in = st_.in;
  const OutputStats& out = st_.out;
  const ForecastStats& fc = st_.forecast;
  const LatencyHistogram step = st_.stepTotal();
  const LatencyHistogram& late = tk.late.total;
  const InputCounters& c = core.counters();
  const std::string& tag = ctx_.tag;
  RtLog& log = ctx_.log;
  log.info("{}final health: t={:.2f} s ticks={} steps={} over the whole run: step p50/p99/p99.9/max="
           "{:.1f}/{:.1f}/{:.1f}/{:.0f} us, tick lateness p50/p99/p99.9/max={:.0f}/{:.0f}/{:.0f}/{:.0f} us, "
           "deadline misses={}; inputs accepted={} rejected={} sequence gaps={}; alarms "
           "active={} events={}; model faults={} resets={}; publish failures={} withheld "
           "(non-finite)={}{}",
           tag, core.modelTime(), tk.ticks, core.steps(), step.quantile(0.5), step.quantile(0.99),
           step.quantile(0.999), step.max(), late.quantile(0.5),
           late.quantile(0.99), late.quantile(0.999), late.max(), tk.deadline_misses,
           c.accepted, c.rejectedTotal(), c.seq_gaps, core.alarms().activeCount(), out.alarm_events,
           core.modelFaults(), core.modelResets(), out.publish_failures, out.nonfinite_blocked,
           core.degraded() ? " DEGRADED" : "");
  for (int i = 0; i < kRejectReasons; ++i)
    if (c.rejected[i] > 0) log.info("{}  rejected {}: {}", tag, toString(static_cast<RejectReason>(i)), c.rejected[i]);
  if (in.command_decode_rejects > 0)
    log.info("{}  rejected alarm commands (command_decode): {}", tag, in.command_decode_rejects);
  if (in.handler_exceptions > 0) log.info("{}  exceptions caught in LCM handlers: {}", tag, in.handler_exceptions);
  if (in.reannounce_requests > 0)
    log.info("{}  alarm re-announce requests: {} ({} honoured, {} merged into a pending one)", tag,
             in.reannounce_requests, in.reannounces, in.reannounce_merged);
  if (ctx_.cfg.forecast.enabled) {
    log.info("{}forecasts: {} done (compute p50/p99/max {:.1f}/{:.1f}/{:.1f} ms), {} dropped (worker late), {} "
             "skipped (degraded), {} failed; trip plans accepted {}, no longer fitting the motion {}",
             tag, fc.forecasts, fc.compute.total.quantile(0.5) / 1e3, fc.compute.total.quantile(0.99) / 1e3,
             fc.compute.total.max() / 1e3, fc.forecasts_dropped, fc.forecasts_skipped, fc.forecast_failures,
             in.plans_accepted, fc.plan_unusable);
    for (int i = 0; i < kPlanRejectReasons; ++i)
      if (in.plan_rejects[static_cast<std::size_t>(i)] > 0)
        log.info("{}  rejected trip plans {}: {}", tag, toString(static_cast<PlanReject>(i)),
                 in.plan_rejects[static_cast<std::size_t>(i)]);
  }
}

std::int64_t ShaftHealth::rssKb() const {
  // /proc/self/statm: size resident ... in pages.  pread into a stack
  // buffer: no allocation.
  if (statm_fd_ < 0) return -1;
  char b[128];
  const ssize_t n = ::pread(statm_fd_, b, sizeof b - 1, 0);
  if (n <= 0) return -1;
  b[n] = '\0';
  long size = 0, resident = 0;
  if (std::sscanf(b, "%ld %ld", &size, &resident) != 2) return -1;
  return static_cast<std::int64_t>(resident) * (::sysconf(_SC_PAGESIZE) / 1024);
}

}  // namespace hoist::service::app
