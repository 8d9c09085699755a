// [condition] (hoist/history/condition_config.hpp).
#include "hoist/history/condition_config.hpp"

#include <algorithm>
#include <stdexcept>

#include "hoist/io/estimator_config.hpp"
#include "hoist/io/toml_section.hpp"
#include "section.hpp"

namespace hoist::history {

ConditionSettings conditionSettingsFromToml(const toml::table& root, const std::string& source) {
  ConditionSettings c;
  io::SectionReader r(root, "condition", source);
  r.number("depth_bin", c.depth_bin);
  r.number("max_sigma", c.max_sigma);
  r.number("band_hz", c.band_hz);
  r.integer("baseline_trips", c.baseline_trips, -1000000, 1000000);
  r.number("fingerprint_sigma", c.fingerprint_sigma);
  r.number("preload_warning", c.preload_warning);
  r.number("preload_critical", c.preload_critical);
  r.number("trend_walk", c.trend_walk);
  detail::runValidated(r, source, [&c] { c.validate(); });
  // The preload fit carries the accelerometer's offset as the estimator
  // does: [sensors] imu_accel_offset_sigma of the same file (default 0.005;
  // 0 = calibrated), so every trip record -- hoist-twind's, hoist-trips
  // ingest's, Python's -- fits it alike.
  c.accel_offset_sigma = io::estimatorConfigFromToml(root, source).settings.accel_offset_sigma;
  return c;
}

std::vector<std::string> configSections() {
  std::vector<std::string> s = io::daemonSections();
  for (const char* extra : {"history", "condition"})
    if (std::find(s.begin(), s.end(), extra) == s.end()) s.emplace_back(extra);
  return s;
}

}  // namespace hoist::history
