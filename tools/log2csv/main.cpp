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
// Columns (doubles printed with 17 significant digits, round-trip exact):
//   hoist.cage_state_t  t,l,v,a,x_c,y_c,theta,lambda_0..lambda_4 (exactly as
//                       hoist-sim's output), then utime,seq,input_seq,y_top,
//                       y_bottom,guide_deflection,clearance_pos_y,
//                       clearance_neg_y,clearance_guide,min_clearance,
//                       alarm_level,degraded,rope_slack_threshold,
//                       rope_overload_threshold (the last two: issue 17, appended)
//   hoist.winder_t      utime,seq,v,a,has_length,length,log_utime
//   hoist.guide_shape_t t,x,y1,y2,l,utime (one row per depth sample, like
//                       hoist-sim --shape-out)
//   hoist.alarm_t       utime,id,t,kind,level,event,active,acked,shelved,latched,
//                       value,threshold,shelved_for,message
//   hoist.alarm_ack_t   utime,kind,level,action,shelve_duration,user
//   hoist.health_t      utime,uptime,t,clock,rate,window,ticks,steps,deadline_misses,
//                       step_p50_us,...,degraded, then rejected_<reason> per reason
//   hoist.forecast_t    one row per scenario: utime,seq,instance_id,t_start,l,v,a,
//                       plan_seq,compute_time,scenario,name,status,horizon,t_reached,
//                       min_clearance,t_min_clearance,t_warning,t_critical,peak_y_c,
//                       peak_theta,peak_lambda_1..peak_lambda_4,lambda0_min,
//                       lambda0_max,num_points (times of a scenario in s after
//                       t_start, -1 = none within the horizon).  The decimated
//                       series go to DIR/<CHANNEL>.series.csv, one row per
//                       point: utime,seq,scenario,name,i,t,min_clearance,
//                       lambda0_min,lambda0_max.
//   hoist.trip_plan_t   utime,seq,target_length,vmax,amax,jerk
// Exit status: 0 on success; 1 if the log cannot be read, a file cannot be
// written to its last byte (the path and the errno text are printed), or --
// unless --lenient -- the log had corrupt regions (bytes skipped, events
// lost) or events that carry a hoist fingerprint but fail the checked decode;
// 2 for a bad command line.
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
#include <sstream>
#include <string>
#include <vector>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/trip_plan_t.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/io/lcm_log.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/winder_t.hpp"

