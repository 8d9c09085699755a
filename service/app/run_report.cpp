// The daemon's run report: see run_report.hpp.
#include "run_report.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "hoist/io/checked_file.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/version.hpp"

namespace hoist::service::inline app {

namespace {

nlohmann::ordered_json histogramJson(const LatencyHistogram& h) {
  nlohmann::ordered_json bins = nlohmann::ordered_json::array();
  for (int b = 0; b < LatencyHistogram::kBins; ++b)
    if (h.binCount(b) != 0) bins.push_back({LatencyHistogram::binLowerUs(b), h.binCount(b)});
  return {{"count", h.count()}, {"p50", h.quantile(0.5)},     {"p99", h.quantile(0.99)},
          {"p999", h.quantile(0.999)}, {"max", h.max()}, {"bins", std::move(bins)}};
}

/// Per twin and tick, in microseconds: where the process's CPU time went.
/// model_step excludes the envelope; tick_other is the rest of each shaft's
/// tick (alarms, health bookkeeping, histograms) and the loop around it;
/// receive is every drain of the input socket; timer_and_rest is the
/// process's CPU time (user + system, all threads) minus all of the above:
/// timer wake-ups, Asio, the kernel's share of the work not inside those
/// calls, the log thread.
nlohmann::ordered_json costSplit(const RunFacts& f) {
  std::int64_t model = 0, env = 0, publish = 0, shaft_ticks = 0, exact = 0, bounded = 0, deferred = 0;
  int longest = 0;
  for (const ShaftTwin* sp : f.shafts) {
    const TickStats& st = sp->stats().tick;
    const TwinCore& core = sp->core();
    model += st.ns_model;
    env += core.envelopeNanos();
    publish += st.ns_publish;
    shaft_ticks += st.ticks;
    exact += core.envelope().exactEvaluations();
    bounded += core.envelope().boundedEvaluations();
    deferred += core.envelope().deferredEvaluations();
    longest = std::max(longest, core.envelope().longestDeferral());
  }
  const double cpu = static_cast<double>(f.cpu_ns);
  const double per = shaft_ticks > 0 ? 1e-3 / static_cast<double>(shaft_ticks) : 0.0;
  const double other = static_cast<double>(f.ns_ticks - model - publish);
  publish += f.ns_flush;  // the batched sends (outside the shafts' ticks)
  return {{"twin_ticks", shaft_ticks},
          {"model_step", per * static_cast<double>(model - env)},
          {"envelope", per * static_cast<double>(env)},
          {"publish", per * static_cast<double>(publish)},
          {"receive", per * static_cast<double>(f.ns_receive)},
          {"tick_other", per * other},
          {"timer_and_rest", per * (cpu - static_cast<double>(f.ns_ticks + f.ns_receive + f.ns_flush))},
          {"process_cpu", per * cpu},
          {"envelope_exact", exact},
          {"envelope_bounded", bounded},
          {"envelope_deferred", deferred},
          {"envelope_longest_deferral", longest}};
}

nlohmann::ordered_json splitJson(const MissRecord& r) {
  auto us = [](std::int64_t ns) { return 1e-3 * static_cast<double>(ns); };
  const LoopSplit& x = r.work;
  return {{"receive", us(x.receive)}, {"step", us(x.step)},     {"envelope", us(x.envelope)},
          {"publish", us(x.publish)}, {"forecast", us(x.forecast)}, {"start", us(x.start)},
          {"health", us(x.health)},   {"other", us(x.other)},     {"timer", r.timer_us},
          {"idle", r.idle_us}};
}

nlohmann::ordered_json missJson(const MissRecord& r, const RunFacts& f) {
  auto label = [&](int id) -> std::string {
    if (id < 0 || static_cast<std::size_t>(id) >= f.shafts.size()) return "";
    return f.shafts[static_cast<std::size_t>(id)]->reportLabel();
  };
  return {{"seq", r.seq},
          {"utime", r.utime},
          {"wall_s", r.wall},
          {"model_t", r.model_t},
          {"schedule_hz", r.rate},
          {"tick", r.tick},
          {"skipped", r.skipped},
          {"late_us", r.late_us},
          {"shafts", r.shafts},
          {"shafts_late", r.shafts_late},
          {"first_shaft", label(r.first_shaft)},
          {"first_late_us", r.first_late_us},
          {"worst_shaft", label(r.worst_shaft)},
          {"worst_late_us", r.worst_late_us},
          {"window_us", r.window_us},
          {"cpu_us", r.cpu_us},
          {"split_us", splitJson(r)}};
}

/// Every kept miss record, oldest first, and how many were dropped.
nlohmann::ordered_json missesJson(const RunFacts& f) {
  const MissLog& m = *f.misses;
  nlohmann::ordered_json records = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < m.kept(); ++i) records.push_back(missJson(m.at(i), f));
  nlohmann::ordered_json o;
  o["note"] =
      "one record per tick that started more than a period late (each shaft of its schedule missed `skipped` "
      "deadlines); split_us: the loop's time from the schedule's previous tick start to this one, by phase "
      "(timer: neither worked nor idle before the deadline: wake-up, kernel, a stall of the machine); the phases "
      "are steady-clock spans, so a preemption inside one counts there: cpu_us, the loop thread's CPU time in the "
      "same interval, shows it (work well above cpu_us: the thread was not running); the ring keeps the latest " + std::to_string(MissLog::kCapacity) + " records";
  o["recorded"] = m.total();
  o["kept"] = m.kept();
  o["dropped"] = m.dropped();
  const MissRecord* w = m.worst();
  o["worst"] = w ? missJson(*w, f) : nlohmann::ordered_json();
  o["records"] = std::move(records);
  return o;
}

/// One shaft: its label, prefix and modes; `health`, the final HOIST_HEALTH
/// as the generated toJson writes it (every counter under health_t's name,
/// the one name it has everywhere); then the figures only a whole run has:
/// the whole-run histograms and the counters HOIST_HEALTH does not carry.
nlohmann::ordered_json shaftJson(const ShaftTwin& sp) {
  const ShaftStatsView st = sp.stats();
  const TwinConfig& c = sp.config();
  nlohmann::ordered_json o;
  o["label"] = sp.reportLabel();
  o["channel_prefix"] = c.service.channel_prefix;
  o["modes"] = c.shaft.n;
  o["health"] = nlohmann::ordered_json(hoist::msg::toJson(sp.lastHealth()));
  o["commands_applied"] = st.in.commands_applied;
  if (c.forecast.enabled) {
    o["forecasts_from_estimate"] = st.forecast.forecasts_from_estimate;
    o["forecast_failures"] = st.forecast.forecast_failures;
    o["forecast_us"] = histogramJson(st.forecast.compute.total);
  }
  o["step_us"] = histogramJson(st.stepTotal());
  o["late_us"] = histogramJson(st.tick.late.total);
  return o;
}

}  // namespace

