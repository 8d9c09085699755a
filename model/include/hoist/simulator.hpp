// hoist/simulator.hpp -- run a solver over a whole profile (offline use).
#pragma once

#include <functional>
#include <vector>

#include "hoist/solver.hpp"

namespace hoist {

struct SimulationOptions {
  double dt = 0.01;          ///< fixed output step [s]
  /// Largest integration step [s]; each output step is split into
  /// ceil(dt / max_step) equal substeps.  0: integrate with dt itself.
  double max_step = 0.0;
  double t_end = -1.0;       ///< < 0: the profile's end time
  Method method = Method::Fast;
  InitialState initial = InitialState::Static;
};

/// Steps `solver` over `profile` from its start time with fixed step dt
/// (substepped per max_step); calls `sink` with the response at t0 and after
/// every output step.  `progress`
/// (optional) gets the fraction done, about 100 times per run.
/// Number of substeps simulate() takes per output step.
int substepsFor(const SimulationOptions& opt);

void simulate(Solver& solver, const HoistProfile& profile, const SimulationOptions& opt,
              const std::function<void(const CageResponse&)>& sink,
              const std::function<void(double)>& progress = {});

}  // namespace hoist
