// Daemon configuration: see hoist/service/config.hpp.
#include "hoist/service/config.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>

#include "hoist/io/config.hpp"

namespace hoist::svc {

const char* toString(ClockMode c) { return c == ClockMode::Wall ? "wall" : "input"; }

namespace {
std::string configMessage(const std::string& source, int line, const std::string& key,
                          const std::string& msg) {
  std::string s = source;
  if (line > 0) {
    s += ':';
    s += std::to_string(line);
  }
  s += ": ";
  s += key;
  s += ": ";
  s += msg;
  return s;
}
}  // namespace

ConfigError::ConfigError(const std::string& source, int line, const std::string& key,
                         const std::string& msg)
    : std::runtime_error(configMessage(source, line, key, msg)), key_(key) {}

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
  checkRange("accel_tolerance", accel_tolerance, 0.0, 100.0, true);
  checkRange("velocity_tolerance", velocity_tolerance, 0.0, 10.0);
  checkRange("consistency_window", consistency_window, 0.0, 60.0, true);
  checkRange("plausible_factor", plausible_factor, 2.0, 1e6);
  checkRange("max_catchup_periods", max_catchup_periods, 1, 1000);
  checkRange("max_commands_per_tick", max_commands_per_tick, 1, 1000);
  if (max_step > 0.0) {
    // Never clamp in silence: the longest interval one step may have to
    // cover (a tick's catch-up, or an input interval with --clock input)
    // must fit kMaxSubsteps substeps.
    const double longest = std::max(max_catchup_periods / rate, max_time_step);
    const double need = std::ceil(longest / max_step - 1e-9);
    if (need > kMaxSubsteps) {
      std::ostringstream os;
      os << max_step << " s would need " << need << " substeps for an interval of " << longest
         << " s (max_time_step or max_catchup_periods / rate); the limit is " << kMaxSubsteps
         << ": use max_step >= " << longest / kMaxSubsteps << " s or 0 (no substeps)";
      bad("service.max_step", os.str());
    }
  }
  for (char c : channel_prefix)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '/'))
      bad("service.channel_prefix", "may contain only letters, digits and _ - . /");
  if (channel_prefix.size() > 64) bad("service.channel_prefix", "at most 64 characters");
}

namespace {

int lineOf(const toml::node& n) { return static_cast<int>(n.source().begin.line); }

/// Reads one section with a fixed set of keys; unknown keys are errors.
class SectionReader {
 public:
  SectionReader(const toml::table& root, const char* section, const std::string& source)
      : section_(section), source_(source) {
    const toml::node* n = root.get(section);
    if (!n) return;
    tbl_ = n->as_table();
    if (!tbl_) throw ConfigError(source, lineOf(*n), section, "must be a table ([" + std::string(section) + "])");
  }

  void number(const char* key, double& out) {
    handlers_[key] = [this, key, &out](const toml::node& n) {
      if (auto i = n.as_integer()) out = static_cast<double>(i->get());
      else if (auto f = n.as_floating_point()) out = f->get();
      else fail(n, key, "must be a number");
      if (!std::isfinite(out)) fail(n, key, "must be finite");
    };
  }
  void integer(const char* key, int& out) {
    handlers_[key] = [this, key, &out](const toml::node& n) {
      auto i = n.as_integer();
      if (!i) fail(n, key, "must be an integer");
      if (i->get() < -1000000000 || i->get() > 1000000000) fail(n, key, "out of range");
      out = static_cast<int>(i->get());
    };
  }
  void boolean(const char* key, bool& out) {
    handlers_[key] = [this, key, &out](const toml::node& n) {
      auto b = n.as_boolean();
      if (!b) fail(n, key, "must be true or false");
      out = b->get();
    };
  }
  void string(const char* key, std::function<void(const toml::node&, const std::string&)> set) {
    handlers_[key] = [this, key, set](const toml::node& n) {
      auto s = n.as_string();
      if (!s) fail(n, key, "must be a string");
      set(n, s->get());
    };
  }