bool writeRunReport(const std::string& path, const RunFacts& f, spdlog::logger& log) {
  char host[256] = "";
  gethostname(host, sizeof host - 1);
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  nlohmann::ordered_json j;
  j["tool"] = "hoist-twind";
  j["version"] = hoist::kVersionString;
  j["command"] = f.command_line;
  j["host"] = host;
  j["date"] = date;
  j["cpus_online"] = sysconf(_SC_NPROCESSORS_ONLN);
  j["duration_s"] = f.duration_s;
  j["stop_reason"] = f.stop_reason;
  j["realtime"] = {{"memory_lock", f.realtime.mlockall},
                   {"scheduling", f.realtime.scheduling},
                   {"affinity", f.realtime.affinity}};
  j["log_lines_dropped"] = f.log_lines_dropped;
  if (f.receiver)
    j["input_socket"] = {{"rcvbuf_bytes", f.receiver->rcvbuf()},
                         {"datagrams", f.receiver->received()},
                         {"kernel_drops", f.receiver->refreshKernelDrops()},
                         {"ignored", f.receiver->ignored()},
                         {"malformed", f.receiver->malformed()}};
  if (f.sender) j["output_socket"] = {{"datagrams", f.sender->sent()}, {"system_calls", f.sender->systemCalls()}};
  j["cost_split_us_per_twin_tick"] = costSplit(f);
  if (f.misses) j["misses"] = missesJson(f);
  j["histogram_note"] =
      "times in microseconds; " + std::to_string(LatencyHistogram::kPerDecade) +
      " logarithmic bins per decade from 0.1 us, so quantiles are bin centres (about 1.2 % resolution); "
      "bins are [lower edge, count]";
  nlohmann::ordered_json shafts = nlohmann::ordered_json::array();
  for (const ShaftTwin* sp : f.shafts) shafts.push_back(shaftJson(*sp));
  j["shafts"] = std::move(shafts);
  try {
    // Every byte checked, with the errno text; a fresh temporary file renamed
    // onto a regular file only (hoist/io/checked_file.hpp).
    hoist::io::CheckedFile file(path, "--report");
    // Invalid UTF-8 (a path or host name) is replaced, never a throw at stop.
    file.write(j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
    file.close();
  } catch (const hoist::io::WriteError& e) {
    log.error("cannot write the run report: {}", e.what());
    return false;
  }
  log.info("run report written to {}", path);
  return true;
}

}  // namespace hoist::service::app
