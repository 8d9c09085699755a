// hoist/service/cfg/config_file.hpp -- reading the daemon's configuration
// (hoist/service/core/config.hpp) from a TOML file: the shaft sections through
// hoist_io, [service] and [alarms] here.  Target hoist_service_cfg; the
// I/O-free TwinCore (hoist_twin) does not link it.
#pragma once

#include <string>

#include <toml++/toml.h>

#include "hoist/io/error.hpp"
#include "hoist/service/core/config.hpp"

namespace hoist::service::inline cfg {

/// A configuration error; what() is "<file>:<line>: <key>: <message>" (the
/// line is omitted when unknown).  The one type of hoist_io.
using ConfigError = hoist::io::ConfigError;

/// Parse [service] and [alarms] from `tbl` into `cfg` (other sections are
/// ignored here).  Throws ConfigError.
void parseServiceSections(const toml::table& tbl, const std::string& source, TwinConfig& cfg);

/// The whole configuration from a TOML file (shaft sections through hoist_io,
/// plus [service] and [alarms]).  Throws ConfigError.
TwinConfig loadTwinConfig(const std::string& path);

/// The effective configuration as TOML (for --print-config): the shaft as
/// hoist::io::toToml writes it, then [service] and [alarms].
std::string toToml(const TwinConfig& cfg);

}  // namespace hoist::service::cfg
