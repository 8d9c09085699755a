// python/src/estimate_py.hpp -- registers hoist._hoist._estimate and
// ESTIMATE_COLUMNS (hoist-estimate's output columns); wrapped in python/hoist/__init__.py.
#pragma once

#include <optional>

#include <pybind11/pybind11.h>

#include "config_py.hpp"

namespace hoist::python {

void bindEstimate(pybind11::module_& m);

/// hoist.estimate's and hoist.record_trips' keyword options `modes` and
/// `max_step`, checked (ValueError naming the option): sets p.n, returns the
/// substep (None: the config's [service] max_step, else 0.0025 s).
double recordedRunOptions(const Config& cfg, std::optional<int> modes, std::optional<double> max_step,
                          ShaftParams& p);

}  // namespace hoist::python
