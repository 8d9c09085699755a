// python/src/config_py.hpp -- hoist.Config: a shaft configuration as the
// programs read it (hoist/io/config.hpp, hoist/io/estimator_config.hpp).
//
// A Config holds the parsed TOML table (so the daemon's [sensors] and
// [estimator] travel with it, for hoist.estimate) and the ShaftParams it
// gives.  Every change (set) goes through the same readers as a file, so a
// bad value raises hoist.ConfigError naming the key, exactly as the file
// would.  Not shared between threads while it is changed; the runs copy
// the ShaftParams out while the GIL is held.
#pragma once

#include <string>

#include <pybind11/pybind11.h>
#include <toml++/toml.h>

#include "hoist/io/estimator_config.hpp"
#include "hoist/params.hpp"

namespace hoist::python {

struct Config {
  toml::table tbl;     ///< the file's table, with every set() applied
  std::string source;  ///< file name, "<paper>" or "<string>"
  ShaftParams params;  ///< the shaft, validated

  /// The [sensors]/[estimator] settings (validated at load and on set()).
  io::EstimatorConfig estimator() const;
  /// hoist-estimate's default substep: [service] max_step, else kDefaultMaxStep (0.0025 s).
  double serviceMaxStep() const;
};

/// Registers hoist._hoist.Config.
void bindConfig(pybind11::module_& m);

}  // namespace hoist::python
