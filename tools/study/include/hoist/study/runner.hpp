// hoist/study/runner.hpp -- running independent simulations on threads.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "hoist/params.hpp"
#include "hoist/profile.hpp"
#include "hoist/simulator.hpp"
#include "hoist/study/trace.hpp"

namespace hoist::study {

struct RunSpec {
  std::string label;    ///< e.g. "Tb1+Tb2=48000"
  double value = 0.0;   ///< swept value (0 for the single baseline run)
  ShaftParams params;
};

struct RunOptions {
  SimulationOptions sim;              ///< dt, max_step, method, initial (overrides params.initial)
  std::vector<double> shape_times;    ///< record guide-rope shapes at these t (nearest step)
  int shape_points = 401;
};

struct RunResult {
  RunSpec spec;
  Trace trace;
  std::vector<Shape> shapes;
  double wall_seconds = 0.0;
  std::string error;  ///< non-empty if the run failed (then trace may be partial)
  bool ok() const { return error.empty(); }
};

/// Simulate one run (thread-safe: builds its own model and solver).
/// `progress` (optional) receives this run's fraction done.
RunResult runOne(const RunSpec& spec, const HoistProfile& profile, const RunOptions& opt,
                 const std::function<void(double)>& progress = {});

/// Run independent specs on `jobs` threads (<= 0: hardware concurrency).
/// `progress(done_fraction)` (optional) is called, serialized, as the runs
/// advance.  Results are in the order of `specs`; failures are reported in
/// RunResult::error, never thrown.
std::vector<RunResult> runAll(const std::vector<RunSpec>& specs, const HoistProfile& profile,
                              const RunOptions& opt, int jobs,
                              const std::function<void(double)>& progress = {});

/// Run `f(i)` for i in [0, count) on `jobs` threads (<= 0: hardware
/// concurrency).  The first exception thrown by any f is rethrown.
void parallelFor(int count, int jobs, const std::function<void(int)>& f);

}  // namespace hoist::study
