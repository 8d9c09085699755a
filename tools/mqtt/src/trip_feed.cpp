// hoist-mqtt's trip feed from the history database (see trip_feed.hpp).
#include "hoist/mqtt/trip_feed.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <utility>

#include <spdlog/spdlog.h>

#include "hoist/history/plausible.hpp"
#include "hoist/preload_trend.hpp"

namespace hoist::mqtt {

namespace {

using Json = nlohmann::json;

Json num(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json sig(double s) { return s >= 0.0 && std::isfinite(s) ? Json(s) : Json(nullptr); }

std::string iso(std::int64_t us) {
  const std::time_t secs = static_cast<std::time_t>(us / 1000000);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char b[40];
  std::snprintf(b, sizeof b, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(((us % 1000000) + 1000000) % 1000000 / 1000));
  return b;
}

const char* levelText(int l) { return l == 2 ? "CRITICAL" : l == 1 ? "WARNING" : "NONE"; }

}  // namespace

std::string dbShaft(const std::string& mqtt_shaft) { return mqtt_shaft == "default" ? std::string() : mqtt_shaft; }

Json tripSummary(const TripRecord& r, const ConditionMetrics& c, const std::string& level_text) {
  const bool ident = r.id.attempted && r.id.sigma_scale >= 0.0;
  Json j{{"trip", r.trip},
         {"direction", r.direction == TripDirection::Down ? "down" : "up"},
         {"t_start", num(r.t_start)},
         {"t_end", num(r.t_end)},
         {"Fa", num(r.Fa_end)},
         {"sigma_Fa", sig(r.sigma_Fa_end)},
         {"moment", num(r.moment_end)},
         {"sigma_moment", sig(r.sigma_moment_end)},
         {"preload_scale", ident ? num(r.id.scale) : Json(nullptr)},
         {"sigma_preload_scale", ident ? sig(r.id.sigma_scale) : Json(nullptr)},
         {"mismatch", r.mismatch},
         {"alarms", r.alarms},
         {"shaft", r.shaft},
         {"wall_start", iso(r.wall_start_us)},
         {"wall_end", iso(r.wall_end_us)},
         {"depth_start", num(r.depth_start)},
         {"depth_end", num(r.depth_end)},
         {"peak_speed", num(r.peak_speed)},
         {"informative", r.id.informative},
         {"imbalance", num(r.id.imbalance)},
         {"sigma_imbalance", sig(r.id.sigma_imbalance)},
         {"nis_peak", num(r.nis_peak)},
         {"min_clearance", num(r.min_clearance)}};
  j["identification"] = {{"attempted", r.id.attempted},
                         {"scale", num(r.id.scale)},
                         {"sigma_scale", sig(r.id.sigma_scale)},
                         {"moment", num(r.id.moment)},
                         {"sigma_moment", sig(r.id.sigma_moment)},
                         {"imbalance", num(r.id.imbalance)},
                         {"sigma_imbalance", sig(r.id.sigma_imbalance)},
                         {"informative", r.id.informative},
                         {"loss30_separation", num(r.id.loss30_separation)},
                         {"note", r.id.note}};
  j["condition"] = {{"preload_scale", c.valid ? num(c.preload_scale) : Json(nullptr)},
                    {"sigma", c.valid ? sig(c.preload_sigma) : Json(nullptr)},
                    {"level", levelText(c.guide_preload_low)},
                    {"trips_in_trend", c.trips_in_trend},
                    {"text", level_text}};
  return j;
}

TripUpdate TripFeed::read(history::Store& store, const std::string& shaft, const ConditionSettings& cond,
                          std::int64_t* rejected) {
  history::ListFilter f;
  f.shaft = dbShaft(shaft);
  const auto recs = store.list(f);
  PreloadTrend trend(cond);
  const TripRecord* last = nullptr;
  TripUpdate u;
  for (const auto& r : recs) {
    if (auto why = history::implausible(r); !why.empty()) {
      if (rejected) ++*rejected;
      spdlog::warn("trip feed: {}: trip {} left out: {}", store.describe(), r.trip, why);
      continue;
    }
    const bool used = trend.add(r);
    u.cond.trips_in_trend += used;
    u.cond.last_informative = used;
    last = &r;
  }
  if (!last) return u;  // no trip: u.shaft stays ""
  const PreloadDecision d = trend.decision();
  u.shaft = shaft;
  u.cond.valid = d.valid;
  u.cond.preload_scale = d.scale;
  u.cond.preload_sigma = d.sigma;
  u.cond.guide_preload_low = static_cast<int>(d.level);
  u.cond.last_trip = last->trip;
  u.last = tripSummary(*last, u.cond, d.text);
  return u;
}

TripFeed::TripFeed(history::StoreOptions store, ConditionSettings cond, double poll_s)
    : store_opt_(std::move(store)), cond_(std::move(cond)), poll_s_(poll_s) {
  store_opt_.read_only = true;
  worker_ = std::thread([this] { run(); });
}

TripFeed::~TripFeed() {
  {
    std::lock_guard<std::mutex> l(mu_);
    stop_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void TripFeed::watch(const std::string& shaft) {
  {
    std::lock_guard<std::mutex> l(mu_);
    watched_.emplace(shaft, -1);
  }
  wake_.notify_all();
}

std::vector<TripUpdate> TripFeed::take() {
  std::lock_guard<std::mutex> l(mu_);
  return std::exchange(out_, {});
}

std::int64_t TripFeed::rejected() const {
  std::lock_guard<std::mutex> l(mu_);
  return rejected_;
}

void TripFeed::run() {
  std::unique_ptr<history::Store> store;
  std::string last_error;
  for (;;) {
    std::map<std::string, std::int64_t> todo;
    {
      std::lock_guard<std::mutex> l(mu_);
      todo = watched_;
    }
    try {
      if (!todo.empty() && !store) {
        store = history::openStore(store_opt_);
        spdlog::info("trip feed: reading {} (read-only)", store->describe());
        last_error.clear();
      }
      for (const auto& [shaft, seen] : todo) {
        const std::int64_t next = store->nextTrip(dbShaft(shaft));
        if (next == seen) continue;
        std::int64_t rej = 0;
        TripUpdate u = read(*store, shaft, cond_, &rej);
        std::lock_guard<std::mutex> l(mu_);
        rejected_ += rej;
        watched_[shaft] = next;
        if (!u.shaft.empty()) out_.push_back(std::move(u));
      }
    } catch (const std::exception& e) {
      if (e.what() != last_error) spdlog::error("trip feed: history database: {} (retrying)", e.what());
      last_error = e.what();
      store.reset();
    }
    std::unique_lock<std::mutex> l(mu_);
    if (wake_.wait_for(l, std::chrono::duration<double>(poll_s_), [this] { return stop_; })) return;
  }
}

}  // namespace hoist::mqtt
