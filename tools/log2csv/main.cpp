// hoist-log2csv -- an LCM log file (as written by lcm-logger) to CSV, one file
// per channel: DIR/<CHANNEL>.csv.
//
//   hoist-log2csv LOGFILE --out-dir DIR [--lenient]
//
// The log is read with hoist::io::LcmLogReader (not liblcm's reader): every
// event header is validated against the file before anything is allocated,
// and a corrupted event is skipped by resynchronising on the next sync word.
// Every payload is validated by hoist::msg::checkedDecode before decoding.
//
// Messages are recognized by their LCM type fingerprint (the first 8 bytes),
// not by channel name, so prefixed or renamed channels decode too.  Events of
// unknown types, and events that fail to decode, are counted and skipped; a
// note on stderr lists them.  A channel whose messages change type midway is
// written to DIR/<CHANNEL>.<type>.csv for the later type.
//
// Columns: those that hoist_msgs_codec generates from msgs/*.lcm
// (hoist::msg::csvHeader / csvRow; docs/codec.md): one per member in the
// .lcm file's order, a fixed array NAME_0.., no columns for variable-length
// arrays; doubles with 17 significant digits (round-trip exact), strings
// quoted, alarm levels and events by name.  Per type:
//   hoist.cage_state_t  t,l,v,a,x_c,y_c,theta,lambda_0..lambda_4 first (exactly
//                       as hoist-sim's output; `@csvfirst` in cage_state_t.lcm),
//                       then the other members in order
//   hoist.winder_t      the members, then log_utime (the log event's timestamp)
//   hoist.guide_shape_t t,x,y1,y2,l,utime (one row per depth sample, like
//                       hoist-sim --shape-out)
//   hoist.alarm_t       the members (event_type in a column "event")
//   hoist.alarm_ack_t, hoist.trip_plan_t  the members
//   hoist.estimate_t    the members (lambdas_0..4, sigma_lambdas_0..4; the
//                       booleans 0/1; a sigma < 0 means "not observed")
//   hoist.cage_imu_t, hoist.rope_load_t  the members
//   hoist.health_t      the members, then rejected_<reason> per reason
//   hoist.forecast_t    one row per scenario: the forecast's columns with
//                       num_scenarios replaced by the scenario's index
//                       "scenario", then the scenario's (name,status,...,
//                       peak_lambda_1..peak_lambda_4,lambda0_min,lambda0_max,
//                       num_points; times in s after t_start, -1 = none
//                       within the horizon).  The decimated series go to
//                       DIR/<CHANNEL>.series.csv, one row per point:
//                       utime,seq,scenario,name,i,t,min_clearance,
//                       lambda0_min,lambda0_max.
// Exit status: 0 on success; 1 if the log cannot be read, a file cannot be
// written to its last byte (the path and the errno text are printed), or --
// unless --lenient -- the log had corrupt regions (bytes skipped, events
// lost) or events that carry a hoist fingerprint but fail the checked decode;
// 2 for a bad command line.
#include "hoist/cli/app.hpp"
#include "hoist/version.hpp"
#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <cerrno>
#include <cstring>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_imu_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_scenario_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/rope_load_t.hpp"
#include "hoist/trip_plan_t.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/io/lcm_log.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/winder_t.hpp"

namespace {

using Event = hoist::io::LcmLogEvent;

/// One output file (hoist::io::CheckedFile: every write, the final fflush and
/// fclose checked).  The first failure is kept and the file dropped, so that
/// the other channels are still converted and the summary names every failure.
struct Writer {
  std::optional<hoist::io::CheckedFile> f;
  std::string path;
  std::string type;
  std::string channel;
  long rows = 0;
  std::string error;  ///< the first failure, with the path and errno text ("": none)
  void open() {
    try {
      f.emplace(path);
    } catch (const hoist::io::WriteError& e) {
      error = e.what();
    }
  }
  void write(const std::string& line) {
    if (!f) return;
    try {
      f->write(line);
      f->write("\n");
    } catch (const hoist::io::WriteError& e) {
      error = e.what();
      f.reset();
    }
  }
  /// Flush and close; false (error set) if any byte did not reach the file.
  bool close() {
    if (f) {
      try {
        f->close();
      } catch (const hoist::io::WriteError& e) {
        error = e.what();
      }
      f.reset();
    }
    return error.empty();
  }
};

class Converter {
 public:
  explicit Converter(std::filesystem::path dir) : dir_(std::move(dir)) {}

