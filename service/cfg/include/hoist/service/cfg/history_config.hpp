// hoist/service/cfg/history_config.hpp -- hoist-twind's [history] and
// [condition]: whether and where the daemon records every trip (issue 32,
// docs/condition.md "Live").
//
// The keys are hoist::history's (hoist/history/config.hpp,
// hoist/history/condition_config.hpp: the same readers as hoist-trips),
// plus one of the daemon's own:
//
//   [history]
//   enabled = true   # record trips (default: true when the daemon has a
//                    # configuration file, false when it runs the paper's
//                    # shaft without one)
//
// The database when `url` is empty: `history.sqlite` beside the
// configuration file, or --history-default (the installed service passes
// /var/lib/hoist-twin/history.sqlite, its StateDirectory).
//
// Who calls: hoist-twind's main (reading, --print-config); the trip room
// (service/app/trip_room.hpp) gets the result.  Target hoist_service_cfg.
#pragma once

#include <string>

#include "hoist/history/config.hpp"
#include "hoist/trip_pipeline.hpp"

namespace hoist::service::inline cfg {

struct TripHistoryConfig {
  bool enabled = false;             ///< history.enabled
  history::HistoryConfig store;     ///< history.url, keep_days, queue_dir, password_file, retry_seconds
  ConditionSettings condition;      ///< [condition]
  std::string config_dir;           ///< the configuration file's folder ("" = none: the working directory)
  /// The shaft's name in the records: the configuration file's stem
  /// (hoist-twind@NAME.service: NAME), or the label of a shaft hosted with others.
  std::string shaft;
};

/// [history] and [condition] of the configuration file `path` ("" = no
/// file: history off, the defaults).  Throws io::ConfigError
/// "file:line: history.key: why" / "condition.key: why".
TripHistoryConfig loadTripHistoryConfig(const std::string& path);

/// [history] (with enabled) and [condition] as TOML, for --print-config.
std::string toToml(const TripHistoryConfig& c);

}  // namespace hoist::service::cfg
