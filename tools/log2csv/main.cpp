// hoist-log2csv -- an LCM log file (as written by lcm-logger) to CSV, one file
// per channel: DIR/<CHANNEL>.csv.
//
//   hoist-log2csv LOGFILE --out-dir DIR
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
//                       alarm_level,degraded
//   hoist.winder_t      utime,seq,v,a,has_length,length,log_utime
//   hoist.guide_shape_t t,x,y1,y2,l,utime (one row per depth sample, like
//                       hoist-sim --shape-out)
//   hoist.alarm_t       utime,id,t,kind,level,event,active,acked,shelved,latched,
//                       value,threshold,shelved_for,message
//   hoist.alarm_ack_t   utime,kind,level,action,shelve_duration,user
//   hoist.health_t      utime,uptime,t,clock,rate,window,ticks,steps,deadline_misses,
//                       step_p50_us,...,degraded, then rejected_<reason> per reason
// Exit status: 0 on success, 1 if the log cannot be read or a file cannot be
// written, 2 for a bad command line.
#include "hoist/version.hpp"
#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/health_t.hpp"
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

std::int64_t fingerprintOf(const void* data, std::size_t size) {
  if (size < 8) return 0;
  const auto* b = static_cast<const std::uint8_t*>(data);
  std::uint64_t h = 0;
  for (int i = 0; i < 8; ++i) h = (h << 8) | b[i];
  return static_cast<std::int64_t>(h);
}

struct Writer {
  std::ofstream out;
  std::string type;
  long rows = 0;
};

class Converter {
 public:
  explicit Converter(std::filesystem::path dir) : dir_(std::move(dir)) {}

  /// Returns false if the event is of no known type or does not decode.
  bool handle(const lcm::LogEvent& ev) {
    const std::int64_t fp = fingerprintOf(ev.data, static_cast<std::size_t>(ev.datalen));
    const int len = ev.datalen;
    if (fp == hoist::cage_state_t::getHash()) return cage(ev, len);
    if (fp == hoist::winder_t::getHash()) return winder(ev, len);
    if (fp == hoist::guide_shape_t::getHash()) return shape(ev, len);
    if (fp == hoist::alarm_t::getHash()) return alarm(ev, len);
    if (fp == hoist::alarm_ack_t::getHash()) return ack(ev, len);
    if (fp == hoist::health_t::getHash()) return health(ev, len);
    ++unknown_[ev.channel];
    return false;
  }

  void report(std::ostream& os) const {
    for (const auto& [key, w] : writers_)
      os << "hoist-log2csv: " << w->rows << " rows of hoist." << w->type << " -> "
         << (dir_ / fileName(key)).string() << "\n";
    for (const auto& [ch, n] : unknown_)
      os << "hoist-log2csv: note: skipped " << n << " event(s) of an unknown type on channel " << ch << "\n";
    for (const auto& [ch, n] : bad_)
      os << "hoist-log2csv: note: skipped " << n << " event(s) on channel " << ch
         << " that carry a hoist fingerprint but do not decode (truncated?)\n";
  }
  bool failed() const { return failed_; }
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

  /// The writer for (channel, type), created with `header` on first use.
  Writer* writer(const std::string& channel, const char* type, const std::string& header) {
    std::string key = sanitize(channel);
    auto it = writers_.find(key);
    if (it != writers_.end() && it->second->type != type) {
      key += std::string(".") + type;
      it = writers_.find(key);
    }
    if (it == writers_.end()) {
      auto w = std::make_unique<Writer>();
      w->type = type;
      const auto path = dir_ / fileName(key);
      w->out.open(path);
      if (!w->out) {
        std::cerr << "hoist-log2csv: cannot write " << path.string() << "\n";
        failed_ = true;
      }
      w->out << header << "\n";
      it = writers_.emplace(key, std::move(w)).first;
    }
    ++it->second->rows;
    return it->second.get();
  }

  template <class Msg>
  bool decode(const lcm::LogEvent& ev, int len, Msg& m) {
    if (m.decode(ev.data, 0, len) != len) {
      ++bad_[ev.channel];
      return false;
    }
    return true;
  }

  bool cage(const lcm::LogEvent& ev, int len) {
    hoist::cage_state_t m{};
    if (!decode(ev, len, m)) return false;
    Writer* w = writer(ev.channel, "cage_state_t",
                       "t,l,v,a,x_c,y_c,theta,lambda_0,lambda_1,lambda_2,lambda_3,lambda_4,utime,seq,"
                       "input_seq,y_top,y_bottom,guide_deflection,clearance_pos_y,clearance_neg_y,"
                       "clearance_guide,min_clearance,alarm_level,degraded");
    std::ostringstream os;
    os << num(m.t) << ',' << num(m.l) << ',' << num(m.v) << ',' << num(m.a) << ',' << num(m.x_c)
       << ',' << num(m.y_c) << ',' << num(m.theta);
    for (double v : m.lambdas) os << ',' << num(v);
    os << ',' << m.utime << ',' << m.seq << ',' << m.input_seq << ',' << num(m.y_top) << ','
       << num(m.y_bottom) << ',' << num(m.guide_deflection) << ',' << num(m.clearance_pos_y) << ','
       << num(m.clearance_neg_y) << ',' << num(m.clearance_guide) << ',' << num(m.min_clearance)
       << ',' << int(m.alarm_level) << ',' << int(m.degraded);
    w->out << os.str() << '\n';
    return true;
  }

