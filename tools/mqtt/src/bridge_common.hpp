// bridge_common.hpp -- what every room of hoist-mqtt's bridge shares: the
// clock, and the one log budget (private to tools/mqtt; the rooms and their
// wiring: bridge.cpp).
//
// LogBudget: a few log lines per 10 s for commands and for LCM input, then
// counted (hoist/rt/log_rate_limiter.hpp).  One budget for the whole bridge
// on purpose (a flood on one path must not buy log lines on another of the
// same key); owned by Bridge, passed by reference to the rooms that log, and
// it outlives them.  Single-threaded, like the whole bridge.
#pragma once

#include <chrono>
#include <cstdint>

#include "hoist/bus/lcm_util.hpp"
#include "hoist/rt/log_rate_limiter.hpp"

namespace hoist::mqtt {

using Clock = std::chrono::steady_clock;

inline double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

/// Wall clock in milliseconds (Sparkplug timestamps).
inline std::uint64_t nowMs() { return static_cast<std::uint64_t>(hoist::bus::wallUtime() / 1000); }

struct LogBudget {
  static constexpr int kCmd = 0, kLcm = 1;
  hoist::rt::LogRateLimiter<2> limit{5, 10.0};
  Clock::time_point started = Clock::now();
  double sinceStart(Clock::time_point t) const { return std::chrono::duration<double>(t - started).count(); }
  /// True if a line of `key` may be logged at `t`; `suppressed` as LogRateLimiter::allow.
  bool allow(int key, Clock::time_point t, std::int64_t& suppressed) { return limit.allow(key, sinceStart(t), suppressed); }
};

}  // namespace hoist::mqtt
