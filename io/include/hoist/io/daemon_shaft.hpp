// hoist/io/daemon_shaft.hpp -- the shaft of hoist-twind's configuration file,
// for the tools that take the daemon's --config but use only its shaft
// (hoist-replay --timing-test, hoist-timing-test, hoist-study advise, ...).
//
// Every section of the daemon's file is accepted (daemonSections(): the
// shaft's, [service], [alarms], [forecast], [sensors], [estimator]); the ones
// the tool does not use are ignored, and said so once.  The shaft sections
// are read as shaftParamsFromToml reads them: a misspelt key there, or an
// unknown top-level section, is still a ConfigError naming file, line and key.
#pragma once

#include <string>
#include <vector>

#include <toml++/toml.h>

#include "hoist/params.hpp"

namespace hoist::io {

/// The daemon's sections besides the shaft's that `tbl` has, in file order.
std::vector<std::string> daemonOnlySectionsIn(const toml::table& tbl);

/// The one line a tool prints (stderr, or its verbose output) about the
/// sections it ignores, e.g. "hoist-study: --config example.toml: using its
/// shaft only; ignoring [service], [estimator]"; "" when there are none.
std::string ignoredSectionsNote(const std::string& tool, const std::string& path,
                                const std::vector<std::string>& ignored);

/// loadTomlFile + shaftParamsFromToml(daemonSections()); `note` (if given)
/// receives ignoredSectionsNote's line ("" if nothing was ignored).
ShaftParams loadDaemonShaft(const std::string& path, const std::string& tool, std::string* note = nullptr);

}  // namespace hoist::io