  bool winder(const lcm::LogEvent& ev, int len) {
    hoist::winder_t m{};
    if (!decode(ev, len, m)) return false;
    Writer* w = writer(ev.channel, "winder_t", "utime,seq,v,a,has_length,length,log_utime");
    w->out << m.utime << ',' << m.seq << ',' << num(m.v) << ',' << num(m.a) << ',' << int(m.has_length)
           << ',' << num(m.length) << ',' << ev.timestamp << '\n';
    return true;
  }

  bool shape(const lcm::LogEvent& ev, int len) {
    hoist::guide_shape_t m{};
    if (!decode(ev, len, m)) return false;
    Writer* w = writer(ev.channel, "guide_shape_t", "t,x,y1,y2,l,utime");
    for (int i = 0; i < m.n; ++i)
      w->out << num(m.t) << ',' << num(m.x[i]) << ',' << num(m.y1[i]) << ',' << num(m.y2[i]) << ','
             << num(m.l) << ',' << m.utime << '\n';
    return true;
  }

  bool alarm(const lcm::LogEvent& ev, int len) {
    hoist::alarm_t m{};
    if (!decode(ev, len, m)) return false;
    Writer* w = writer(ev.channel, "alarm_t",
                       "utime,id,t,kind,level,event,active,acked,shelved,latched,value,threshold,"
                       "shelved_for,message");
    static const char* levels[] = {"NONE", "WARNING", "CRITICAL"};
    static const char* events[] = {"?", "RAISE", "CLEAR", "ACK", "SHELVE", "UNSHELVE", "REANNOUNCE"};
    const char* lvl = (m.level >= 0 && m.level <= 2) ? levels[m.level] : "?";
    const char* evn = (m.event_type >= 1 && m.event_type <= 6) ? events[m.event_type] : "?";
    w->out << m.utime << ',' << m.id << ',' << num(m.t) << ',' << csvQuote(m.kind) << ',' << lvl << ','
           << evn << ',' << int(m.active) << ',' << int(m.acked) << ',' << int(m.shelved) << ','
           << int(m.latched) << ',' << num(m.value) << ',' << num(m.threshold) << ','
           << num(m.shelved_for) << ',' << csvQuote(m.message) << '\n';
    return true;
  }

  bool ack(const lcm::LogEvent& ev, int len) {
    hoist::alarm_ack_t m{};
    if (!decode(ev, len, m)) return false;
    Writer* w = writer(ev.channel, "alarm_ack_t", "utime,kind,level,action,shelve_duration,user");
    w->out << m.utime << ',' << csvQuote(m.kind) << ',' << int(m.level) << ',' << int(m.action) << ','
           << num(m.shelve_duration) << ',' << csvQuote(m.user) << '\n';
    return true;
  }

  bool health(const lcm::LogEvent& ev, int len) {
    hoist::health_t m{};
    if (!decode(ev, len, m)) return false;
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
    w->out << os.str() << '\n';
    return true;
  }

  std::filesystem::path dir_;
  std::map<std::string, std::unique_ptr<Writer>> writers_;
  std::map<std::string, long> unknown_, bad_;
  bool failed_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "hoist-log2csv: convert an LCM log (lcm-logger) of the hoist channels to CSV,\n"
      "one file per channel (DIR/<CHANNEL>.csv).  Types are recognized by fingerprint;\n"
      "for HOIST_CAGE the first columns are t,l,v,a,x_c,y_c,theta,lambda_0..lambda_4\n"
      "(as hoist-sim writes them)."};
  app.name("hoist-log2csv");  // usage lines name the program, not the path it was run by
  app.set_version_flag("--version", std::string("hoist-log2csv ") + hoist::kVersionString);
  std::string log_path, out_dir;
  app.add_option("LOGFILE", log_path, "LCM log file")->required()->check(CLI::ExistingFile);
  app.add_option("--out-dir", out_dir, "output directory (created if missing)")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    std::cerr << "hoist-log2csv: cannot create " << out_dir << ": " << ec.message() << "\n";
    return 1;
  }
  lcm::LogFile log(log_path, "r");
  if (!log.good()) {
    std::cerr << "hoist-log2csv: cannot open " << log_path << " as an LCM log\n";
    return 1;
  }
  Converter conv(out_dir);
  long events = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    ++events;
    conv.handle(*ev);
  }
  std::cerr << "hoist-log2csv: " << events << " events read from " << log_path << "\n";
  conv.report(std::cerr);
  return conv.failed() ? 1 : 0;
}
