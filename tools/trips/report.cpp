// hoist-trips list, show, export and baseline (trips.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "hoist/history/record_json.hpp"
#include "hoist/history/schema.hpp"
#include "hoist/io/checked_file.hpp"
#include "trips.hpp"

namespace hoist::trips {

namespace {

using history::Kind;
using history::Value;

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string valueText(const Value& v) {
  switch (v.kind) {
    case Kind::Real: return num(v.real, 17);
    case Kind::Integer: return std::to_string(v.integer);
    case Kind::Boolean: return v.integer ? "1" : "0";
    case Kind::Text: return csvField(v.text);
  }
  return {};
}

const char* dirName(TripDirection d) { return d == TripDirection::Down ? "down" : "up"; }

/// Writes to --out (a checked file) or stdout.
class Output {
 public:
  explicit Output(const std::string& path, const std::string& label = "--out") {
    if (!path.empty() && path != "-") file_.emplace(path, label);
  }
  void write(const std::string& s) {
    if (file_) file_->write(s);
    else std::cout << s;
  }
  void close() {
    if (file_) file_->close();
    else std::cout.flush();
  }

 private:
  std::optional<io::CheckedFile> file_;
};

// The list's CSV: the columns first, then what an analyst also wants.
constexpr const char* kListHeader =
    "trip,direction,t_start,t_end,Fa,sigma_Fa,moment,sigma_moment,preload_scale,sigma_preload_scale,mismatch,alarms,"
    "shaft,wall_start,wall_end,depth_start,depth_end,peak_speed,informative,imbalance,sigma_imbalance,nis_peak,"
    "min_clearance\n";

std::string listCsvRow(const TripRecord& r) {
  // Fa and M at arrival: the estimate that saw the whole trip.
  std::string s = std::to_string(r.trip) + "," + dirName(r.direction) + "," + num(r.t_start) + "," + num(r.t_end) + "," +
                  num(r.Fa_end) + "," + sigma(r.sigma_Fa_end) + "," + num(r.moment_end) + "," +
                  sigma(r.sigma_moment_end) + ",";
  if (r.id.attempted) s += num(r.id.scale) + "," + sigma(r.id.sigma_scale);
  else s += ",";
  s += std::string(",") + (r.mismatch ? "1" : "0") + "," + history::joinAlarms(r.alarms) + "," + csvField(r.shaft) + "," +
       isoTime(r.wall_start_us) + "," + isoTime(r.wall_end_us) + "," + num(r.depth_start) + "," + num(r.depth_end) +
       "," + num(r.peak_speed) + "," + (r.id.informative ? "1" : "0") + "," + num(r.id.imbalance) + "," +
       sigma(r.id.sigma_imbalance) + "," + num(r.nis_peak) + "," + num(r.min_clearance) + "\n";
  return s;
}

std::string pm(double v, double s, const char* fmt) {
  char a[64], b[64];
  std::snprintf(a, sizeof a, fmt, v);
  if (s < 0) return std::string(a) + " (n/o)";
  std::snprintf(b, sizeof b, fmt, s);
  return std::string(a) + " +- " + b;
}

std::string tableRow(const TripRecord& r) {
  char buf[512];
  const std::string scale = !r.id.attempted ? "-" : pm(r.id.scale, r.id.sigma_scale, "%.3f") + (r.id.informative ? "" : " *");
  std::snprintf(buf, sizeof buf, "%6lld  %-4s  %-24s %7.1f  %7.1f -> %-7.1f  %-22s  %-22s  %-20s  %-3s  %s\n",
                static_cast<long long>(r.trip), dirName(r.direction), isoTime(r.wall_start_us).c_str(),
                r.t_end - r.t_start, r.depth_start, r.depth_end, pm(r.Fa_end, r.sigma_Fa_end, "%.0f").c_str(),
                pm(r.moment_end, r.sigma_moment_end, "%.0f").c_str(), scale.c_str(), r.mismatch ? "yes" : "no",
                r.alarms.empty() ? "-" : history::joinAlarms(r.alarms).c_str());
  return buf;
}

}  // namespace

std::string isoTime(std::int64_t us) {
  const std::time_t secs = static_cast<std::time_t>(us / 1000000);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[48];
  const int ms = static_cast<int>((us % 1000000) / 1000);
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                tm.tm_hour, tm.tm_min, tm.tm_sec, ms < 0 ? 0 : ms);
  return buf;
}

std::string num(double v, int digits) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string sigma(double s, int digits) { return s < 0 ? std::string() : num(s, digits); }

std::vector<TripRecord> selected(history::Store& s, const Options& o, bool with_bins) {
  history::ListFilter f;
  if (!o.all_shafts) f.shaft = o.shaft;
  f.with_bins = with_bins;
  return s.list(f);
}

