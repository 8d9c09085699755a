// hoist._hoist._estimate: hoist-estimate from Python (the wrapper with the
// docstring: python/hoist/__init__.py).  The input checks and the NIS-window
// sizing are hoist-estimate's (io::checkRecordedRun, one function) so that both give the
// same numbers; the columns are its output columns, in its order, with nan for
// a value not observed (the test compares both on the same files).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>

#include <pybind11/stl.h>

#include "arrays.hpp"
#include "config_py.hpp"
#include "errors.hpp"
#include "estimate_py.hpp"
#include "hoist/io/recorded_run.hpp"
#include "hoist/io/sim_run.hpp"
#include "hoist/load_estimator.hpp"
#include "tasks.hpp"

namespace py = pybind11;

namespace hoist::python {

namespace {

struct Cell {
  const char* name;
  std::function<double(const LoadEstimate&, const EstimatorCounters&)> get;
};

/// nan unless observed (hoist-estimate's rule: seen and sigma >= 0).
double obs(double v, double sigma, bool seen) { return seen && sigma >= 0.0 ? v : std::nan(""); }

const std::vector<Cell>& cells() {
  using E = LoadEstimate;
  using C = EstimatorCounters;
  static const std::vector<Cell> c = {
      {"t", [](const E& e, const C&) { return e.t; }},
      {"l", [](const E& e, const C&) { return e.kin.l; }},
      {"Fa", [](const E& e, const C&) { return obs(e.Fa, e.sigma_Fa, e.fa_observed); }},
      {"b", [](const E& e, const C&) { return obs(e.b, e.sigma_b, e.fa_observed && e.moment_observed); }},
      {"moment", [](const E& e, const C&) { return obs(e.moment, e.sigma_moment, e.moment_observed); }},
      {"sigma_Fa", [](const E& e, const C&) { return obs(e.sigma_Fa, e.sigma_Fa, e.fa_observed); }},
      {"sigma_moment", [](const E& e, const C&) { return obs(e.sigma_moment, e.sigma_moment, e.moment_observed); }},
      {"y_c", [](const E& e, const C&) { return e.y_c; }},
      {"theta", [](const E& e, const C&) { return e.theta; }},
      {"sigma_y_c", [](const E& e, const C&) { return e.sigma_y_c; }},
      {"sigma_theta", [](const E& e, const C&) { return e.sigma_theta; }},
      {"lambda_0", [](const E& e, const C&) { return e.lambda[0]; }},
      {"lambda_1", [](const E& e, const C&) { return e.lambda[1]; }},
      {"lambda_2", [](const E& e, const C&) { return e.lambda[2]; }},
      {"lambda_3", [](const E& e, const C&) { return e.lambda[3]; }},
      {"lambda_4", [](const E& e, const C&) { return e.lambda[4]; }},
      {"nis", [](const E& e, const C&) { return e.nis; }},
      {"nis_window", [](const E& e, const C&) { return e.nis_window; }},
      {"mismatch", [](const E& e, const C&) { return e.mismatch ? 1.0 : 0.0; }},
      {"sigma_b", [](const E& e, const C&) { return obs(e.sigma_b, e.sigma_b, e.fa_observed && e.moment_observed); }},
      {"x_c", [](const E& e, const C&) { return e.x_c; }},
      {"sigma_x_c", [](const E& e, const C&) { return e.sigma_x_c; }},
      {"sigma_lambda_0", [](const E& e, const C&) { return e.sigma_lambda[0]; }},
      {"sigma_lambda_1", [](const E& e, const C&) { return e.sigma_lambda[1]; }},
      {"sigma_lambda_2", [](const E& e, const C&) { return e.sigma_lambda[2]; }},
      {"sigma_lambda_3", [](const E& e, const C&) { return e.sigma_lambda[3]; }},
      {"sigma_lambda_4", [](const E& e, const C&) { return e.sigma_lambda[4]; }},
      {"theta_open", [](const E& e, const C&) { return e.theta_open; }},
      {"nis_dof", [](const E& e, const C&) { return static_cast<double>(e.nis_dof); }},
      {"nis_lower", [](const E& e, const C&) { return e.nis_lower; }},
      {"nis_upper", [](const E& e, const C&) { return e.nis_upper; }},
      {"nis_bound", [](const E& e, const C&) { return e.nis_bound; }},
      {"drift", [](const E& e, const C&) { return e.drift; }},
      {"nis_exceeded", [](const E& e, const C&) { return e.nis_exceeded ? 1.0 : 0.0; }},
      {"drift_exceeded", [](const E& e, const C&) { return e.drift_exceeded ? 1.0 : 0.0; }},
      {"sensors", [](const E& e, const C&) { return static_cast<double>(e.sensors); }},
      {"fa_observed", [](const E& e, const C&) { return e.fa_observed ? 1.0 : 0.0; }},
      {"moment_observed", [](const E& e, const C&) { return e.moment_observed ? 1.0 : 0.0; }},
      {"accepted", [](const E&, const C& c) { return static_cast<double>(c.accepted); }},
      {"gated", [](const E&, const C& c) { return static_cast<double>(c.gated); }},
      {"load_changes", [](const E&, const C& c) { return static_cast<double>(c.load_changes); }},
      {"implausible", [](const E&, const C& c) { return static_cast<double>(c.implausible); }},
      {"plausible", [](const E& e, const C&) { return e.plausible ? 1.0 : 0.0; }},
      {"fault_imu_accel", [](const E& e, const C&) { return static_cast<double>(e.fault_imu_accel); }},
      {"fault_imu_rate", [](const E& e, const C&) { return static_cast<double>(e.fault_imu_rate); }},
      {"fault_rope_load", [](const E& e, const C&) { return static_cast<double>(e.fault_rope_load); }},
      {"noise_imu_accel", [](const E& e, const C&) { return e.noise_imu_accel; }},
      {"noise_imu_rate", [](const E& e, const C&) { return e.noise_imu_rate; }},
      {"noise_rope_load", [](const E& e, const C&) { return e.noise_rope_load; }},
      {"change_t", [](const E& e, const C&) { return e.change_t; }},
      {"change_Fa", [](const E& e, const C&) { return e.change_Fa; }},
      {"change_moment", [](const E& e, const C&) { return e.change_moment; }},
  };
  return c;
}

std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

double recordedRunOptions(const Config& cfg, std::optional<int> modes, std::optional<double> max_step_opt,
                          ShaftParams& p) {
  if (max_step_opt && !(*max_step_opt >= 0.0 && *max_step_opt <= 10.0))
    throw py::value_error("max_step: " + fmt(*max_step_opt) + " is not in [0, 10]");
  const double max_step = max_step_opt ? *max_step_opt : cfg.serviceMaxStep();
  if (modes) {
    if (*modes < 1 || *modes > kMaxModes)
      throw py::value_error("modes: " + std::to_string(*modes) + " is not in [1, " + std::to_string(kMaxModes) + "]");
    p.n = *modes;
  }
  return max_step;
}

namespace {

py::dict estimate(const Config& cfg, const py::object& measurements, std::optional<int> modes,
                  std::optional<double> max_step_opt, const py::object& progress) {
  ShaftParams p = cfg.params;
  const io::EstimatorConfig ec = cfg.estimator();
  const double max_step = recordedRunOptions(cfg, modes, max_step_opt, p);
  // Measurements: a CSV path, or named arrays written as that CSV (same reader, same checks).
  std::string source;
  const std::vector<MeasurementSample> samples = measurementSamples(measurements, source);
  // The shaft, the NIS window's rate and the substeps: hoist-estimate's checks (hoist/io/recorded_run.hpp).
  EstimatorSettings set;
  try {
    set = io::checkRecordedRun(samples, p, ec.settings, max_step, source);
  } catch (const io::RecordedRunError& e) {
    throw py::value_error(e.option == io::RecordedRunError::Option::MaxStep
                              ? "max_step " + fmt(max_step) + ": " + e.what()
                              : "measurements " + source + ": " + e.what());
  }

  const auto& cs = cells();
  std::vector<std::vector<double>> cols(cs.size());
  for (auto& c : cols) c.reserve(samples.size());
  std::atomic<double> fraction{0.0};
  struct Stop {};
  const TaskOutcome out = runTasks(
      1, 1,
      [&](std::size_t, const std::atomic<bool>& cancel) {
        try {
          estimateRecorded(
              p, set, max_step, samples,
              [&](const LoadEstimate& e, const EstimatorCounters& c) {
                if (cancel.load(std::memory_order_relaxed)) throw Stop{};
                for (std::size_t k = 0; k < cs.size(); ++k) cols[k].push_back(cs[k].get(e, c));
              },
              [&](double f) { fraction.store(f); });
        } catch (const std::domain_error& e) {
          throw RunError(std::string("the model left its domain: ") + e.what());
        } catch (const Stop&) {
        }
      },
      [&](std::size_t) {
        if (!progress.is_none()) progress(fraction.load());
      });
  if (out.errors[0]) raise(out.errors[0]);
  py::dict d;
  for (std::size_t k = 0; k < cs.size(); ++k) d[cs[k].name] = toNumpy(std::move(cols[k]));
  return d;
}

}  // namespace

void bindEstimate(py::module_& m) {
  m.def("_estimate", &estimate, py::arg("cfg"), py::arg("measurements"), py::arg("modes"), py::arg("max_step"),
        py::arg("progress"));
  py::list names;
  for (const auto& c : cells()) names.append(c.name);
  m.attr("ESTIMATE_COLUMNS") = names;
}

}  // namespace hoist::python
