// [condition] (hoist/history/condition_config.hpp).
#include "hoist/history/condition_config.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "hoist/io/error.hpp"
#include "hoist/io/estimator_config.hpp"
#include "hoist/load_estimator.hpp"
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
  r.number("model_check_sigma", c.model_check_sigma);
  r.integer("seed_trips", c.seed_trips, -1000000, 1000000000);
  detail::runValidated(r, source, [&c] { c.validate(); });
  // The preload fit carries the accelerometer's offset as the estimator
  // does: [sensors] imu_accel_offset_sigma of the same file (default 0.005;
  // 0 = calibrated), so every trip record -- hoist-twind's, hoist-trips
  // ingest's, Python's -- fits it alike.
  // Only that key: the whole [sensors]/[estimator] is validated by whoever
  // reads the estimator (the daemon adds keys of its own to [estimator]).
  c.accel_offset_sigma = EstimatorSettings{}.accel_offset_sigma;
  if (const toml::table* sensors = root["sensors"].as_table()) {
    const toml::node* v = sensors->get("imu_accel_offset_sigma");
    if (v) {
      const std::optional<double> x = v->value<double>();
      if (!x || !std::isfinite(*x) || *x < 0.0 || *x > 1.0) {
        const auto& where = v->source().begin;
        throw io::ConfigError(source, static_cast<int>(where.line), "sensors.imu_accel_offset_sigma",
                              "must be a number in [0, 1] m/s^2");
      }
      c.accel_offset_sigma = *x;
    }
  }
  return c;
}

std::vector<std::string> configSections() {
  std::vector<std::string> s = io::daemonSections();
  for (const char* extra : {"history", "condition"})
    if (std::find(s.begin(), s.end(), extra) == s.end()) s.emplace_back(extra);
  return s;
}

}  // namespace hoist::history
