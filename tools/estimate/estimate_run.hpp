// hoist-estimate's run (tools/estimate/main.cpp: parse -> check -> run):
// the estimator over the checked input, one output row per measurement row,
// the offset file, and the one-paragraph summary (with each trip's preload
// detectability and MODEL_MISMATCH's trip-end test) on stdout.
#pragma once

#include <chrono>

#include "estimate_check.hpp"
#include "estimate_options.hpp"

namespace hoist::estimate {

/// Runs the estimate of `in` as `o` asks; `started` is when the program
/// began reading its input (the summary's time).  Returns the exit status
/// (0).  Throws hoist::io::WriteError (an output file) or std::runtime_error
/// (the model left its domain): exit status 1.
int run(const Options& o, const Input& in, std::chrono::steady_clock::time_point started);

}  // namespace hoist::estimate
