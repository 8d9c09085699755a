// hoist/service/budget.hpp -- does a configuration fit its period?  The
// daemon measures the cost of one tick of the ACTUAL configuration (model
// size, substeps, envelope) at start-up, on a scratch TwinCore fed a
// constant-speed trip, before it runs (issue 12, section 4).
#pragma once

#include "hoist/service/config.hpp"

namespace hoist::svc {

struct TickBudget {
  int ticks = 0;           ///< ticks measured
  double tick_us = 0.0;    ///< mean cost of one tick [us] (after warm-up)
  double max_us = 0.0;     ///< slowest measured tick [us]
  double period_us = 0.0;  ///< 1e6 / service.rate
  double use = 0.0;        ///< tick_us / period_us (fraction of one core)
};

/// Measure at most `max_ticks` ticks, stopping early after `max_seconds`
/// (at least 3 ticks).  Throws what TwinCore throws for a bad configuration.
TickBudget measureTickBudget(const TwinConfig& cfg, int max_ticks = 200, double max_seconds = 0.3);

}  // namespace hoist::svc
