// hoist/service/core/health.hpp -- the names the daemon's health report uses from
// hoist_rt: the latency histogram and the log rate limiter.
#pragma once

#include "hoist/rt/histogram.hpp"
#include "hoist/rt/log_rate_limiter.hpp"

namespace hoist::service::inline core {

/// The step-time and lateness histogram: the project's one histogram type
/// (hoist/rt/histogram.hpp), shared with hoist-replay --timing-test.
using LatencyHistogram = hoist::rt::LatencyHistogram;

/// The log rate limiter of the daemon's rooms (hoist/rt/log_rate_limiter.hpp).
using hoist::rt::LogRateLimiter;

}  // namespace hoist::service::core