  /// Apply all handlers; returns the line of the section (for validate errors).
  void run() {
    if (!tbl_) return;
    for (auto&& [k, node] : *tbl_) {
      auto it = handlers_.find(std::string(k.str()));
      if (it == handlers_.end()) {
        std::string known;
        for (auto& h : handlers_) known += (known.empty() ? "" : ", ") + h.first;
        fail(node, std::string(k.str()), "unknown key (known: " + known + ")");
      }
      it->second(node);
      lines_[it->first] = lineOf(node);
    }
  }
  int lineOfKey(const std::string& key) const {
    auto it = lines_.find(key);
    if (it != lines_.end()) return it->second;
    return tbl_ ? lineOf(*tbl_) : 0;
  }
  [[noreturn]] void fail(const toml::node& n, const std::string& key, const std::string& why) const {
    throw ConfigError(source_, lineOf(n), std::string(section_) + "." + key, why);
  }

 private:
  const char* section_;
  std::string source_;
  const toml::table* tbl_ = nullptr;
  std::map<std::string, std::function<void(const toml::node&)>> handlers_;
  std::map<std::string, int> lines_;
};

/// Rethrow a validate() error ("section.key: why") with the file and line.
[[noreturn]] void rethrowWithPosition(const std::invalid_argument& e, const std::string& source,
                                      const SectionReader& r, const std::string& section) {
  std::string what = e.what();
  const auto colon = what.find(": ");
  std::string key = colon == std::string::npos ? section : what.substr(0, colon);
  std::string why = colon == std::string::npos ? what : what.substr(colon + 2);
  const auto dot = key.find('.');
  const int line = r.lineOfKey(dot == std::string::npos ? key : key.substr(dot + 1));
  throw ConfigError(source, line, key, why);
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
  sr.string("lcm_url_out", [&](const toml::node& n, const std::string& v) {
    if (!v.empty() && v.find("://") == std::string::npos)
      sr.fail(n, "lcm_url_out", "must be an LCM URL such as \"udpm://239.255.76.67:7668?ttl=0\" (or \"\" for lcm_url), got \"" + v + "\"");
    s.lcm_url_out = v;
  });
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
  sr.number("accel_tolerance", s.accel_tolerance);
  sr.number("velocity_tolerance", s.velocity_tolerance);
  sr.number("consistency_window", s.consistency_window);
  sr.number("plausible_factor", s.plausible_factor);
  sr.integer("max_catchup_periods", s.max_catchup_periods);
  sr.integer("max_commands_per_tick", s.max_commands_per_tick);
  sr.run();
  try {
    s.validate();
  } catch (const std::invalid_argument& e) {
    rethrowWithPosition(e, source, sr, "service");
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
    rethrowWithPosition(e, source, ar, "alarms");
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
  const ShaftParams& p = c.shaft;
  os << "# hoist-twind effective configuration\n"
     << "[hoisting_rope]\nmass_per_length = " << Num{p.rho1} << "\naxial_stiffness = " << Num{p.EA}
     << "\ndamping = " << Num{p.u1} << "\ninitial_length = " << Num{p.l0} << "\n\n"
     << "[guide_ropes]\nlength = " << Num{p.L} << "\nmass_per_length = " << Num{p.rho2}
     << "\ndamping = " << Num{p.u2} << "\npreload = [" << Num{p.Tb1} << ", " << Num{p.Tb2} << "]\n\n"
     << "[cage]\nmass = " << Num{p.m} << "\ninertia = " << Num{p.J} << "\nhalf_height = " << Num{p.h} << "\n\n"
     << "[load]\neccentric_force = " << Num{p.Fa} << "\noffset = " << Num{p.b} << "\n\n"
     << "[model]\nmodes = " << p.n << "\ngravity = " << Num{p.g} << "\ninitial = \""
     << toString(p.initial) << "\"\nrho_inf = " << Num{p.rho_inf} << "\n\n";
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
     << "\nfault_hold = " << Num{s.fault_hold} << "\nlcm_url_out = \"" << s.lcm_url_out
     << "\"\naccel_tolerance = " << Num{s.accel_tolerance} << "\nvelocity_tolerance = " << Num{s.velocity_tolerance}
     << "\nconsistency_window = " << Num{s.consistency_window} << "\nplausible_factor = " << Num{s.plausible_factor}
     << "\nmax_catchup_periods = " << s.max_catchup_periods << "\nmax_commands_per_tick = " << s.max_commands_per_tick
     << "\n\n";
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
