// hoist-twind's [history] and [condition]: see hoist/service/cfg/history_config.hpp.
#include "hoist/service/cfg/history_config.hpp"

#include <charconv>
#include <filesystem>
#include <sstream>

#include "hoist/history/condition_config.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/toml_section.hpp"

namespace hoist::service::inline cfg {

TripHistoryConfig loadTripHistoryConfig(const std::string& path) {
  TripHistoryConfig c;
  if (path.empty()) return c;  // the paper's shaft, no file: nothing recorded
  toml::table tbl = hoist::io::loadTomlFile(path);
  c.enabled = true;
  c.config_dir = std::filesystem::path(path).parent_path().string();
  c.shaft = std::filesystem::path(path).stem().string();
  // history.enabled is the daemon's own key: taken out before the shared
  // reader (which refuses keys it does not know) sees the section.
  if (toml::table* sec = tbl["history"].as_table()) {
    if (const toml::node* n = sec->get("enabled")) {
      const auto* b = n->as_boolean();
      if (!b)
        throw hoist::io::ConfigError(path, hoist::io::lineOf(*n), "history.enabled",
                                     std::string("must be true or false, got ") + hoist::io::typeName(*n));
      c.enabled = b->get();
      sec->erase("enabled");
    }
  }
  try {
    c.store = history::historyConfigFromToml(tbl, path);
  } catch (const hoist::io::ConfigError& e) {
    // The shared reader lists its own keys; the daemon also takes enabled.
    if (e.key().rfind("history.", 0) != 0 || e.message().find("unknown key") == std::string::npos) throw;
    throw hoist::io::ConfigError(e.source(), e.line(), e.key(), e.message() + ", and (hoist-twind) enabled");
  }
  c.condition = history::conditionSettingsFromToml(tbl, path);
  return c;
}

namespace {
std::string num(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}
}  // namespace

std::string toToml(const TripHistoryConfig& c) {
  std::ostringstream os;
  const history::HistoryConfig& h = c.store;
  os << "[history]\n"
     << "enabled = " << (c.enabled ? "true" : "false") << "\n"
     << "url = \"" << h.url << "\"\n"
     << "keep_days = " << h.keep_days << "\n"
     << "queue_dir = \"" << h.queue_dir << "\"\n"
     << "password_file = \"" << h.password_file << "\"\n"
     << "retry_seconds = " << num(h.retry_seconds) << "\n";
  const ConditionSettings& s = c.condition;
  os << "\n[condition]\n"
     << "depth_bin = " << num(s.depth_bin) << "\n"
     << "max_sigma = " << num(s.max_sigma) << "\n"
     << "band_hz = " << num(s.band_hz) << "\n"
     << "baseline_trips = " << s.baseline_trips << "\n"
     << "fingerprint_sigma = " << num(s.fingerprint_sigma) << "\n"
     << "preload_warning = " << num(s.preload_warning) << "\n"
     << "preload_critical = " << num(s.preload_critical) << "\n"
     << "trend_walk = " << num(s.trend_walk) << "\n";
  return os.str();
}

}  // namespace hoist::service::cfg
