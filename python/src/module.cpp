// hoist._hoist: the C++ half of the Python package `hoist` (issue 34,
// docs/python.md).  The public API, its docstrings and the Result type are in
// python/hoist/__init__.py; this module gives Config, the exceptions and the
// runs (_simulate, _simulate_batch, _estimate) and the trip records (_trips,
// _trip, _record_trips).
#include <pybind11/pybind11.h>

#include "config_py.hpp"
#include "errors.hpp"
#include "hoist/profile.hpp"
#include "hoist/version.hpp"
#include "estimate_py.hpp"
#include "simulate_py.hpp"
#include "trips_py.hpp"

PYBIND11_MODULE(_hoist, m) {
  m.doc() = "hoist-twin's model and tools from Python (the C++ half; use the package `hoist`).";
  m.attr("__version__") = hoist::kVersionString;
  m.attr("DEFAULT_MAX_STEP") = hoist::kDefaultMaxStep;  // the model's one default substep [s]
  hoist::python::bindErrors(m);
  hoist::python::bindConfig(m);
  hoist::python::bindSimulate(m);
  hoist::python::bindEstimate(m);
  hoist::python::bindTrips(m);
}
