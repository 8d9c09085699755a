// hoist._hoist.simulate and simulate_batch: hoist-sim's runs from Python
// (the Python wrappers with the docstrings: python/hoist/__init__.py).
#include <atomic>
#include <cmath>
#include <optional>

#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "config_py.hpp"
#include "errors.hpp"
#include "run.hpp"
#include "simulate_py.hpp"
#include "tasks.hpp"

namespace py = pybind11;

namespace hoist::python {

namespace {

/// hoist-sim's option checks (CLI11's ranges and choices), naming the keyword.
io::SimRunOptions runOptions(double dt, double max_step, std::optional<double> t_end, std::optional<int> modes,
                             const std::string& initial, const std::string& method,
                             const py::object& static_correction, std::optional<double> rho_inf) {
  io::SimRunOptions o;
  auto range = [](const char* name, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi))
      throw py::value_error(std::string(name) + ": " + py::str(py::float_(v)).cast<std::string>() +
                            " is not in [" + py::str(py::float_(lo)).cast<std::string>() + ", " +
                            py::str(py::float_(hi)).cast<std::string>() + "]");
  };
  range("dt", dt, 1e-6, 1.0);
  range("max_step", max_step, 0.0, 1.0);
  o.dt = dt;
  o.max_step = max_step;
  if (t_end) {
    if (!std::isfinite(*t_end) || *t_end < 0) throw py::value_error("t_end: must be a finite time >= 0 [s] (None: the profile's end)");
    o.t_end = *t_end;
  }
  if (modes) {
    if (*modes < 1 || *modes > kMaxModes)
      throw py::value_error("modes: " + std::to_string(*modes) + " is not in [1, " + std::to_string(kMaxModes) + "]");
    o.modes = *modes;
  }
  if (!initial.empty() && initial != "static" && initial != "rest" && initial != "config")
    throw py::value_error("initial: '" + initial + "' is not one of 'static', 'rest', 'config'");
  o.initial = initial;
  if (method != "fast" && method != "paper")
    throw py::value_error("method: '" + method + "' is not one of 'fast', 'paper'");
  o.method = method;
  if (py::isinstance<py::bool_>(static_correction)) {
    o.static_correction = static_correction.cast<bool>() ? "on" : "off";
  } else if (py::isinstance<py::str>(static_correction)) {
    o.static_correction = static_correction.cast<std::string>();
    if (o.static_correction != "on" && o.static_correction != "off")
      throw py::value_error("static_correction: '" + o.static_correction + "' is not one of True, False, 'on', 'off'");
  } else if (!static_correction.is_none()) {
    throw py::value_error("static_correction: expected True, False, 'on', 'off' or None (the config's)");
  }
  if (rho_inf) {
    range("rho_inf", *rho_inf, 0.0, 1.0);
    o.rho_inf = *rho_inf;
  }
  return o;
}

/// A finished run as the Python side's parts: (columns, shapes or None, info).
py::tuple toPython(RunResult&& r) {
  py::dict cols;
  for (std::size_t k = 0; k < kResultColumns.size(); ++k) cols[kResultColumns[k]] = toNumpy(std::move(r.columns[k]));
  py::object shapes = py::none();
  if (!r.shapes[0].empty()) {
    py::dict s;
    for (std::size_t k = 0; k < kShapeColumns.size(); ++k) s[kShapeColumns[k]] = toNumpy(std::move(r.shapes[k]));
    shapes = s;
  }
  py::dict info;
  info["modes"] = r.params.n;
  info["substeps"] = r.substeps;
  info["initial"] = toString(r.params.initial);
  info["static_correction"] = r.params.static_correction;
  return py::make_tuple(cols, shapes, info);
}

struct Common {
  io::SimRunOptions options;
  std::vector<double> shape_times;
  int shape_points = 401;
  std::optional<double> estop_at;
  double estop_decel = 3.0, estop_jerk = 10.0;

  RunSpec spec(const ShaftParams& p) const {
    RunSpec s{p, options, shape_times, shape_points};
    s.estop = estop_at.has_value();
    s.estop_at = estop_at.value_or(0.0);
    s.estop_decel = estop_decel;
    s.estop_jerk = estop_jerk;
    return s;
  }
};

/// --estop-at, --estop-decel, --estop-jerk (hoist-sim's ranges).
void estopOptions(Common& c, std::optional<double> at, double decel, double jerk) {
  if (!(decel >= 1e-6 && decel <= 100.0)) throw py::value_error("estop_decel: must be in [1e-06, 100] m/s^2");
  if (!(jerk >= 1e-6 && jerk <= 1e6)) throw py::value_error("estop_jerk: must be in [1e-06, 1e+06] m/s^3");
  c.estop_at = at;
  c.estop_decel = decel;
  c.estop_jerk = jerk;
}

