// hoist/service/config_file.hpp -- reading the daemon's configuration
// (hoist/service/config.hpp) from a TOML file: the shaft sections through
// hoist_io, [service] and [alarms] here.  Target hoist_service_cfg; the
// I/O-free TwinCore (hoist_twin) does not link it.
#pragma once

#include <string>

#include <toml++/toml.h>

#include "hoist/service/config.hpp"

namespace hoist::svc {

/// Parse [service] and [alarms] from `tbl` into `cfg` (other sections are
/// ignored here).  Throws ConfigError.
void parseServiceSections(const toml::table& tbl, const std::string& source, TwinConfig& cfg);

/// The whole configuration from a TOML file (shaft sections through hoist_io,
/// plus [service] and [alarms]).  Throws (ConfigError or hoist_io's error).
TwinConfig loadTwinConfig(const std::string& path);

}  // namespace hoist::svc
