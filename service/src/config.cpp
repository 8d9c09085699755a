// Daemon configuration (plain structs, validation, TOML output): see
// hoist/service/config.hpp.  Reading TOML lives in config_file.cpp.
#include "hoist/service/config.hpp"

#include <cctype>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

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
  if (!lcm_url_out.empty() && lcm_url_out.find("://") == std::string::npos)
    bad("service.lcm_url_out", "must be an LCM URL such as \"udpm://239.255.76.67:7668?ttl=0\" (or \"\" for lcm_url), got \"" +
                                   lcm_url_out + "\"");
  for (char c : channel_prefix)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '/'))
      bad("service.channel_prefix", "may contain only letters, digits and _ - . /");
  if (channel_prefix.size() > 64) bad("service.channel_prefix", "at most 64 characters");
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

}  // namespace hoist::svc
