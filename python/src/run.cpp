// One simulation run without Python (python/src/run.hpp).
#include "run.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "hoist/io/profile.hpp"
#include "hoist/plausibility.hpp"
#include "hoist/shaft_model.hpp"
#include "hoist/simulator.hpp"

namespace hoist::python {

HoistProfile ProfileSource::load(double l0) const {
  if (csv_text.empty()) return io::loadProfile(arg, l0);
  std::istringstream in(csv_text);
  return io::readProfileCsv(in, name(), l0);
}

namespace {
struct Diverged {};
}  // namespace

long expectedRows(const RunSpec& spec, const ProfileSource& profile) {
  ShaftParams p = spec.params;
  io::applySimOverrides(p, spec.options);
  const HoistProfile prof = profile.load(p.l0);
  const double t_end = io::simEndTime(prof, spec.options.t_end);
  return static_cast<long>(std::round((t_end - prof.startTime()) / spec.options.dt)) + 1;
}

RunResult runSimulation(const RunSpec& spec, const ProfileSource& profile_src, const std::atomic<bool>& cancel,
                        std::atomic<long>* steps) {
  // The same order of checks as hoist-sim (tools/sim/main.cpp).
  RunResult res;
  ShaftParams p = spec.params;
  io::applySimOverrides(p, spec.options);
  HoistProfile profile = profile_src.load(p.l0);
  if (spec.estop)
    profile = io::estopRun(profile, spec.options.t_end, spec.estop_at, spec.estop_decel, spec.estop_jerk,
                           spec.options.dt);
  const double t0 = profile.startTime();
  const double t_end = io::simEndTime(profile, spec.options.t_end);
  io::checkSimulatedPartInShaft(profile, p, t_end, spec.options.dt, profile_src.name());
  const SimulationOptions sim = io::simulationOptions(spec.options, p, t_end, res.substeps);
  std::vector<double> shape_times = spec.shape_times;
  std::sort(shape_times.begin(), shape_times.end());
  for (double ts : shape_times)
    if (!std::isfinite(ts) || ts < t0 - 1e-9 || ts > t_end + 1e-9)
      throw io::OptionError("shape_times: " + std::to_string(ts) + " s is outside the run [" + std::to_string(t0) +
                            ", " + std::to_string(t_end) + "] s");
  if (spec.shape_points < 2 || spec.shape_points > 100000)
    throw io::OptionError("shape_points: must be in [2, 100000], got " + std::to_string(spec.shape_points));

  const auto rows = static_cast<std::size_t>(std::round((t_end - t0) / spec.options.dt)) + 1;
  for (auto& c : res.columns) c.reserve(rows);
  auto model = std::make_shared<const ShaftModel>(p);
  auto solver = makeSolver(sim.method, model);
  const VectorXd xs = VectorXd::LinSpaced(spec.shape_points, 0.0, p.L);
  VectorXd y1(xs.size()), y2(xs.size());
  std::size_t next_shape = 0;
  const PlausibilityBounds bounds = plausibilityBounds(p, 1.0);
  const char* implausible_what = nullptr;
  double implausible_value = 0.0, implausible_limit = 0.0, fail_t = 0.0;
  bool failed = false;
  try {
    simulate(*solver, profile, sim, [&](const CageResponse& r) {
      if (cancel.load(std::memory_order_relaxed)) throw Cancelled{};
      if (!solver->finite() || !std::isfinite(r.y_c) || !std::isfinite(r.theta) || !std::isfinite(r.x_c)) {
        failed = true;
        fail_t = r.t;
        throw Diverged{};
      }
      implausible_what = implausible(r, p.h, bounds, implausible_value, implausible_limit);
      if (implausible_what) {
        failed = true;
        fail_t = r.t;
        throw Diverged{};
      }
      const double row[12] = {r.t,      r.kin.l,      r.kin.v,      r.kin.a,      r.x_c,        r.y_c,
                              r.theta,  r.lambda[0],  r.lambda[1],  r.lambda[2],  r.lambda[3],  r.lambda[4]};
      for (std::size_t k = 0; k < 12; ++k) res.columns[k].push_back(row[k]);
      while (next_shape < shape_times.size() && r.t >= shape_times[next_shape] - 0.5 * spec.options.dt) {
        solver->guideRopeShapes(xs, y1, y2);
        for (Eigen::Index i = 0; i < xs.size(); ++i) {
          res.shapes[0].push_back(r.t);
          res.shapes[1].push_back(xs[i]);
          res.shapes[2].push_back(y1[i]);
          res.shapes[3].push_back(y2[i]);
        }
        ++next_shape;
      }
      if (steps) steps->fetch_add(1, std::memory_order_relaxed);
    });
  } catch (const Diverged&) {
  } catch (const std::domain_error& e) {
    throw RunError(std::string("the model left its domain: ") + e.what());
  }
  if (failed) {
    std::ostringstream s;
    if (implausible_what)
      s << "implausible state at t = " << fail_t << " s: " << implausible_what << " = " << implausible_value
        << " (plausible: |" << implausible_what << "| <= " << implausible_limit << "; valid rope lengths are ["
        << validLengthRange(p).lo << ", " << validLengthRange(p).hi << "] m)";
    else
      s << "the state became non-finite at t = " << fail_t
        << " s (unstable parameters or step; try a smaller dt / max_step)";
    throw RunError(s.str());
  }
  res.params = p;
  return res;
}

}  // namespace hoist::python