  /// Returns false if the event is of no known type or does not decode.
  bool handle(const Event& ev) {
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
  bool finish(std::ostream& os) {
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
  bool failed() const { return failed_; }
  long badCount() const {
    long n = 0;
    for (auto& [c, k] : bad_) n += k;
    return n;
  }
  long unknownCount() const {
    long n = 0;
    for (auto& [c, k] : unknown_) n += k;
    return n;
  }

 private:
  static std::string sanitize(const std::string& ch) {
    std::string s = ch;
    for (char& c : s)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) c = '_';
    return s.empty() ? std::string("_") : s;
  }
  static std::string fileName(const std::string& key) { return key + ".csv"; }
  static std::string hash8(const std::string& s) {  // FNV-1a, 32 bits
    std::uint32_t h = 2166136261u;
    for (unsigned char c : s) h = (h ^ c) * 16777619u;
    char buf[12];
    std::snprintf(buf, sizeof buf, "%08x", h);
    return buf;
  }

  /// The writer for (channel, type), created with `header` on first use
  /// (`suffix`: a second file of the channel, DIR/<CHANNEL><suffix>.csv).
  /// Two channels never share a file: names that sanitize alike
  /// ("a/HOIST_WINDER", "a_HOIST_WINDER") get distinct files (the later one
  /// DIR/<CHANNEL>.<hash of its name>.csv), and a note names both.
  Writer* writer(const std::string& channel, const char* type, const std::string& header,
                 const char* suffix = "") {
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

  template <class Msg>
  bool decode(const Event& ev, Msg& m) {
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
  bool table(const Event& ev, const char* type, Extra extra) {
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
  bool table(const Event& ev, const char* type) {
    return table<Msg>(ev, type, [](const Event&, const Msg&, std::string&, std::string&) {});
  }

  /// winder_t: then the log event's own timestamp.
  static void logUtime(const Event& ev, const hoist::winder_t&, std::string& head, std::string& row) {
    head += ",log_utime";
    row += ',';
    hoist::msg::csvInt(row, ev.timestamp);
  }
  /// health_t: then rejected_<reason> per reason (the pair of variable arrays
  /// reject_reason / rejected, as columns of their own).
  static void rejectedByReason(const Event&, const hoist::health_t& m, std::string& head, std::string& row) {
    for (const auto& r : m.reject_reason) head += ",rejected_" + r;
    for (auto v : m.rejected) {
      row += ',';
      hoist::msg::csvInt(row, v);
    }
  }

  /// One row per scenario: the forecast's columns with its count column
  /// (num_scenarios) replaced by the scenario's index, then the scenario's
  /// columns; the decimated series (variable arrays: no columns) one row per
  /// point in DIR/<CHANNEL>.series.csv.
  static constexpr std::string_view kScenarioCount = "num_scenarios";
  bool forecast(const Event& ev) {
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
  bool shape(const Event& ev) {
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

  std::filesystem::path dir_;
  struct Owner {
    std::string channel;
  };
  std::map<std::string, std::unique_ptr<Writer>> writers_;  // by channel, suffix and type
  std::map<std::string, Owner> files_;                      // file stem -> the channel written there
  std::vector<std::string> notes_;
  std::map<std::string, long> unknown_;
  std::map<std::pair<std::string, std::string>, long> bad_;  // (channel, status)
  bool failed_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "hoist-log2csv: convert an LCM log (lcm-logger) of the hoist channels to CSV,\n"
      "one file per channel (DIR/<CHANNEL>.csv).  Types are recognized by fingerprint;\n"
      "for HOIST_CAGE the first columns are t,l,v,a,x_c,y_c,theta,lambda_0..lambda_4\n"
      "(as hoist-sim writes them).  Corrupted events are skipped (resynchronising on\n"
      "the next event) and reported; the exit status is then 1 unless --lenient.\n"
      "Exit status: 0 ok, 1 unreadable log / unwritable file / data lost, 2 bad usage."};
  hoist::cli::nameProgram(app, "hoist-log2csv");
  std::string log_path, out_dir;
  bool lenient = false;
  // Required, but checked after parsing: CLI11 reports a missing LOGFILE
  // before an unknown option, and "--bogus-opt" must be named.
  app.add_option("LOGFILE", log_path, "LCM log file (required)")->check(CLI::ExistingFile);
  app.add_option("--out-dir", out_dir, "output directory (created if missing; required)");
  app.add_flag("--lenient", lenient,
               "exit 0 even when corrupt events were skipped or events failed to decode");
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  for (const auto& [given, what] : {std::pair{!log_path.empty(), "LOGFILE"}, std::pair{!out_dir.empty(), "--out-dir"}})
    if (!given) {
      std::cerr << "hoist-log2csv: " << what << " is required\nRun with --help for more information.\n";
      return 2;
    }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    std::cerr << "hoist-log2csv: cannot create " << out_dir << ": " << ec.message() << "\n";
    return 1;
  }
  hoist::io::LcmLogReader log(log_path);
  if (!log.ok()) {
    std::cerr << "hoist-log2csv: " << log.error() << "\n";
    return 1;
  }
  Converter conv(out_dir);
  hoist::io::LcmLogEvent ev;
  while (log.next(ev)) conv.handle(ev);
  const bool files_ok = conv.finish(std::cerr);
  if (!log.ok()) {
    std::cerr << "hoist-log2csv: error: " << log.error() << "\n";
    return 1;
  }
  std::cerr << "hoist-log2csv: " << log_path << ": " << log.summary() << "\n";
  if (!files_ok) return 1;
  const bool lost = log.stats().lost() || conv.badCount() > 0;
  if (lost) {
    std::cerr << "hoist-log2csv: " << (lenient ? "warning" : "error") << ": data lost ("
              << log.stats().bytes_skipped << " bytes skipped, about " << log.stats().events_lost
              << " event(s) lost, " << conv.badCount() << " undecodable)"
              << (lenient ? " -- ignored (--lenient)" : "; use --lenient to accept") << "\n";
    if (!lenient) return 1;
  }
  return 0;
}
