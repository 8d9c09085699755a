// hoist-trips ingest (trips.hpp): a recorded measurement CSV (hoist-estimate's
// columns) through the daemon's trip pipeline (hoist::recordTrips,
// hoist/trip_pipeline.hpp), each trip's condition alarms decided as the
// daemon decides them (PreloadTrend, ShaftFingerprint over the shaft's stored
// trips, then the new ones), and the records stored.
//
// Numbering: from --first-trip, else the shaft's next trip number; a second
// ingest of the same file with the same --first-trip stores nothing twice
// (the store's put is idempotent on (shaft, trip)).  Wall-clock times: the
// row t = 0 is --wall-start (ISO 8601 UTC, e.g. 2026-12-06T08:00:00Z), else
// the time of the ingest.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <unistd.h>

#include "hoist/history/condition_config.hpp"
#include "hoist/history/condition_judge.hpp"
#include "hoist/history/schema.hpp"
#include "hoist/io/config.hpp"
#include "hoist/profile.hpp"
#include "hoist/io/estimator_config.hpp"
#include "hoist/trip_pipeline.hpp"
#include "trips.hpp"

namespace hoist::trips {

namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace

int runIngest(const Options& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const toml::table tbl = io::loadTomlFile(o.config);
  ShaftParams p = io::shaftParamsFromToml(tbl, o.config, history::configSections());
  const io::EstimatorConfig ec = io::estimatorConfigFromToml(tbl, o.config);
  const ConditionSettings cond = history::conditionSettingsFromToml(tbl, o.config);
  const double max_step = o.max_step >= 0.0 ? o.max_step : io::serviceMaxStep(tbl, o.config, hoist::kDefaultMaxStep);
  if (o.modes != 0) p.n = o.modes;
  try {
    p.validate();
  } catch (const ParamError& e) {
    throw UsageError(std::string("--modes: ") + e.what());
  }
  const auto samples = io::readMeasurementsCsvFile(o.measurements);
  EstimatorSettings set = ec.settings;
  double min_dt = samples[1].t - samples[0].t;  // the NIS window is sized for the file's rate
  for (std::size_t i = 2; i < samples.size(); ++i) min_dt = std::min(min_dt, samples[i].t - samples[i - 1].t);
  set.max_rate = std::max(set.max_rate, static_cast<int>(std::min(100000.0, std::ceil(1.0 / min_dt - 1e-9))));
  auto db = openDb(o, false);  // before the long run: a bad --db fails at once
  const bool tty = ::isatty(2) && !o.quiet;
  std::vector<TripRecord> recs;
  try {
    recs = recordTrips(p, set, cond, max_step, samples, [&](double f) {
      if (tty) std::fprintf(stderr, "\rhoist-trips: ingest %3.0f %%", 100.0 * f);
    });
  } catch (const std::domain_error& e) {
    throw std::runtime_error(std::string("the model left its domain: ") + e.what());
  }
  if (tty) std::fputc('\n', stderr);
  const std::int64_t wall0 = o.wall_start_us != 0 ? o.wall_start_us
                             : std::chrono::duration_cast<std::chrono::microseconds>(
                                   std::chrono::system_clock::now().time_since_epoch()).count();
  std::int64_t next = o.first_trip > 0 ? o.first_trip : db->nextTrip(o.shaft);
  history::ConditionJudge judge(cond);
  judge.seed(*db, o.shaft);
  int stored = 0, dup = 0, queued = 0;
  for (auto& r : recs) {
    r.shaft = o.shaft;
    r.trip = next++;
    r.wall_start_us = wall0 + std::llround(r.t_start * 1e6);
    r.wall_end_us = wall0 + std::llround(r.t_end * 1e6);
    judge.judge(r);
    const auto res = db->put(r);
    stored += res == history::PutResult::Stored;
    dup += res == history::PutResult::Duplicate;
    queued += res == history::PutResult::Queued;
    if (!o.quiet)
      std::cout << "trip " << r.trip << " " << (r.direction == TripDirection::Down ? "down" : "up") << " "
                << fmt("%.1f", r.depth_start) << " -> " << fmt("%.1f", r.depth_end) << " m, s = "
                << (r.id.attempted && r.id.sigma_scale >= 0 ? fmt("%.3f", r.id.scale) + " +- " + fmt("%.3f", r.id.sigma_scale)
                                                            : std::string("not identified"))
                << (r.id.informative ? "" : " (not informative)") << ", alarms: "
                << (r.alarms.empty() ? std::string("none") : history::joinAlarms(r.alarms)) << " -- "
                << history::toString(res) << "\n";
  }
  const auto hc = history::historyConfigFromToml(tbl, o.config);
  const std::int64_t pruned = db->prune(hc.keep_days, wall0);
  if (!o.quiet)
    std::cout << "hoist-trips: " << recs.size() << " trip(s) from " << o.measurements << " (" << samples.size()
              << " rows) at n = " << p.n << " into " << db->describe() << ": " << stored << " stored, " << dup
              << " already there, " << queued << " queued; " << pruned << " pruned (keep_days " << hc.keep_days
              << "); " << fmt("%.1f", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count())
              << " s. " << judge.summary() << "\n";
  return 0;
}

}  // namespace hoist::trips
