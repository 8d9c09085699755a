// hoist/service/lcm/budget.hpp -- does a configuration fit its period?  The
// daemon measures the cost of one WHOLE tick of the actual configuration at
// start-up, before it runs, on a scratch TwinCore fed a synthetic trip with
// the cage moving (at [forecast] vmax, the acceleration swinging by
// [forecast] amax): the model step with its substeps, the guide-rope
// envelope of the deflection alarm (exact or bounded, as the moving cage
// needs it), the load estimator when enabled, and the publication work of
// the tick -- the cage message every cage period and the guide-rope shape
// (evaluated on shape_points depths and encoded) every shape period,
// amortized over the ticks.  A configuration measured at rest passed with a
// shape published every tick on 20 001 envelope points, then missed most
// ticks once the cage moved.
#pragma once

#include <string>

#include "hoist/service/core/config.hpp"

namespace hoist::service::inline lcm {

struct TickBudget {
  int ticks = 0;           ///< ticks measured
  double tick_us = 0.0;    ///< mean cost of one whole tick [us] (after warm-up): step + publication
  double max_us = 0.0;     ///< slowest measured model step [us]
  double period_us = 0.0;  ///< 1e6 / service.rate
  double use = 0.0;        ///< tick_us / period_us (fraction of one core)
  // The parts of tick_us [us per tick]:
  double step_us = 0.0;      ///< model step with substeps, envelope and estimator (mean)
  double envelope_us = 0.0;  ///< ... of which the guide-rope envelope (mean)
  double cage_us = 0.0;      ///< cage message (and estimate) encoding, amortized over the ticks
  double shape_us = 0.0;     ///< guide-rope shape evaluation and encoding, amortized over the ticks
  double shape_each_us = 0.0;     ///< one shape publication [us]
  double envelope_exact = 0.0;    ///< fraction of the envelope evaluations that were exact
  double moved_m = 0.0;           ///< how far the synthetic trip moved the cage [m]
  double exact_us = 0.0;          ///< one exact evaluation of the guide-rope envelope [us]
  double worst_us = 0.0;          ///< the slowest tick: step + exact envelope + shape + cage message [us]
};

/// Exact envelope evaluations a second of model time the budget assumes while
/// the cage moves (with envelope_tolerance > 0): the paper's trip needs about
/// 6 a second at 100 Hz and at 1 kHz alike (the bound fails as the state
/// drifts, whatever the rate).
inline constexpr double kExactPerSecond = 10.0;

/// Measure at most `max_ticks` ticks, stopping early after `max_seconds`
/// (at least 3 ticks).  tick_us is the mean whole tick: the measured step
/// (with the envelope as the moving cage needed it), the exact envelope at
/// kExactPerSecond (every tick with envelope_tolerance = 0) beyond the exact
/// evaluations measured, the cage and shape publications at their rates.
/// A configuration fits when the summed use of its shafts is at most 1 and
/// no shaft's worst_us exceeds its period (a tick that needs the exact
/// envelope would miss deadlines, and the catch-up that follows drifts
/// further from the bound: more exact evaluations).  Throws what TwinCore
/// throws for a bad configuration.
TickBudget measureTickBudget(const TwinConfig& cfg, int max_ticks = 200, double max_seconds = 0.3);

/// The parts of a measured tick, each with the configuration keys that set
/// its cost, largest first: "step 850 us ([model] modes = 400, [service]
/// rate = 1000 Hz, max_step = 0.0025 s: 1 substep; of it the envelope 600 us:
/// [service] envelope_points = 20001, envelope_tolerance = 0.01), shape 1200
/// us per tick ([service] shape_rate = 1000 Hz, shape_points = 101), ...".
std::string describeBudget(const TickBudget& b, const TwinConfig& cfg);

}  // namespace hoist::service::lcm
