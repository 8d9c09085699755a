// Reading the daemon's configuration from TOML: see hoist/service/config_file.hpp.
#include "hoist/service/config_file.hpp"

#include <cmath>
#include <functional>
#include <map>

#include "hoist/io/config.hpp"

namespace hoist::svc {

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
  sr.string("lcm_url_out", [&](const toml::node&, const std::string& v) { s.lcm_url_out = v; });
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

}  // namespace hoist::svc
