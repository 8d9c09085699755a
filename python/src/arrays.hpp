// python/src/arrays.hpp -- numpy in and out, and the tables the module
// builds from arrays.  Called with the GIL held.
//   toNumpy: a column vector handed to numpy without copying (the array owns it).
//   columnsCsv: named 1-d arrays as a CSV text (shortest round-trip doubles,
//     so the programs' CSV readers read exactly these numbers and apply
//     exactly their checks).
//   profileSource: hoist.simulate's `profile` argument.
//   measurementSamples: hoist.estimate's / hoist.record_trips' `measurements`.
#pragma once

#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "hoist/load_estimator.hpp"
#include "run.hpp"

namespace hoist::python {

/// The vector's storage as a 1-d float64 array (moved, not copied).
pybind11::array_t<double> toNumpy(std::vector<double>&& v);

/// Named columns of equal length as CSV text with the header `names`; NaN is
/// written as an empty field (a sample missing in that row).  `what` names
/// the argument in errors (ValueError).
std::string columnsCsv(const std::vector<std::string>& names, const std::vector<pybind11::object>& arrays,
                       const std::string& what);

/// A str or os.PathLike (CSV path or SPEC), a sequence (t, v, a[, l]) or a
/// mapping with keys t, v, a[, l].
ProfileSource profileSource(const pybind11::object& profile);

/// A measurement CSV path (str or os.PathLike) or a dict of named arrays
/// (written as that CSV: the same reader, the same checks); `source` is set
/// to the file name or "<measurement arrays>".  io::MeasurementError for bad
/// data, TypeError for another kind of argument.
std::vector<MeasurementSample> measurementSamples(const pybind11::object& measurements, std::string& source);

}  // namespace hoist::python
