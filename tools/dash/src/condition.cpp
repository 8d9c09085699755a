// The "Shaft condition" view's data (see condition.hpp).
#include "condition.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <utility>

#include <spdlog/spdlog.h>

#include "hoist/history/condition_config.hpp"
#include "hoist/history/judged_history.hpp"
#include "hoist/history/plausible.hpp"
#include "hoist/history/record_json.hpp"
#include "hoist/history/schema.hpp"
#include "hoist/io/config.hpp"
#include "hoist/preload_trend.hpp"
#include "hoist/shaft_fingerprint.hpp"

namespace hoist::dash {

namespace {

using Json = nlohmann::json;

std::int64_t nowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

const char* levelName(ConditionLevel l) {
  switch (l) {
    case ConditionLevel::Warning: return "WARNING";
    case ConditionLevel::Critical: return "CRITICAL";
    case ConditionLevel::None: break;
  }
  return "NONE";
}

const char* dirName(TripDirection d) { return d == TripDirection::Down ? "down" : "up"; }

/// A number for the page: null when not finite (JSON has no NaN).
Json num(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

}  // namespace

ConditionOptions conditionOptions(const std::string& history_url, const std::string& config,
                                  const std::string& shaft) {
  ConditionOptions o;
  o.shaft = shaft;
  history::HistoryConfig hc;
  std::string dir;
  if (!config.empty()) {
    const toml::table t = io::loadTomlFile(config);
    hc = history::historyConfigFromToml(t, config);
    o.cond = history::conditionSettingsFromToml(t, config);
    dir = std::filesystem::path(config).parent_path().string();
    if (dir.empty()) dir = ".";
  }
  if (history_url.empty() && config.empty()) throw std::invalid_argument("--history: required (or --config)");
  if (!history_url.empty()) {  // relative to the working directory, as any command-line path
    const auto u = history::parseDatabaseUrl(history_url, "--history");
    hc.url = u.backend == history::Backend::Sqlite ? std::filesystem::absolute(u.target).string() : history_url;
  }
  o.store = history::resolveStoreOptions(hc, dir, history_url.empty() ? config + ": history.url" : "--history");
  o.store.read_only = true;
  return o;
}

Json ConditionView::build(history::Store& store, const std::string& shaft, const ConditionSettings& cond,
                          std::size_t max_trips) {
  // The trips the daemon's judge rests on (a bounded read: the newest
  // [condition] seed_trips and the baseline before them).
  history::JudgedHistory h = history::readJudgedHistory(store, shaft, cond);
  Json j;
  j["ok"] = true;
  j["error"] = "";
  j["db"] = store.describe();
  j["shaft"] = shaft;
  j["thresholds"] = {{"warning", cond.preload_warning}, {"critical", cond.preload_critical},
                     {"max_sigma", cond.max_sigma}};
  // Validate before anything uses a value.
  Json notes = Json::array();
  std::size_t rejected = 0;
  auto valid = [&](std::vector<TripRecord>& in) {
    std::vector<TripRecord> out;
    for (auto& r : in) {
      if (auto why = history::implausible(r); !why.empty()) {
        ++rejected;
        if (notes.size() < 10) notes.push_back("trip " + std::to_string(r.trip) + ": " + why);
        continue;
      }
      out.push_back(std::move(r));
    }
    return out;
  };
  const std::vector<TripRecord> base = valid(h.baseline);
  std::vector<TripRecord> recs = valid(h.trips);
  j["trips"] = recs.size();
  j["stored_last_trip"] = h.last_trip;
  j["windowed"] = h.windowed;
  j["rejected"] = rejected;
  j["rejected_notes"] = notes;

  // The daemon's decisions, replayed over the stored trips (as its judge
  // seeds them: ConditionJudge::seed).
  PreloadTrend trend(cond);
  ShaftFingerprint finger(cond);
  history::primeFingerprint(base, recs, h.marks, finger);
  const std::size_t first = recs.size() > max_trips ? recs.size() - max_trips : 0;
  Json tr = Json::array();
  for (std::size_t i = 0; i < recs.size(); ++i) {
    const TripRecord& r = recs[i];
    trend.add(r);
    finger.add(r);
    if (i < first) continue;
    const bool identified = r.id.attempted && r.id.sigma_scale >= 0.0;
    tr.push_back({{"trip", r.trip},
                  {"direction", dirName(r.direction)},
                  {"attempted", identified},
                  {"informative", identified && r.id.informative},
                  {"s", identified ? num(r.id.scale) : Json(nullptr)},
                  {"sigma", identified ? num(r.id.sigma_scale) : Json(nullptr)},
                  {"combined", trend.valid() ? num(trend.scale()) : Json(nullptr)},
                  {"combined_sigma", trend.valid() ? num(trend.sigma()) : Json(nullptr)}});
  }
  j["trend"] = tr;
  const PreloadDecision pd = trend.decision();
  j["preload"] = {{"level", levelName(pd.level)}, {"valid", pd.valid},    {"scale", num(pd.scale)},
                  {"sigma", num(pd.sigma)},        {"upper95", num(pd.upper95)}, {"trips", pd.trips},
                  {"text", pd.text}};
  const FingerprintDecision fd = finger.decision();
  Json hits = Json::array();
  for (const auto& h : fd.hits)
    hits.push_back({{"direction", dirName(h.direction)}, {"depth_lo", h.depth_lo}, {"trips_over", h.trips_over},
                    {"z_last", num(h.z_last)}});
  j["fingerprint"] = {{"active", fd.active}, {"text", fd.text}, {"hits", hits}};

  // Heat map: the shown trips x every bin depth seen (mm keys: exact bins).
  std::set<long long> depths_mm;
  double bin = cond.depth_bin;
  for (std::size_t i = first; i < recs.size(); ++i) {
    bin = recs[i].depth_bin;
    for (const auto& b : recs[i].bins) depths_mm.insert(std::llround(b.depth_lo * 1000.0));
  }
  Json trips = Json::array(), depths = Json::array(), cells = Json::array();
  for (long long mm : depths_mm) depths.push_back(mm / 1000.0);
  for (std::size_t i = first; i < recs.size(); ++i) {
    trips.push_back(recs[i].trip);
    std::map<long long, const DepthBinStats*> by;
    for (const auto& b : recs[i].bins) by[std::llround(b.depth_lo * 1000.0)] = &b;
    Json row = Json::array();
    for (long long mm : depths_mm) {
      const auto it = by.find(mm);
      row.push_back(it != by.end() && it->second->samples > 0 ? num(it->second->resid_rms) : Json(nullptr));
    }
    cells.push_back(row);
  }
  j["heatmap"] = {{"value", "resid_rms"}, {"bin", bin}, {"trips", trips}, {"depths", depths}, {"cells", cells}};
  j["last"] = recs.empty() ? Json(nullptr) : history::recordToJson(recs.back());
  return j;
}

ConditionView::ConditionView(ConditionOptions o) : opt_(std::move(o)) {
  opt_.store.read_only = true;
  json_ = Json{{"ok", false}, {"loading", true}, {"error", "reading the history database..."}, {"generation", 0}}.dump();
  worker_ = std::thread([this] { run(); });
}

ConditionView::~ConditionView() {
  {
    std::lock_guard<std::mutex> l(wake_mu_);
    stop_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

std::string ConditionView::snapshot() const {
  std::lock_guard<std::mutex> l(mu_);
  return json_;
}

void ConditionView::publish(Json j) {
  j["generation"] = generation_.load() + 1;
  j["updated_us"] = nowUs();
  std::string s = j.dump(-1, ' ', false, Json::error_handler_t::replace);
  {
    std::lock_guard<std::mutex> l(mu_);
    json_ = std::move(s);
  }
  ++generation_;
}

void ConditionView::run() {
  std::unique_ptr<history::Store> store;
  std::int64_t seen_next = -1;
  std::string last_error;
  auto last_build = std::chrono::steady_clock::now();
  const std::string where = opt_.store.db.backend == history::Backend::Sqlite
                                ? "sqlite " + opt_.store.db.target
                                : std::string("postgresql");
  for (;;) {
    try {
      if (!store) {
        store = history::openStore(opt_.store);
        spdlog::info("shaft condition: reading {} (read-only), shaft '{}'", store->describe(), opt_.shaft);
        seen_next = -1;
      }
      const std::int64_t next = store->nextTrip(opt_.shaft);
      const auto now = std::chrono::steady_clock::now();
      if (next != seen_next || now - last_build > std::chrono::duration<double>(opt_.rebuild_s)) {
        Json j = build(*store, opt_.shaft, opt_.cond, opt_.max_trips);
        if (j["rejected"].get<std::size_t>() > 0)
          spdlog::warn("shaft condition: {} trip record(s) in {} rejected (first: {})", j["rejected"].get<std::size_t>(),
                       store->describe(), j["rejected_notes"][0].get<std::string>());
        if (next != seen_next && seen_next >= 0)
          spdlog::info("shaft condition: new trip(s) in {}: {} trip(s)", store->describe(), j["trips"].get<std::size_t>());
        publish(std::move(j));
        seen_next = next;
        last_build = now;
        if (!last_error.empty()) spdlog::info("shaft condition: {} readable again", store->describe());
        last_error.clear();
      }
    } catch (const std::exception& e) {
      const std::string msg = e.what();
      if (msg != last_error) {
        spdlog::error("shaft condition: history database {}: {}", where, msg);
        publish(Json{{"ok", false}, {"error", msg}, {"db", where}, {"shaft", opt_.shaft}});
      }
      last_error = msg;
      store.reset();  // re-open at the next poll (a file that appears, a server back)
      seen_next = -1;
    }
    std::unique_lock<std::mutex> l(wake_mu_);
    if (wake_.wait_for(l, std::chrono::duration<double>(opt_.poll_s), [this] { return stop_; })) return;
  }
}

}  // namespace hoist::dash
