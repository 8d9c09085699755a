// python/src/simulate_py.hpp -- registers hoist._hoist._simulate and
// _simulate_batch (wrapped with docstrings in python/hoist/__init__.py).
#pragma once

#include <pybind11/pybind11.h>

namespace hoist::python {

void bindSimulate(pybind11::module_& m);

}  // namespace hoist::python
