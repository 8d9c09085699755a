// Can a configuration run in real time?  hoist-twind measures a tick of
// each shaft on a scratch model at start-up (hoist/service/lcm/budget.hpp) and
// sums them; this turns the measurements into the start-up log line and
// the verdict main() acts on (refuse, exit 2, unless --force).  Before the
// loop starts; nothing here runs in it.
#pragma once

#include <string>

#include "daemon.hpp"

namespace hoist::service::inline app {

struct StartupBudget {
  std::string line;   ///< "measured start-up budget: ..." (the log line; with the parts when warned)
  std::string parts;  ///< a whole tick with the cage moving, largest part first, per shaft
  bool over = false;  ///< the shafts cannot keep up (more than one core, or a tick longer than its period)
  bool warn = false;  ///< over, or more than half the period: logged as a warning
};

/// Measures every shaft of `opt`; `force`: --force (an over-budget line says
/// it runs anyway).  Throws std::exception for a configuration the
/// measurement cannot build (a configuration error).
StartupBudget measureStartupBudget(const DaemonOptions& opt, bool force);

}  // namespace hoist::service::app
