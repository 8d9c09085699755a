// hoist/io/config.hpp -- the shaft configuration file (INTERFACES.md).
//
//   [hoisting_rope] mass_per_length, axial_stiffness, damping, initial_length
//   [guide_ropes]   length, mass_per_length, damping, preload = [Tb1, Tb2]
//   [cage]          mass, inertia, half_height
//   [load]          eccentric_force, offset
//   [model]         modes, gravity, initial = "static"|"rest", rho_inf
//
// Every key is optional and defaults to the paper's Section 3 value
// (ShaftParams{}).  Rejected, with ConfigError naming file, line and key:
// TOML syntax errors, unknown sections or keys (with a "did you mean"),
// wrong types (a string for a number, a float for `modes`, ...), and every
// value ShaftParams::validate() refuses (non-finite, non-positive mass, a cage
// longer than the guide ropes, ...).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "hoist/io/error.hpp"
#include "hoist/params.hpp"

namespace hoist::io {

/// Parse a TOML file.  Throws ConfigError (file:line: syntax error) or when the
/// file cannot be read.
toml::table loadTomlFile(const std::string& path);

/// Parse TOML text; `source` names it in messages.
toml::table parseToml(std::string_view text, const std::string& source = "<string>");

/// The shaft parameters of a parsed file.  `other_sections` are top-level
/// tables that belong to someone else (e.g. {"service", "alarms"} for the
/// daemon) and are skipped; any other unknown top-level key is an error.
/// The result has passed ShaftParams::validate().
ShaftParams shaftParamsFromToml(const toml::table& tbl, const std::string& source,
                                const std::vector<std::string>& other_sections = {});

/// Convenience: loadTomlFile + shaftParamsFromToml.
ShaftParams loadShaftConfig(const std::string& path,
                            const std::vector<std::string>& other_sections = {});

/// The parameters as a complete TOML document that shaftParamsFromToml reads
/// back exactly (doubles in shortest round-trip form).
std::string toToml(const ShaftParams& p);

}  // namespace hoist::io
