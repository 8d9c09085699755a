// Daemon configuration: see hoist/service/config.hpp.
#include "hoist/service/config.hpp"

#include <charconv>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>

#include "hoist/io/config.hpp"
#include "hoist/io/toml_section.hpp"

namespace hoist::svc {

const char* toString(ClockMode c) { return c == ClockMode::Wall ? "wall" : "input"; }

namespace {

[[noreturn]] void bad(const std::string& key, const std::string& why) {
  // validate() has no file position: the loader rethrows with one.
  throw std::invalid_argument(key + ": " + why);
}

void checkRange(const char* key, double v, double lo, double hi, bool lo_open = false) {
  if (!std::isfinite(v) || v > hi || (lo_open ? !(v > lo) : v < lo)) {
    std::ostringstream os;
    os << "must be in " << (lo_open ? "(" : "[") << lo << ", " << hi << "], got " << v;
    bad(std::string("service.") + key, os.str());
  }
}

}  // namespace

void ServiceConfig::validate() const {
  checkRange("rate", rate, 1.0, 1000.0);
  checkRange("cage_rate", cage_rate, 0.0, rate);
  checkRange("shape_rate", shape_rate, 0.0, rate);
  checkRange("health_rate", health_rate, 0.0, 10.0, true);
  checkRange("max_speed", max_speed, 0.0, 1e3, true);
  checkRange("max_accel", max_accel, 0.0, 1e4, true);
  checkRange("max_length_jump", max_length_jump, 0.0, 1e4, true);
  checkRange("max_time_step", max_time_step, 0.0, 3600.0, true);
  checkRange("stale_timeout", stale_timeout, 0.0, 3600.0, true);
  checkRange("stale_periods", stale_periods, 0.0, 1000.0);
  checkRange("stale_min", stale_min, 0.0, 3600.0);
  checkRange("max_step", max_step, 0.0, 10.0);
  checkRange("shape_points", shape_points, 2, 2001);
  checkRange("envelope_points", envelope_points, 2, 20001);
  checkRange("log_rate_limit", log_rate_limit, 1, 1000);
  checkRange("fault_hold", fault_hold, 0.0, 3600.0);
  for (char c : channel_prefix)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '/'))
      bad("service.channel_prefix", "may contain only letters, digits and _ - . /");
}

namespace {

using hoist::io::SectionReader;

/// Rethrow a validate() error ("section.key: why") with the file and line.
[[noreturn]] void rethrowWithPosition(const std::invalid_argument& e, const std::string& source,
                                      const SectionReader& r) {
  hoist::io::rethrowWithLine(e.what(), source, {&r}, true);
}

}  // namespace

void parseServiceSections(const toml::table& tbl, const std::string& source, TwinConfig& cfg) {
  ServiceConfig& s = cfg.service;
  SectionReader sr(tbl, "service", source);
  sr.number("rate", s.rate);
  sr.number("cage_rate", s.cage_rate);
  sr.number("shape_rate", s.shape_rate);
  sr.number("health_rate", s.health_rate);
  sr.string("channel_prefix", [&](const toml::node&, const std::string& v) { s.channel_prefix = v; });
  sr.string("lcm_url", [&](const toml::node&, const std::string& v) { s.lcm_url = v; });
  sr.string("clock", [&](const toml::node& n, const std::string& v) {
    if (v == "wall") s.clock = ClockMode::Wall;
    else if (v == "input") s.clock = ClockMode::Input;
    else sr.fail(n, "clock", "must be \"wall\" or \"input\", got \"" + v + "\"");
  });
  sr.number("max_speed", s.max_speed);
  sr.number("max_accel", s.max_accel);
  sr.number("max_length_jump", s.max_length_jump);
  sr.number("max_time_step", s.max_time_step);
  sr.number("stale_timeout", s.stale_timeout);
  sr.number("stale_periods", s.stale_periods);
  sr.number("stale_min", s.stale_min);
  sr.number("max_step", s.max_step);
  sr.integer("shape_points", s.shape_points);
  sr.integer("envelope_points", s.envelope_points);
  sr.integer("log_rate_limit", s.log_rate_limit);
  sr.number("fault_hold", s.fault_hold);
  sr.run();
  try {
    s.validate();
  } catch (const std::invalid_argument& e) {
    rethrowWithPosition(e, source, sr);
  }

  AlarmConfig& a = cfg.alarms;
  SectionReader ar(tbl, "alarms", source);
  ar.number("gap_pos_y", a.gap_pos_y);
  ar.number("gap_neg_y", a.gap_neg_y);
  ar.number("guide_rope_gap", a.guide_rope_gap);
  ar.number("warning_fraction", a.warning_fraction);
  ar.number("critical_fraction", a.critical_fraction);
  ar.number("deadband", a.deadband);
  ar.number("on_delay", a.on_delay);
  ar.number("off_delay", a.off_delay);
  ar.number("reannounce", a.reannounce);
  ar.boolean("latch_critical", a.latch_critical);
  ar.number("max_shelve", a.max_shelve);
  ar.run();
  try {
    a.validate();
  } catch (const std::invalid_argument& e) {
    rethrowWithPosition(e, source, ar);
  }
}

