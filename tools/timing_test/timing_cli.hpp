// timing_cli.hpp -- the command line of the timing test: hoist-timing-test,
// and its alias hoist-replay --timing-test.
#pragma once

#include <string>
#include <vector>

namespace hoist::replay {

/// Parse the timing test's options (argv[0] is the program) and run it.
/// `program` names it in messages and --help ("hoist-timing-test").
/// Returns the exit status (timing_test.hpp; 2 for bad options).
int timingTestMain(int argc, char** argv, const std::string& program);

/// The options only the timing test takes (for hoist-replay's message when
/// one is given without --timing-test).
const std::vector<std::string>& timingOnlyOptions();

}  // namespace hoist::replay