namespace {

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// CSV field quoting (RFC 4180) for free text.
std::string csvQuote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += "\"\"";
    else if (c == '\n' || c == '\r') out += ' ';
    else out += c;
  }
  return out + "\"";
}

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
    if (name == "hoist.cage_state_t") return cage(ev);
    if (name == "hoist.winder_t") return winder(ev);
    if (name == "hoist.guide_shape_t") return shape(ev);
    if (name == "hoist.alarm_t") return alarm(ev);
    if (name == "hoist.alarm_ack_t") return ack(ev);
    if (name == "hoist.health_t") return health(ev);
    if (name == "hoist.forecast_t") return forecast(ev);
    if (name == "hoist.trip_plan_t") return plan(ev);
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

  bool cage(const Event& ev) {
    hoist::cage_state_t m{};
    if (!decode(ev, m)) return false;
    Writer* w = writer(ev.channel, "cage_state_t",
                       "t,l,v,a,x_c,y_c,theta,lambda_0,lambda_1,lambda_2,lambda_3,lambda_4,utime,seq,"
                       "input_seq,y_top,y_bottom,guide_deflection,clearance_pos_y,clearance_neg_y,"
                       "clearance_guide,min_clearance,alarm_level,degraded,rope_slack_threshold,"
                       "rope_overload_threshold");
    std::ostringstream os;
    os << num(m.t) << ',' << num(m.l) << ',' << num(m.v) << ',' << num(m.a) << ',' << num(m.x_c)
       << ',' << num(m.y_c) << ',' << num(m.theta);
    for (double v : m.lambdas) os << ',' << num(v);
    os << ',' << m.utime << ',' << m.seq << ',' << m.input_seq << ',' << num(m.y_top) << ','
       << num(m.y_bottom) << ',' << num(m.guide_deflection) << ',' << num(m.clearance_pos_y) << ','
       << num(m.clearance_neg_y) << ',' << num(m.clearance_guide) << ',' << num(m.min_clearance)
       << ',' << int(m.alarm_level) << ',' << int(m.degraded) << ',' << num(m.rope_slack_threshold) << ','
       << num(m.rope_overload_threshold);
    w->write(os.str());
    return true;
  }

  bool forecast(const Event& ev) {
    hoist::forecast_t m{};
    if (!decode(ev, m)) return false;
    if (m.scenarios.empty()) return true;  // nothing to tabulate (counted as a message, no row)
    Writer* w = writer(ev.channel, "forecast_t",
                       "utime,seq,instance_id,t_start,l,v,a,plan_seq,compute_time,scenario,name,status,horizon,"
                       "t_reached,min_clearance,t_min_clearance,t_warning,t_critical,peak_y_c,peak_theta,"
                       "peak_lambda_1,peak_lambda_2,peak_lambda_3,peak_lambda_4,lambda0_min,lambda0_max,"
                       "num_points");
    --w->rows;  // rows counted per scenario below
    bool any_points = false;
    for (std::size_t i = 0; i < m.scenarios.size(); ++i) {
      const auto& sc = m.scenarios[i];
      std::ostringstream os;
      os << m.utime << ',' << m.seq << ',' << m.instance_id << ',' << num(m.t_start) << ',' << num(m.l) << ','
         << num(m.v) << ',' << num(m.a) << ',' << m.plan_seq << ',' << num(m.compute_time) << ',' << i << ','
         << csvQuote(sc.name) << ',' << int(sc.status) << ',' << num(sc.horizon) << ',' << num(sc.t_reached)
         << ',' << num(sc.min_clearance) << ',' << num(sc.t_min_clearance) << ',' << num(sc.t_warning) << ','
         << num(sc.t_critical) << ',' << num(sc.peak_y_c) << ',' << num(sc.peak_theta);
      for (double v : sc.peak_lambdas) os << ',' << num(v);
      os << ',' << num(sc.lambda0_min) << ',' << num(sc.lambda0_max) << ',' << sc.num_points;
      w->write(os.str());
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
        std::ostringstream os;
        os << m.utime << ',' << m.seq << ',' << i << ',' << csvQuote(sc.name) << ',' << k << ','
           << num(sc.series_t[k]) << ',' << num(sc.series_min_clearance[k]) << ','
           << num(sc.series_lambda0_min[k]) << ',' << num(sc.series_lambda0_max[k]);
        s->write(os.str());
        ++s->rows;
      }
    }
    return true;
  }

  bool plan(const Event& ev) {
    hoist::trip_plan_t m{};
    if (!decode(ev, m)) return false;
    Writer* w = writer(ev.channel, "trip_plan_t", "utime,seq,target_length,vmax,amax,jerk");
    std::ostringstream os;
    os << m.utime << ',' << m.seq << ',' << num(m.target_length) << ',' << num(m.vmax) << ',' << num(m.amax)
       << ',' << num(m.jerk);
    w->write(os.str());
    return true;
  }

  bool winder(const Event& ev) {
    hoist::winder_t m{};
    if (!decode(ev, m)) return false;
    Writer* w = writer(ev.channel, "winder_t", "utime,seq,v,a,has_length,length,log_utime");
    {
      std::ostringstream os;
      os << m.utime << ',' << m.seq << ',' << num(m.v) << ',' << num(m.a) << ',' << int(m.has_length)
           << ',' << num(m.length) << ',' << ev.timestamp;
      w->write(os.str());
    }
    return true;
  }

  bool shape(const Event& ev) {
    hoist::guide_shape_t m{};
    if (!decode(ev, m)) return false;
    Writer* w = writer(ev.channel, "guide_shape_t", "t,x,y1,y2,l,utime");
    for (int i = 0; i < m.n; ++i)
      {
      std::ostringstream os;
      os << num(m.t) << ',' << num(m.x[i]) << ',' << num(m.y1[i]) << ',' << num(m.y2[i]) << ','
             << num(m.l) << ',' << m.utime;
      w->write(os.str());
    }
    return true;
  }

  bool alarm(const Event& ev) {
    hoist::alarm_t m{};
    if (!decode(ev, m)) return false;
    Writer* w = writer(ev.channel, "alarm_t",
                       "utime,id,t,kind,level,event,active,acked,shelved,latched,value,threshold,"
                       "shelved_for,message");
    static const char* levels[] = {"NONE", "WARNING", "CRITICAL"};
    static const char* events[] = {"?", "RAISE", "CLEAR", "ACK", "SHELVE", "UNSHELVE", "REANNOUNCE"};
    const char* lvl = (m.level >= 0 && m.level <= 2) ? levels[m.level] : "?";
    const char* evn = (m.event_type >= 1 && m.event_type <= 6) ? events[m.event_type] : "?";
    {
      std::ostringstream os;
      os << m.utime << ',' << m.id << ',' << num(m.t) << ',' << csvQuote(m.kind) << ',' << lvl << ','
           << evn << ',' << int(m.active) << ',' << int(m.acked) << ',' << int(m.shelved) << ','
           << int(m.latched) << ',' << num(m.value) << ',' << num(m.threshold) << ','
           << num(m.shelved_for) << ',' << csvQuote(m.message);
      w->write(os.str());
    }
    return true;
  }

  bool ack(const Event& ev) {
    hoist::alarm_ack_t m{};
    if (!decode(ev, m)) return false;
    Writer* w = writer(ev.channel, "alarm_ack_t", "utime,kind,level,action,shelve_duration,user");
    {
      std::ostringstream os;
      os << m.utime << ',' << csvQuote(m.kind) << ',' << int(m.level) << ',' << int(m.action) << ','
           << num(m.shelve_duration) << ',' << csvQuote(m.user);
      w->write(os.str());
    }
    return true;
  }

  bool health(const Event& ev) {
    hoist::health_t m{};
    if (!decode(ev, m)) return false;
    std::string header =
        "utime,uptime,t,clock,rate,window,ticks,steps,deadline_misses,step_p50_us,step_p99_us,"
        "step_max_us,late_p50_us,late_p99_us,late_max_us,input_age,accepted,seq_gaps,rejected_total,"
        "alarms_active,alarms_unacked,alarms_shelved,alarm_events,model_faults,model_resets,"
        "publish_failures,nonfinite_blocked,degraded";
    for (const auto& r : m.reject_reason) header += ",rejected_" + r;
    Writer* w = writer(ev.channel, "health_t", header);
    std::ostringstream os;
    os << m.utime << ',' << num(m.uptime) << ',' << num(m.t) << ',' << m.clock << ',' << num(m.rate)
       << ',' << num(m.window) << ',' << m.ticks << ',' << m.steps << ',' << m.deadline_misses << ','
       << num(m.step_p50_us) << ',' << num(m.step_p99_us) << ',' << num(m.step_max_us) << ','
       << num(m.late_p50_us) << ',' << num(m.late_p99_us) << ',' << num(m.late_max_us) << ','
       << num(m.input_age) << ',' << m.accepted << ',' << m.seq_gaps << ',' << m.rejected_total << ','
       << m.alarms_active << ',' << m.alarms_unacked << ',' << m.alarms_shelved << ','
       << m.alarm_events << ',' << m.model_faults << ',' << m.model_resets << ','
       << m.publish_failures << ',' << m.nonfinite_blocked << ',' << int(m.degraded);
    for (auto v : m.rejected) os << ',' << v;
    w->write(os.str());
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
  app.name("hoist-log2csv");  // usage lines name the program, not the path it was run by
  app.failure_message([](const CLI::App* a, const CLI::Error& e) { return a->get_name() + ": " + CLI::FailureMessage::simple(a, e); });  // errors name the program
  app.set_version_flag("--version", std::string("hoist-log2csv ") + hoist::kVersionString);
  std::string log_path, out_dir;
  bool lenient = false;
  // Required, but checked after parsing: CLI11 reports a missing LOGFILE
  // before an unknown option, and "--bogus-opt" must be named.
  app.add_option("LOGFILE", log_path, "LCM log file (required)")->check(CLI::ExistingFile);
  app.add_option("--out-dir", out_dir, "output directory (created if missing; required)");
  app.add_flag("--lenient", lenient,
               "exit 0 even when corrupt events were skipped or events failed to decode");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
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
