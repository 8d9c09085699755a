// python/src/errors.hpp -- the module's exceptions and the one mapping from
// the C++ errors of hoist_io/hoist_model to them.
//
//   hoist.InputError(ValueError)   io::InputError: .source, .line, .key
//     hoist.ConfigError            io::ConfigError (TOML)
//     hoist.ProfileError           io::ProfileError (profile CSV/SPEC/arrays)
//     hoist.MeasurementError       io::MeasurementError (estimator input)
//   ValueError                     io::OptionError, ParamError (a keyword option)
//   hoist.RunError(RuntimeError)   the run diverged or left the model's domain
// Every exception may carry .index (which configuration of a batch).
// Called with the GIL held.
#pragma once

#include <exception>
#include <string>

#include <pybind11/pybind11.h>

namespace hoist::python {

/// Creates the exception classes in `m` and registers the translator.
void bindErrors(pybind11::module_& m);

/// Sets the Python error for `e` (message prefixed by `prefix`, attribute
/// index = `index` when >= 0) and throws pybind11::error_already_set.
[[noreturn]] void raise(std::exception_ptr e, const std::string& prefix = "", long index = -1);

}  // namespace hoist::python