Common common(double dt, double max_step, std::optional<double> t_end, std::optional<int> modes,
              const std::string& initial, const std::string& method, const py::object& static_correction,
              std::optional<double> rho_inf, std::vector<double> shape_times, int shape_points) {
  Common c;
  c.options = runOptions(dt, max_step, t_end, modes, initial, method, static_correction, rho_inf);
  c.shape_times = std::move(shape_times);
  c.shape_points = shape_points;
  return c;
}

py::tuple simulateOne(const Config& cfg, const py::object& profile, double dt, double max_step,
                      std::optional<double> t_end, std::optional<int> modes, const std::string& initial,
                      const std::string& method, const py::object& static_correction, std::optional<double> rho_inf,
                      std::vector<double> shape_times, int shape_points, std::optional<double> estop_at,
                      double estop_decel, double estop_jerk, const py::object& progress) {
  Common c = common(dt, max_step, t_end, modes, initial, method, static_correction, rho_inf,
                    std::move(shape_times), shape_points);
  estopOptions(c, estop_at, estop_decel, estop_jerk);
  const RunSpec spec = c.spec(cfg.params);
  const ProfileSource src = profileSource(profile);
  const long rows = progress.is_none() ? 0 : std::max(1L, expectedRows(spec, src));
  std::atomic<long> steps{0};
  std::optional<RunResult> result;
  const TaskOutcome out = runTasks(
      1, 1, [&](std::size_t, const std::atomic<bool>& cancel) {
        try {
          result = runSimulation(spec, src, cancel, &steps);
        } catch (const Cancelled&) {
          // Only Ctrl-C or a raising progress cancels a single run: runTasks raises that.
        }
      },
      [&](std::size_t) {
        if (!progress.is_none()) progress(std::min(1.0, static_cast<double>(steps.load()) / static_cast<double>(rows)));
      });
  if (out.errors[0]) raise(out.errors[0]);
  return toPython(std::move(*result));
}

py::list simulateBatch(const std::vector<const Config*>& configs, const py::object& profile, int threads,
                       const py::object& progress, double dt, double max_step, std::optional<double> t_end,
                       std::optional<int> modes, const std::string& initial, const std::string& method,
                       const py::object& static_correction, std::optional<double> rho_inf,
                       std::vector<double> shape_times, int shape_points, std::optional<double> estop_at,
                       double estop_decel, double estop_jerk) {
  Common c = common(dt, max_step, t_end, modes, initial, method, static_correction, rho_inf,
                    std::move(shape_times), shape_points);
  estopOptions(c, estop_at, estop_decel, estop_jerk);
  const ProfileSource src = profileSource(profile);
  std::vector<RunSpec> specs;
  specs.reserve(configs.size());
  for (std::size_t i = 0; i < configs.size(); ++i) {
    if (!configs[i]) throw py::type_error("simulate_batch: configs[" + std::to_string(i) + "] is None, not a Config");
    specs.push_back(c.spec(configs[i]->params));
  }
  std::vector<std::optional<RunResult>> results(specs.size());
  std::size_t last_done = static_cast<std::size_t>(-1);
  const TaskOutcome out = runTasks(
      specs.size(), threads,
      [&](std::size_t i, const std::atomic<bool>& cancel) {
        try {
          results[i] = runSimulation(specs[i], src, cancel);
        } catch (const Cancelled&) {
          // Stopped because another run failed (or Ctrl-C): that one is reported.
        }
      },
      [&](std::size_t done) {
        if (progress.is_none() || done == last_done) return;
        last_done = done;
        progress(done, specs.size());
      });
  // The first failure by index (later ones may be cancellations); nothing is returned.
  for (std::size_t i = 0; i < specs.size(); ++i)
    if (out.errors[i]) {
      results.clear();
      raise(out.errors[i], "simulate_batch: configs[" + std::to_string(i) + "]: ", static_cast<long>(i));
    }
  py::list list;
  for (auto& r : results) list.append(toPython(std::move(*r)));
  return list;
}

}  // namespace

void bindSimulate(py::module_& m) {
  m.def("_simulate", &simulateOne, py::arg("cfg"), py::arg("profile"), py::arg("dt"), py::arg("max_step"),
        py::arg("t_end"), py::arg("modes"), py::arg("initial"), py::arg("method"), py::arg("static_correction"),
        py::arg("rho_inf"), py::arg("shape_times"), py::arg("shape_points"), py::arg("estop_at"),
        py::arg("estop_decel"), py::arg("estop_jerk"), py::arg("progress"));
  m.def("_simulate_batch", &simulateBatch, py::arg("configs"), py::arg("profile"), py::arg("threads"),
        py::arg("progress"), py::arg("dt"), py::arg("max_step"), py::arg("t_end"), py::arg("modes"),
        py::arg("initial"), py::arg("method"), py::arg("static_correction"), py::arg("rho_inf"),
        py::arg("shape_times"), py::arg("shape_points"), py::arg("estop_at"), py::arg("estop_decel"),
        py::arg("estop_jerk"));
}

}  // namespace hoist::python
