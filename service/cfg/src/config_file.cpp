// Reading the daemon's configuration from TOML: see hoist/service/cfg/config_file.hpp.
#include "hoist/service/cfg/config_file.hpp"

#include "hoist/io/estimator_config.hpp"
#include "hoist/history/condition_config.hpp"

#include <charconv>
#include <cmath>
#include <functional>
#include <ostream>
#include <sstream>

#include "hoist/io/config.hpp"
#include "hoist/io/toml_section.hpp"

namespace hoist::service::inline cfg {

namespace {

using hoist::io::SectionReader;

/// Rethrow a validate() error ("section.key: why") with the file and line.
[[noreturn]] void rethrowWithPosition(const std::invalid_argument& e, const std::string& source,
                                      const SectionReader& r) {
  hoist::io::rethrowWithLine(e.what(), source, {&r}, true);
}

/// One key of a [service], [alarms] or [forecast] section and the member it
/// sets: the one list of the keys, in file order, that both the reader
/// (parseServiceSections) and the writer (toToml) go through -- as
/// hoist::kParamFields is for the shaft's sections.  Exactly one member
/// pointer is set; a key with a value of its own syntax (the clock) has a
/// reader and writer of its own.
template <class S>
struct Key {
  const char* name;
  double S::*real = nullptr;
  int S::*integer = nullptr;
  bool S::*boolean = nullptr;
  std::string S::*text = nullptr;
  ClockMode S::*clock = nullptr;
};
template <class S>
constexpr Key<S> real(const char* n, double S::*m) { return {n, m, nullptr, nullptr, nullptr, nullptr}; }
template <class S>
constexpr Key<S> integer(const char* n, int S::*m) { return {n, nullptr, m, nullptr, nullptr, nullptr}; }
template <class S>
constexpr Key<S> boolean(const char* n, bool S::*m) { return {n, nullptr, nullptr, m, nullptr, nullptr}; }
template <class S>
constexpr Key<S> text(const char* n, std::string S::*m) { return {n, nullptr, nullptr, nullptr, m, nullptr}; }

using SC = ServiceConfig;
const Key<SC> kServiceKeys[] = {
    real("rate", &SC::rate),
    real("cage_rate", &SC::cage_rate),
    real("shape_rate", &SC::shape_rate),
    real("health_rate", &SC::health_rate),
    text("channel_prefix", &SC::channel_prefix),
    text("lcm_url", &SC::lcm_url),
    Key<SC>{"clock", nullptr, nullptr, nullptr, nullptr, &SC::clock},
    real("max_speed", &SC::max_speed),
    real("max_accel", &SC::max_accel),
    real("max_length_jump", &SC::max_length_jump),
    real("max_time_step", &SC::max_time_step),
    real("stale_timeout", &SC::stale_timeout),
    real("stale_periods", &SC::stale_periods),
    real("stale_min", &SC::stale_min),
    real("max_step", &SC::max_step),
    integer("shape_points", &SC::shape_points),
    integer("envelope_points", &SC::envelope_points),
    real("envelope_tolerance", &SC::envelope_tolerance),
    integer("log_rate_limit", &SC::log_rate_limit),
    real("fault_hold", &SC::fault_hold),
    text("lcm_url_out", &SC::lcm_url_out),
    real("accel_tolerance", &SC::accel_tolerance),
    real("velocity_tolerance", &SC::velocity_tolerance),
    real("consistency_window", &SC::consistency_window),
    real("plausible_factor", &SC::plausible_factor),
    integer("max_catchup_periods", &SC::max_catchup_periods),
    integer("max_commands_per_tick", &SC::max_commands_per_tick),
    integer("max_starts_per_tick", &SC::max_starts_per_tick),
    integer("max_exact_envelopes_per_tick", &SC::max_exact_envelopes_per_tick),
};

using AC = AlarmConfig;
const Key<AC> kAlarmKeys[] = {
    real("gap_pos_y", &AC::gap_pos_y),
    real("gap_neg_y", &AC::gap_neg_y),
    real("guide_rope_gap", &AC::guide_rope_gap),
    real("warning_fraction", &AC::warning_fraction),
    real("critical_fraction", &AC::critical_fraction),
    real("deadband", &AC::deadband),
    real("on_delay", &AC::on_delay),
    real("off_delay", &AC::off_delay),
    real("reannounce", &AC::reannounce),
    boolean("latch_critical", &AC::latch_critical),
    real("max_shelve", &AC::max_shelve),
    real("slack_fraction", &AC::slack_fraction),
    real("overload_fraction", &AC::overload_fraction),
    real("force_deadband", &AC::force_deadband),
};

using FC = ForecastConfig;
const Key<FC> kForecastKeys[] = {
    boolean("enabled", &FC::enabled),
    real("rate", &FC::rate),
    real("horizon", &FC::horizon),
    real("estop_decel", &FC::estop_decel),
    real("estop_jerk", &FC::estop_jerk),
    real("vmax", &FC::vmax),
    real("amax", &FC::amax),
    real("jerk", &FC::jerk),
    real("plan_timeout", &FC::plan_timeout),
    integer("workers", &FC::workers),
    integer("series_points", &FC::series_points),
    boolean("exact", &FC::exact),
    integer("modes", &FC::modes),
};

/// Registers every key of `keys` on `r`, setting the members of `out`.
template <class S, std::size_t N>
void readKeys(SectionReader& r, const Key<S> (&keys)[N], S& out) {
  for (const Key<S>& k : keys) {
    if (k.real) {
      r.number(k.name, out.*k.real);
    } else if (k.integer) {
      r.integer(k.name, out.*k.integer);
    } else if (k.boolean) {
      r.boolean(k.name, out.*k.boolean);
    } else if (k.text) {
      std::string S::*m = k.text;
      r.string(k.name, [&out, m](const toml::node&, const std::string& v) { out.*m = v; });
    } else if (k.clock) {
      ClockMode S::*m = k.clock;
      r.string(k.name, [&out, &r, m](const toml::node& n, const std::string& v) {
        if (v == "wall") out.*m = ClockMode::Wall;
        else if (v == "input") out.*m = ClockMode::Input;
        else r.fail(n, "clock", "must be \"wall\" or \"input\", got \"" + v + "\"");
      });
    }
  }
}

}  // namespace

void parseServiceSections(const toml::table& tbl, const std::string& source, TwinConfig& cfg) {
  ServiceConfig& s = cfg.service;
  SectionReader sr(tbl, "service", source);
  readKeys(sr, kServiceKeys, s);
  sr.run();
  try {
    s.validate();
  } catch (const std::invalid_argument& e) {
    rethrowWithPosition(e, source, sr);
  }

  AlarmConfig& a = cfg.alarms;
  SectionReader ar(tbl, "alarms", source);
  readKeys(ar, kAlarmKeys, a);
  ar.run();
  try {
    a.validate();
  } catch (const std::invalid_argument& e) {
    rethrowWithPosition(e, source, ar);
  }

  ForecastConfig& f = cfg.forecast;
  SectionReader fr(tbl, "forecast", source);
  readKeys(fr, kForecastKeys, f);
  fr.run();
  try {
    f.validate(s.rate);
  } catch (const std::invalid_argument& e) {
    rethrowWithPosition(e, source, fr);
  }
}

namespace {

/// The daemon's own keys of [sensors] and [estimator] (the estimator's
/// keys are hoist::io::kEstimatorFields): section, key, member.
struct DaemonSensorKey {
  const char* section;
  const char* key;
  double EstimatorConfig::*member;
};
constexpr DaemonSensorKey kDaemonSensorKeys[] = {
    {"sensors", "max_clock_offset", &EstimatorConfig::max_clock_offset},
    {"estimator", "clear_hold", &EstimatorConfig::clear_hold},
};

/// Read the daemon's own keys into `out` and remove them from `tbl` (the
/// estimator's reader then sees only its keys).  Errors name file:line:key.
void takeDaemonSensorKeys(toml::table& tbl, const std::string& source, EstimatorConfig& out) {
  for (const DaemonSensorKey& k : kDaemonSensorKeys) {
    toml::table* sec = tbl[k.section].as_table();
    if (!sec) continue;  // absent, or not a table (the estimator's reader says so)
    const toml::node* n = sec->get(k.key);
    if (!n) continue;
    const std::string dotted = std::string(k.section) + "." + k.key;
    if (const auto* i = n->as_integer()) out.*k.member = static_cast<double>(i->get());
    else if (const auto* f = n->as_floating_point()) out.*k.member = f->get();
    else
      throw hoist::io::ConfigError(source, hoist::io::lineOf(*n), dotted,
                                   std::string("must be a number, got ") + hoist::io::typeName(*n));
    const int line = hoist::io::lineOf(*n);
    sec->erase(k.key);
    try {
      out.validate();
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      if (what.rfind(dotted + ":", 0) == 0)
        throw hoist::io::ConfigError(source, line, dotted, what.substr(dotted.size() + 2));
      throw;
    }
  }
}

}  // namespace

TwinConfig loadTwinConfig(const std::string& path) {
  toml::table tbl = hoist::io::loadTomlFile(path);
  TwinConfig cfg;
  cfg.shaft = hoist::io::shaftParamsFromToml(tbl, path, hoist::history::configSections());  // [history], [condition]: history_config.hpp
  parseServiceSections(tbl, path, cfg);
  takeDaemonSensorKeys(tbl, path, cfg.estimator);
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

namespace {
/// "[name]\n" and one "key = value" line per key of `keys`, in table order.
template <class S, std::size_t N>
void writeKeys(std::ostream& os, const char* name, const Key<S> (&keys)[N], const S& in) {
  os << "[" << name << "]\n";
  for (const Key<S>& k : keys) {
    os << k.name << " = ";
    if (k.real) os << Num{in.*k.real};
    else if (k.integer) os << in.*k.integer;
    else if (k.boolean) os << (in.*k.boolean ? "true" : "false");
    else if (k.text) os << "\"" << in.*k.text << "\"";
    else if (k.clock) os << "\"" << toString(in.*k.clock) << "\"";
    os << "\n";
  }
}
}  // namespace

std::string toToml(const TwinConfig& c) {
  std::ostringstream os;
  os << "# hoist-twind effective configuration\n" << hoist::io::toToml(c.shaft) << "\n";
  writeKeys(os, "service", kServiceKeys, c.service);
  os << "\n";
  writeKeys(os, "alarms", kAlarmKeys, c.alarms);
  os << "\n";
  writeKeys(os, "forecast", kForecastKeys, c.forecast);
  // The estimator's sections, with the daemon's own keys at the head of each.
  std::string est = hoist::io::toToml(hoist::io::EstimatorConfig{c.estimator.enabled, c.estimator.settings});
  for (const DaemonSensorKey& k : kDaemonSensorKeys) {
    const std::string header = std::string("[") + k.section + "]\n";
    std::ostringstream line;
    line << k.key << " = " << Num{c.estimator.*k.member} << "\n";
    const std::size_t at = est.find(header);
    if (at == std::string::npos) est += "\n" + header + line.str();
    else est.insert(at + header.size(), line.str());
  }
  os << "\n" << est;
  return os.str();
}

}  // namespace hoist::service::cfg
