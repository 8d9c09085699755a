// python/src/estimate_py.hpp -- registers hoist._hoist._estimate and
// ESTIMATE_COLUMNS (hoist-estimate's output columns); wrapped in python/hoist/__init__.py.
#pragma once

#include <pybind11/pybind11.h>

namespace hoist::python {

void bindEstimate(pybind11::module_& m);

}  // namespace hoist::python
