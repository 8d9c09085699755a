#include "hoist/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hoist/fast_solver.hpp"
#include "hoist/paper_solver.hpp"

namespace hoist {

int substepsFor(const SimulationOptions& opt) {
  if (!(opt.max_step >= 0.0) || !std::isfinite(opt.max_step))
    throw std::invalid_argument("simulate: max_step must be >= 0");
  if (opt.max_step >= opt.dt) return 1;
  try {
    return substepCount(opt.dt, opt.max_step, 1000000);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("simulate: dt / max_step exceeds 1e6 substeps");
  }
}

void simulate(Solver& solver, const HoistProfile& profile, const SimulationOptions& opt,
              const std::function<void(const CageResponse&)>& sink, const std::function<void(double)>& progress) {
  if (profile.empty()) throw std::invalid_argument("simulate: empty profile");
  if (!(opt.dt > 0.0) || !std::isfinite(opt.dt)) throw std::invalid_argument("simulate: dt must be > 0");
  const double t0 = profile.startTime();
  const double t_end = opt.t_end < 0 ? profile.endTime() : opt.t_end;
  const long steps = std::lround((t_end - t0) / opt.dt);
  if (steps < 0) throw std::invalid_argument("simulate: t_end before the profile start");
  solver.initialize(t0, profile.at(t0), opt.initial);
  if (sink) sink(solver.response());
  const long every = std::max(1L, steps / 100);
  const int sub = substepsFor(opt);
  for (long k = 1; k <= steps; ++k) {
    const double t = t0 + static_cast<double>(k) * opt.dt;
    for (int j = 1; j < sub; ++j) {
      const double ts = t0 + (static_cast<double>(k - 1) + static_cast<double>(j) / sub) * opt.dt;
      solver.step(ts, profile.at(ts));
    }
    solver.step(t, profile.at(t));
    if (sink) sink(solver.response());
    if (progress && k % every == 0) progress(static_cast<double>(k) / static_cast<double>(steps));
  }
  if (progress) progress(1.0);
}

}  // namespace hoist