TwinConfig loadTwinConfig(const std::string& path) {
  const toml::table tbl = hoist::io::loadTomlFile(path);
  TwinConfig cfg;
  cfg.shaft = hoist::io::shaftParamsFromToml(tbl, path, {"service", "alarms"});
  parseServiceSections(tbl, path, cfg);
  return cfg;
}

namespace {
/// A double as a TOML float: shortest round-trip form, always with '.' or 'e'.
struct Num {
  double v;
};
std::ostream& operator<<(std::ostream& os, Num n) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, n.v);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return os << s;
}
}  // namespace

std::string toToml(const TwinConfig& c) {
  std::ostringstream os;
  os << "# hoist-twind effective configuration\n" << hoist::io::toToml(c.shaft) << "\n";
  const ServiceConfig& s = c.service;
  os << "[service]\nrate = " << Num{s.rate} << "\ncage_rate = " << Num{s.cage_rate}
     << "\nshape_rate = " << Num{s.shape_rate} << "\nhealth_rate = " << Num{s.health_rate}
     << "\nchannel_prefix = \"" << s.channel_prefix << "\"\nlcm_url = \"" << s.lcm_url
     << "\"\nclock = \"" << toString(s.clock) << "\"\nmax_speed = " << Num{s.max_speed}
     << "\nmax_accel = " << Num{s.max_accel} << "\nmax_length_jump = " << Num{s.max_length_jump}
     << "\nmax_time_step = " << Num{s.max_time_step} << "\nstale_timeout = " << Num{s.stale_timeout}
     << "\nstale_periods = " << Num{s.stale_periods} << "\nstale_min = " << Num{s.stale_min}
     << "\nmax_step = " << Num{s.max_step} << "\nshape_points = " << s.shape_points
     << "\nenvelope_points = " << s.envelope_points << "\nlog_rate_limit = " << s.log_rate_limit
     << "\nfault_hold = " << Num{s.fault_hold} << "\n\n";
  const AlarmConfig& a = c.alarms;
  os << "[alarms]\ngap_pos_y = " << Num{a.gap_pos_y} << "\ngap_neg_y = " << Num{a.gap_neg_y}
     << "\nguide_rope_gap = " << Num{a.guide_rope_gap} << "\nwarning_fraction = " << Num{a.warning_fraction}
     << "\ncritical_fraction = " << Num{a.critical_fraction} << "\ndeadband = " << Num{a.deadband}
     << "\non_delay = " << Num{a.on_delay} << "\noff_delay = " << Num{a.off_delay}
     << "\nreannounce = " << Num{a.reannounce} << "\nlatch_critical = "
     << (a.latch_critical ? "true" : "false") << "\nmax_shelve = " << Num{a.max_shelve} << "\n";
  return os.str();
}

Channels::Channels(const std::string& prefix)
    : winder(prefix + "HOIST_WINDER"),
      cage(prefix + "HOIST_CAGE"),
      shape(prefix + "HOIST_GUIDE_SHAPE"),
      alarm(prefix + "HOIST_ALARM"),
      ack(prefix + "HOIST_ALARM_ACK"),
      health(prefix + "HOIST_HEALTH") {}

}  // namespace hoist::svc
