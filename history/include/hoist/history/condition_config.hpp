// hoist/history/condition_config.hpp -- [condition]: the trip records' and
// the condition alarms' settings (hoist::ConditionSettings,
// hoist/trip_pipeline.hpp), read from hoist-twind's configuration.
//
//   [condition]
//   depth_bin = 10.0          # depth-bin size of the record [m]
//   max_sigma = 0.1           # sigma(s) above this: the trip is not informative
//   band_hz = 0.0             # the model's band for the f_y split (0: from the twin's highest mode)
//   baseline_trips = 10       # commissioning fingerprint: trips per direction
//   fingerprint_sigma = 4.0   # SHAFT_FINGERPRINT threshold [baseline sd]
//   preload_warning = 0.85    # GUIDE_PRELOAD_LOW WARNING below (95 % confidence)
//   preload_critical = 0.70   # ... CRITICAL below
//   trend_walk = 0.05         # random walk of s between trips (sigma per trip)
//   seed_trips = 500          # newest stored trips read at start (and the baseline before them); 0: all
//
// Every key optional (ConditionSettings{} defaults).  Errors: io::ConfigError
// "file:line: condition.key: why" (unknown keys with "did you mean", wrong
// types, what ConditionSettings::validate() refuses).  The accelerometer's
// offset prior is [sensors] imu_accel_offset_sigma of the same file (read
// here too: the preload fit carries the offset as the estimator does).  The
// clearance gaps are not [condition] keys (they stay at their defaults here;
// the daemon copies its [alarms]).
// Who calls: hoist-trips (ingest, trend); the daemon's configuration later.
#pragma once

#include <string>
#include <vector>

#include <toml++/toml.h>

#include "hoist/trip_pipeline.hpp"

namespace hoist::history {

ConditionSettings conditionSettingsFromToml(const toml::table& root, const std::string& source);

/// The top-level sections hoist-twind's configuration may hold besides the
/// shaft's ([history] and [condition] added to io::daemonSections()), for
/// io::shaftParamsFromToml's `other_sections`.
std::vector<std::string> configSections();

}  // namespace hoist::history
