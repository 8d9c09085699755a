// timing_stats.hpp -- hoist-replay --timing-test's latency histogram is the
// project's one histogram type (hoist/rt/histogram.hpp), the daemon's too.
#pragma once

#include "hoist/rt/histogram.hpp"

namespace hoist::replay {

using Histogram = hoist::rt::LatencyHistogram;

}  // namespace hoist::replay
