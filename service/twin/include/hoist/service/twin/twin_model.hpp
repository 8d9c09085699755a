// hoist/service/twin/twin_model.hpp -- the model a TwinCore runs, as one object
// that can be built off the real-time loop and swapped in (issue 32: an
// operator adopts the guide-rope preload the shaft's memory identified;
// docs/condition.md "Adopting the identified preload").
//
// A TwinModel is the shaft's parameters with both guide-rope preloads
// (Tb1, Tb2) scaled by `preload_scale`, and everything the twin derives from
// them: the solver, the deflection envelope and the shape grid, the
// plausibility bounds, and the load estimator's unit-load solvers.  Build
// it with buildTwinModel() (allocates: a worker thread or start-up), hand it
// to TwinCore::adoptModel() on the loop (allocation-free: pointers and
// buffers are swapped), and release what adoptModel() hands back off the
// loop again.
#pragma once

#include <memory>

#include "hoist/guide_rope_envelope.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/plausibility.hpp"
#include "hoist/service/core/config.hpp"
#include "hoist/solver.hpp"

namespace hoist::service::inline twin {

struct TwinModel {
  TwinModel(double scale, std::unique_ptr<Solver> s, int envelope_points, int shape_points)
      : preload_scale(scale),
        shaft(s->model().params()),
        solver(std::move(s)),
        envelope(solver->model(), envelope_points),
        shape(solver->model(), shape_points) {}

  double preload_scale = 1.0;        ///< both guide-rope preloads times this (1 = the config's)
  ShaftParams shaft;                 ///< the shaft the solver runs (Tb1, Tb2 scaled)
  std::unique_ptr<Solver> solver;    ///< the fast solver of `shaft`
  GuideRopeEnvelope envelope, shape; ///< [service] envelope_points, shape_points
  PlausibilityBounds bounds;         ///< the twin's plausibility bounds for `shaft`
  LoadEstimator::Model estimator;    ///< its unit-load solvers ([estimator] enabled; else empty)
};

/// `shaft` with both guide-rope preloads (Tb1, Tb2) times `scale`: the one
/// definition of an adopted preload (the twin's model and the forecasts').
ShaftParams withPreloadScale(ShaftParams shaft, double scale);

/// The model of `cfg`'s shaft with both guide-rope preloads times `scale`
/// (> 0; the operator's bounds are the contract's kMinPreloadScale ..
/// kMaxPreloadScale).  Allocates.  Throws ParamError / std::invalid_argument
/// for parameters the model refuses.
std::unique_ptr<TwinModel> buildTwinModel(const TwinConfig& cfg, double scale);

/// The twin's plausibility bounds for `cfg` with shaft `shaft`.
PlausibilityBounds twinPlausibilityBounds(const TwinConfig& cfg, const ShaftParams& shaft);

}  // namespace hoist::service::twin
