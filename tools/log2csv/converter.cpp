// hoist-log2csv's converter: see converter.hpp.
#include "converter.hpp"

#include <cctype>
#include <cstdio>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_imu_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_scenario_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/rope_load_t.hpp"
#include "hoist/trip_plan_t.hpp"
#include "hoist/winder_t.hpp"

namespace hoist::log2csv {

namespace {

std::string sanitize(const std::string& ch) {
  std::string s = ch;
  for (char& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) c = '_';
  return s.empty() ? std::string("_") : s;
}
std::string fileName(const std::string& key) { return key + ".csv"; }
std::string hash8(const std::string& s) {  // FNV-1a, 32 bits
  std::uint32_t h = 2166136261u;
  for (unsigned char c : s) h = (h ^ c) * 16777619u;
  char buf[12];
  std::snprintf(buf, sizeof buf, "%08x", h);
  return buf;
}

/// winder_t: then the log event's own timestamp.
void logUtime(const Event& ev, const hoist::winder_t&, std::string& head, std::string& row) {
  head += ",log_utime";
  row += ',';
  hoist::msg::csvInt(row, ev.timestamp);
}
/// health_t: then rejected_<reason> per reason (the pair of variable arrays
/// reject_reason / rejected, as columns of their own).
void rejectedByReason(const Event&, const hoist::health_t& m, std::string& head, std::string& row) {
  for (const auto& r : m.reject_reason) head += ",rejected_" + r;
  for (auto v : m.rejected) {
    row += ',';
    hoist::msg::csvInt(row, v);
  }
}

/// forecast_t's count column, replaced by the scenario's index.
constexpr std::string_view kScenarioCount = "num_scenarios";

}  // namespace

template <class Msg>
bool Converter::decode(const Event& ev, Msg& m) {
  const auto st = hoist::msg::checkedDecode(ev.data.data(), ev.data.size(), m);
  if (st != hoist::msg::DecodeStatus::ok) {
    ++bad_[{ev.channel, hoist::msg::toString(st)}];
    return false;
  }
  return true;
}

/// One row per message: the generated CSV columns of Msg (hoist/msg/codec.hpp,
/// from msgs/*.lcm), then the columns `extra(ev, m, header, row)` appends.
template <class Msg, class Extra>
bool Converter::table(const Event& ev, const char* type, Extra extra) {
  Msg m{};
  if (!decode(ev, m)) return false;
  std::string head, row;
  hoist::msg::csvHeader<Msg>(head);
  hoist::msg::csvRow(row, m);
  extra(ev, m, head, row);
  writer(ev.channel, type, head)->write(row);
  return true;
}
template <class Msg>
bool Converter::table(const Event& ev, const char* type) {
  return table<Msg>(ev, type, [](const Event&, const Msg&, std::string&, std::string&) {});
}

/// Returns false if the event is of no known type or does not decode.
bool Converter::handle(const Event& ev) {
  const hoist::msg::TypeInfo* t = hoist::msg::findByFingerprint(ev.data.data(), ev.data.size());
  const std::string name = t ? t->name : "";
  if (name == "hoist.cage_state_t") return table<hoist::cage_state_t>(ev, "cage_state_t");
  if (name == "hoist.winder_t") return table<hoist::winder_t>(ev, "winder_t", logUtime);
  if (name == "hoist.guide_shape_t") return shape(ev);
  if (name == "hoist.alarm_t") return table<hoist::alarm_t>(ev, "alarm_t");
  if (name == "hoist.alarm_ack_t") return table<hoist::alarm_ack_t>(ev, "alarm_ack_t");
  if (name == "hoist.health_t") return table<hoist::health_t>(ev, "health_t", rejectedByReason);
  if (name == "hoist.forecast_t") return forecast(ev);
  if (name == "hoist.trip_plan_t") return table<hoist::trip_plan_t>(ev, "trip_plan_t");
  if (name == "hoist.estimate_t") return table<hoist::estimate_t>(ev, "estimate_t");
  if (name == "hoist.cage_imu_t") return table<hoist::cage_imu_t>(ev, "cage_imu_t");
  if (name == "hoist.rope_load_t") return table<hoist::rope_load_t>(ev, "rope_load_t");
  ++unknown_[ev.channel];
  return false;
}

/// Closes every file (checked to the last byte), then prints the summary.
/// False if any file failed.
bool Converter::finish(std::ostream& os) {
  for (auto& [key, w] : writers_) {
    if (!w->close()) {
      os << "hoist-log2csv: error: " << w->error << "\n";
      failed_ = true;
    } else {
      os << "hoist-log2csv: " << w->rows << " rows of hoist." << w->type << " on "
         << hoist::msg::terminalSafe(w->channel) << " -> " << w->path << "\n";
    }
  }
  for (const auto& n : notes_) os << "hoist-log2csv: note: " << n << "\n";
  for (const auto& [ch, n] : unknown_)
    os << "hoist-log2csv: note: skipped " << n << " event(s) of an unknown type on channel "
       << hoist::msg::terminalSafe(ch) << "\n";
  for (const auto& [key, n] : bad_)
    os << "hoist-log2csv: skipped " << n << " event(s) on channel " << hoist::msg::terminalSafe(key.first)
       << " that carry a hoist fingerprint but fail the checked decode (" << key.second << ")\n";
  return !failed_;
}
long Converter::badCount() const {
  long n = 0;
  for (auto& [c, k] : bad_) n += k;
  return n;
}
long Converter::unknownCount() const {
  long n = 0;
  for (auto& [c, k] : unknown_) n += k;
  return n;
}

/// The writer for (channel, type), created with `header` on first use
/// (`suffix`: a second file of the channel, DIR/<CHANNEL><suffix>.csv).
/// Two channels never share a file: names that sanitize alike
/// ("a/HOIST_WINDER", "a_HOIST_WINDER") get distinct files (the later one
/// DIR/<CHANNEL>.<hash of its name>.csv), and a note names both.
Writer* Converter::writer(const std::string& channel, const char* type, const std::string& header,
                          const char* suffix) {
  const std::string id = channel + '\0' + suffix + '\0' + type;
  auto it = writers_.find(id);
  if (it == writers_.end()) {
    std::string key = sanitize(channel) + suffix;
    const auto owner = [&](const std::string& k) -> const Owner* {
      auto o = files_.find(k);
      return o == files_.end() ? nullptr : &o->second;
    };
    // The channel's messages changed type midway: a second file of its own.
    if (const Owner* o = owner(key); o && o->channel == channel) key += std::string(".") + type;
    if (const Owner* o = owner(key); o && o->channel != channel) {
      std::string alt = sanitize(channel) + "." + hash8(channel) + suffix;
      for (int n = 2; owner(alt) && !(owner(alt)->channel == channel); ++n)
        alt = sanitize(channel) + "." + hash8(channel) + "-" + std::to_string(n) + suffix;
      if (owner(alt)) alt += std::string(".") + type;
      notes_.push_back("channels " + hoist::msg::terminalSafe(o->channel) + " and " +
                       hoist::msg::terminalSafe(channel) + " have the same file name " + fileName(key) +
                       ": the second is written to " + fileName(alt));
      key = alt;
    }
    files_[key] = Owner{channel};
    auto w = std::make_unique<Writer>();
    w->type = type;
    w->channel = channel;
    w->path = (dir_ / fileName(key)).string();
    w->open();
    w->write(header);
    it = writers_.emplace(id, std::move(w)).first;
  }
  ++it->second->rows;
  return it->second.get();
}

/// One row per scenario: the forecast's columns with its count column
/// (num_scenarios) replaced by the scenario's index, then the scenario's
/// columns; the decimated series (variable arrays: no columns) one row per
/// point in DIR/<CHANNEL>.series.csv.
bool Converter::forecast(const Event& ev) {
  hoist::forecast_t m{};
  if (!decode(ev, m)) return false;
  if (m.scenarios.empty()) return true;  // nothing to tabulate (counted as a message, no row)
  std::string head;
  for (const auto& c : hoist::msg::csvColumns<hoist::forecast_t>()) {
    head += c.name == kScenarioCount ? std::string_view("scenario") : std::string_view(c.name);
    head += ',';
  }
  hoist::msg::csvHeader<hoist::forecast_scenario_t>(head);
  Writer* w = writer(ev.channel, "forecast_t", head);
  --w->rows;  // rows counted per scenario below
  bool any_points = false;
  for (std::size_t i = 0; i < m.scenarios.size(); ++i) {
    const auto& sc = m.scenarios[i];
    std::string row;
    for (const auto& c : hoist::msg::csvColumns<hoist::forecast_t>()) {
      if (c.name == kScenarioCount) hoist::msg::csvInt(row, static_cast<std::int64_t>(i));
      else c.write(row, m);
      row += ',';
    }
    hoist::msg::csvRow(row, sc);
    w->write(row);
    ++w->rows;
    any_points = any_points || sc.num_points > 0;
  }
  if (!any_points) return true;
  Writer* s = writer(ev.channel, "forecast_t",
                     "utime,seq,scenario,name,i,t,min_clearance,lambda0_min,lambda0_max", ".series");
  --s->rows;
  for (std::size_t i = 0; i < m.scenarios.size(); ++i) {
    const auto& sc = m.scenarios[i];
    for (std::size_t k = 0; k < sc.series_t.size(); ++k) {
      std::string row;
      for (const std::int64_t v : {m.utime, m.seq, static_cast<std::int64_t>(i)}) {
        hoist::msg::csvInt(row, v);
        row += ',';
      }
      hoist::msg::csvText(row, sc.name);
      row += ',';
      hoist::msg::csvInt(row, static_cast<std::int64_t>(k));
      for (const double v : {sc.series_t[k], sc.series_min_clearance[k], sc.series_lambda0_min[k],
                             sc.series_lambda0_max[k]}) {
        row += ',';
        hoist::msg::csvReal(row, v);
      }
      s->write(row);
      ++s->rows;
    }
  }
  return true;
}

/// One row per depth sample, t,x,y1,y2,l,utime (as hoist-sim --shape-out).
bool Converter::shape(const Event& ev) {
  hoist::guide_shape_t m{};
  if (!decode(ev, m)) return false;
  Writer* w = writer(ev.channel, "guide_shape_t", "t,x,y1,y2,l,utime");
  for (std::size_t i = 0; i < m.x.size(); ++i) {
    std::string row;
    for (const double v : {m.t, m.x[i], m.y1[i], m.y2[i], m.l}) {
      hoist::msg::csvReal(row, v);
      row += ',';
    }
    hoist::msg::csvInt(row, m.utime);
    w->write(row);
  }
  return true;
}

}  // namespace hoist::log2csv