int runList(const Options& o) {
  auto db = openDb(o, true);
  const auto recs = selected(*db, o, false);
  Output out(o.out);
  if (o.format == "csv") {
    out.write(kListHeader);
    for (const auto& r : recs) out.write(listCsvRow(r));
  } else if (o.format == "json") {
    auto a = nlohmann::json::array();
    for (const auto& r : recs) a.push_back(history::recordToJson(r));
    out.write(a.dump(1) + "\n");
  } else {
    char head[256];
    std::snprintf(head, sizeof head, "%6s  %-4s  %-24s %7s  %-18s  %-22s  %-22s  %-20s  %-3s  %s\n", "trip", "dir",
                  "departure (UTC)", "time/s", "depth/m", "Fa/N (arrival)", "M/N m (arrival)", "preload scale s",
                  "mm", "alarms");
    out.write(head);
    for (const auto& r : recs) out.write(tableRow(r));
    out.write(std::to_string(recs.size()) + " trip(s) in " + db->describe() +
              (o.all_shafts ? "" : ", shaft '" + o.shaft + "'") + "; * = not informative (sigma above max_sigma), "
              "n/o = not observed, mm = MODEL_MISMATCH\n");
  }
  out.close();
  return 0;
}

int runShow(const Options& o) {
  auto db = openDb(o, true);
  const auto r = db->get(o.shaft, o.trip);
  if (!r) {
    std::cerr << "hoist-trips: error: no trip " << o.trip << " of shaft '" << o.shaft << "' in " << db->describe()
              << "\n";
    return 1;
  }
  Output out(o.out);
  if (o.format == "json") {
    out.write(history::recordToJson(*r).dump(1) + "\n");
    out.close();
    return 0;
  }
  std::string s = "trip " + std::to_string(r->trip) + (r->shaft.empty() ? "" : " of shaft '" + r->shaft + "'") + ", " +
                  dirName(r->direction) + ", " + isoTime(r->wall_start_us) + " .. " + isoTime(r->wall_end_us) + "\n";
  const auto baseline = db->baseline(r->shaft);
  const bool marked = std::find(baseline.begin(), baseline.end(), r->trip) != baseline.end();
  s += std::string("  baseline: ") + (marked ? "marked" : "no") + "\n";
  // Every stored column, by the schema's names (nothing left out).
  for (const auto& f : history::tripFields()) {
    const Value v = f.get(*r);
    s += "  " + std::string(f.column) + ": " + (v.kind == Kind::Text ? v.text : valueText(v)) + "\n";
  }
  s += "depth bins (" + std::to_string(r->bins.size()) + ", " + num(r->depth_bin) + " m):\n ";
  for (const auto& f : history::binFields()) {
    char c[32];
    std::snprintf(c, sizeof c, " %12s", std::string(f.column).c_str());
    s += c;
  }
  s += "\n";
  for (const auto& b : r->bins) {
    s += " ";
    for (const auto& f : history::binFields()) {
      const Value v = f.get(b);
      char c[32];
      if (v.kind == Kind::Integer) std::snprintf(c, sizeof c, " %12lld", static_cast<long long>(v.integer));
      else std::snprintf(c, sizeof c, " %12.5g", v.real);
      s += c;
    }
    s += "\n";
  }
  out.write(s);
  out.close();
  return 0;
}

int runExport(const Options& o) {
  auto db = openDb(o, true);
  const auto recs = selected(*db, o, true);
  Output out(o.out);
  if (o.format == "json") {
    auto a = nlohmann::json::array();
    for (const auto& r : recs) a.push_back(history::recordToJson(r));
    out.write(a.dump(1) + "\n");
  } else {
    out.write(history::tripColumnList() + "\n");
    for (const auto& r : recs) {
      std::string row = csvField(r.shaft) + "," + std::to_string(r.trip);
      for (const auto& f : history::tripFields()) row.append(",").append(valueText(f.get(r)));
      out.write(row + "\n");
    }
  }
  if (!o.bins_out.empty()) {
    Output bins(o.bins_out, "--bins");
    bins.write("shaft,trip,idx," + history::binColumnList() + "\n");
    for (const auto& r : recs)
      for (std::size_t i = 0; i < r.bins.size(); ++i) {
        std::string row = csvField(r.shaft) + "," + std::to_string(r.trip) + "," + std::to_string(i);
        for (const auto& f : history::binFields()) row.append(",").append(valueText(f.get(r.bins[i])));
        bins.write(row + "\n");
      }
    bins.close();
  }
  out.close();
  if (!o.quiet && !o.out.empty() && o.out != "-")
    std::cerr << "hoist-trips: exported " << recs.size() << " trip(s) to " << o.out << "\n";
  return 0;
}

int runBaseline(const Options& o) {
  const bool writes = !o.mark.empty() || !o.unmark.empty();
  auto db = openDb(o, !writes);
  const auto now = std::chrono::duration_cast<std::chrono::microseconds>(
                       std::chrono::system_clock::now().time_since_epoch()).count();
  for (auto t : o.mark) db->markBaseline(o.shaft, t, true, now);
  for (auto t : o.unmark) db->markBaseline(o.shaft, t, false, now);
  const auto b = db->baseline(o.shaft);
  std::string s = "baseline of shaft '" + o.shaft + "': ";
  if (b.empty()) s += "none marked (the trend uses the first [condition] baseline_trips trips)";
  for (std::size_t i = 0; i < b.size(); ++i) s.append(i ? " " : "").append(std::to_string(b[i]));
  std::cout << s << "\n";
  return 0;
}

}  // namespace hoist::trips
