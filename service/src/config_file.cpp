// Reading the daemon's configuration from TOML: see hoist/service/config_file.hpp.
#include "hoist/service/config_file.hpp"

#include "hoist/io/estimator_config.hpp"

#include <charconv>
#include <cmath>
#include <functional>
#include <ostream>
#include <sstream>

#include "hoist/io/config.hpp"
#include "hoist/io/toml_section.hpp"

namespace hoist::svc {

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
  sr.number("envelope_tolerance", s.envelope_tolerance);
  sr.integer("log_rate_limit", s.log_rate_limit);
  sr.number("fault_hold", s.fault_hold);
  sr.string("lcm_url_out", [&](const toml::node&, const std::string& v) { s.lcm_url_out = v; });
  sr.number("accel_tolerance", s.accel_tolerance);
  sr.number("velocity_tolerance", s.velocity_tolerance);
  sr.number("consistency_window", s.consistency_window);
  sr.number("plausible_factor", s.plausible_factor);
  sr.integer("max_catchup_periods", s.max_catchup_periods);
  sr.integer("max_commands_per_tick", s.max_commands_per_tick);
  sr.integer("max_starts_per_tick", s.max_starts_per_tick);
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
  ar.number("slack_fraction", a.slack_fraction);
  ar.number("overload_fraction", a.overload_fraction);
  ar.number("force_deadband", a.force_deadband);
  ar.run();
  try {
    a.validate();
  } catch (const std::invalid_argument& e) {
    rethrowWithPosition(e, source, ar);
  }

  ForecastConfig& f = cfg.forecast;
  SectionReader fr(tbl, "forecast", source);
  fr.boolean("enabled", f.enabled);
  fr.number("rate", f.rate);
  fr.number("horizon", f.horizon);
  fr.number("estop_decel", f.estop_decel);
  fr.number("estop_jerk", f.estop_jerk);
  fr.number("vmax", f.vmax);
  fr.number("amax", f.amax);
  fr.number("jerk", f.jerk);
  fr.number("plan_timeout", f.plan_timeout);
  fr.integer("workers", f.workers);
  fr.integer("series_points", f.series_points);
  fr.boolean("exact", f.exact);
  fr.integer("modes", f.modes);
  fr.run();
  try {
    f.validate(s.rate);
  } catch (const std::invalid_argument& e) {
    rethrowWithPosition(e, source, fr);
  }
}

TwinConfig loadTwinConfig(const std::string& path) {
  const toml::table tbl = hoist::io::loadTomlFile(path);
  TwinConfig cfg;
  cfg.shaft = hoist::io::shaftParamsFromToml(tbl, path, hoist::io::daemonSections());
  parseServiceSections(tbl, path, cfg);
  const hoist::io::EstimatorConfig e = hoist::io::estimatorConfigFromToml(tbl, path);
  cfg.estimator.enabled = e.enabled;
  cfg.estimator.settings = e.settings;
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
     << "\nenvelope_points = " << s.envelope_points << "\nenvelope_tolerance = " << Num{s.envelope_tolerance} << "\nlog_rate_limit = " << s.log_rate_limit
     << "\nfault_hold = " << Num{s.fault_hold} << "\nlcm_url_out = \"" << s.lcm_url_out
     << "\"\naccel_tolerance = " << Num{s.accel_tolerance} << "\nvelocity_tolerance = " << Num{s.velocity_tolerance}
     << "\nconsistency_window = " << Num{s.consistency_window} << "\nplausible_factor = " << Num{s.plausible_factor}
     << "\nmax_catchup_periods = " << s.max_catchup_periods << "\nmax_commands_per_tick = " << s.max_commands_per_tick
     << "\nmax_starts_per_tick = " << s.max_starts_per_tick << "\n\n";
  const AlarmConfig& a = c.alarms;
  os << "[alarms]\ngap_pos_y = " << Num{a.gap_pos_y} << "\ngap_neg_y = " << Num{a.gap_neg_y}
     << "\nguide_rope_gap = " << Num{a.guide_rope_gap} << "\nwarning_fraction = " << Num{a.warning_fraction}
     << "\ncritical_fraction = " << Num{a.critical_fraction} << "\ndeadband = " << Num{a.deadband}
     << "\non_delay = " << Num{a.on_delay} << "\noff_delay = " << Num{a.off_delay}
     << "\nreannounce = " << Num{a.reannounce} << "\nlatch_critical = "
     << (a.latch_critical ? "true" : "false") << "\nmax_shelve = " << Num{a.max_shelve}
     << "\nslack_fraction = " << Num{a.slack_fraction} << "\noverload_fraction = " << Num{a.overload_fraction}
     << "\nforce_deadband = " << Num{a.force_deadband} << "\n";
  const ForecastConfig& f = c.forecast;
  os << "\n[forecast]\nenabled = " << (f.enabled ? "true" : "false") << "\nrate = " << Num{f.rate}
     << "\nhorizon = " << Num{f.horizon} << "\nestop_decel = " << Num{f.estop_decel}
     << "\nestop_jerk = " << Num{f.estop_jerk} << "\nvmax = " << Num{f.vmax} << "\namax = " << Num{f.amax}
     << "\njerk = " << Num{f.jerk} << "\nplan_timeout = " << Num{f.plan_timeout}
     << "\nworkers = " << f.workers << "\nseries_points = " << f.series_points
     << "\nexact = " << (f.exact ? "true" : "false") << "\nmodes = " << f.modes << "\n";
  os << "\n" << hoist::io::toToml(hoist::io::EstimatorConfig{c.estimator.enabled, c.estimator.settings});
  return os.str();
}

}  // namespace hoist::svc
