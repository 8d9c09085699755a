// hoist-sim's run: check the options against the configuration and the
// profile, then load, set up, solve and write (the phases timed in the
// summary; see main.cpp for the program's contract and exit statuses).
// Called once by main() after parsing; throws UsageError / hoist::io errors
// for bad input (main maps them to exit 2) and returns 1 when the run failed
// (non-finite or implausible state), 0 otherwise.
#pragma once

#include "sim_options.hpp"

namespace hoist::sim {

int run(const Options& o);

}  // namespace hoist::sim
