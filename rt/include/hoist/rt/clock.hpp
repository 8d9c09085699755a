// hoist/rt/clock.hpp -- the two clock helpers of the cost split: a
// steady-clock span in nanoseconds and the process's CPU time.  No
// allocation, no lock (clock_gettime is a vDSO call).
#pragma once

#include <chrono>
#include <cstdint>
#include <ctime>

namespace hoist::rt {

/// Steady-clock span in nanoseconds.
inline std::int64_t nanos(std::chrono::steady_clock::duration d) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count();
}

/// User + system CPU time of the whole process [ns] (0 if unavailable).
inline std::int64_t processCpuNanos() {
  timespec ts{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return 0;
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace hoist::rt
