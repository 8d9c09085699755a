// numpy in and out (python/src/arrays.hpp).
#include "arrays.hpp"

#include <cmath>
#include <sstream>

#include "hoist/io/estimator_config.hpp"
#include "hoist/io/results.hpp"

namespace py = pybind11;

namespace hoist::python {

py::array_t<double> toNumpy(std::vector<double>&& v) {
  auto* owned = new std::vector<double>(std::move(v));
  py::capsule free_it(owned, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  return py::array_t<double>(static_cast<py::ssize_t>(owned->size()), owned->data(), free_it);
}

std::string columnsCsv(const std::vector<std::string>& names, const std::vector<py::object>& arrays,
                       const std::string& what) {
  std::vector<py::array_t<double, py::array::c_style | py::array::forcecast>> cols;
  py::ssize_t n = -1;
  for (std::size_t k = 0; k < arrays.size(); ++k) {
    auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(arrays[k]);
    if (!a || a.ndim() != 1)
      throw py::value_error(what + ": column '" + names[k] + "' must be a 1-d array of numbers");
    if (n >= 0 && a.shape(0) != n)
      throw py::value_error(what + ": column '" + names[k] + "' has " + std::to_string(a.shape(0)) +
                            " values, column '" + names[0] + "' has " + std::to_string(n));
    n = a.shape(0);
    cols.push_back(std::move(a));
  }
  std::string s;
  for (std::size_t k = 0; k < names.size(); ++k) s += (k ? "," : "") + names[k];
  s += '\n';
  s.reserve(static_cast<std::size_t>(n) * 20 * names.size());
  for (py::ssize_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < cols.size(); ++k) {
      if (k) s += ',';
      const double v = cols[k].at(i);
      if (std::isnan(v)) continue;  // empty field: no sample
      if (std::isinf(v)) s += v > 0 ? "inf" : "-inf";  // the reader rejects it, naming the row and column
      else io::appendNumber(s, v);
    }
    s += '\n';
  }
  return s;
}

ProfileSource profileSource(const py::object& profile) {
  ProfileSource src;
  const py::module_ os = py::module_::import("os");
  if (py::isinstance<py::str>(profile) || py::isinstance(profile, os.attr("PathLike"))) {
    src.arg = py::str(os.attr("fspath")(profile));
    return src;
  }
  std::vector<std::string> names = {"t", "v", "a", "l"};
  std::vector<py::object> arrays;
  if (py::isinstance<py::dict>(profile)) {
    const auto d = profile.cast<py::dict>();
    for (const auto& k : d)
      if (std::string key = py::str(k.first); key != "t" && key != "v" && key != "a" && key != "l")
        throw py::value_error("profile: unknown column '" + key + "' (a profile has t, v, a and optionally l)");
    for (const auto& k : names)
      if (d.contains(k)) arrays.push_back(d[k.c_str()]);
      else if (k != "l") throw py::value_error("profile: column '" + k + "' is missing (t, v, a required, l optional)");
  } else if (py::isinstance<py::sequence>(profile) && !py::isinstance<py::array>(profile)) {
    for (const auto& a : profile.cast<py::sequence>()) arrays.push_back(py::reinterpret_borrow<py::object>(a));
    if (arrays.size() != 3 && arrays.size() != 4)
      throw py::value_error("profile: expected arrays (t, v, a) or (t, v, a, l), got " + std::to_string(arrays.size()));
  } else {
    throw py::type_error("profile: expected a SPEC string, a CSV path, arrays (t, v, a[, l]) or a dict of them");
  }
  names.resize(arrays.size());
  // The columns in the CSV reader's order: t, l, v, a.
  if (arrays.size() == 4) {
    names = {"t", "l", "v", "a"};
    arrays = {arrays[0], arrays[3], arrays[1], arrays[2]};
  }
  src.csv_text = columnsCsv(names, arrays, "profile");
  return src;
}

std::vector<MeasurementSample> measurementSamples(const py::object& measurements, std::string& source) {
  const py::module_ os = py::module_::import("os");
  if (py::isinstance<py::str>(measurements) || py::isinstance(measurements, os.attr("PathLike"))) {
    source = py::str(os.attr("fspath")(measurements));
    return io::readMeasurementsCsvFile(source);
  }
  if (py::isinstance<py::dict>(measurements)) {
    std::vector<std::string> names;
    std::vector<py::object> arrays;
    for (const auto& [k, v] : measurements.cast<py::dict>()) {
      names.push_back(py::str(k));
      arrays.push_back(py::reinterpret_borrow<py::object>(v));
    }
    source = "<measurement arrays>";
    std::istringstream in(columnsCsv(names, arrays, "measurements"));
    return io::readMeasurementsCsv(in, source);
  }
  throw py::type_error("measurements: expected a CSV path or a dict of arrays (t, l, v, a[, f_y, omega, rope_load])");
}

}  // namespace hoist::python
