// hoist/rt/clock.hpp -- the clock helpers of the cost split: a
// steady-clock span in nanoseconds, a scoped span that adds itself to its
// accumulators, and the process's CPU time.  No
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

/// Adds the steady-clock span of its scope [ns] to every accumulator given
/// (up to three; a null one is skipped), at the end of the scope: one
/// timed phase, counted where each of its readers looks (a shaft's
/// whole-run cost, the loop's split).  Two clock reads; no allocation.
class ScopedSpan {
 public:
  explicit ScopedSpan(std::int64_t* a, std::int64_t* b = nullptr, std::int64_t* c = nullptr)
      : to_{a, b, c}, t0_(std::chrono::steady_clock::now()) {}
  ~ScopedSpan() {
    const std::int64_t ns = nanos(std::chrono::steady_clock::now() - t0_);
    for (std::int64_t* p : to_)
      if (p) *p += ns;
  }
  ScopedSpan(const ScopedSpan&) = delete;
  ScopedSpan& operator=(const ScopedSpan&) = delete;

 private:
  std::int64_t* to_[3];
  std::chrono::steady_clock::time_point t0_;
};

/// User + system CPU time of the whole process [ns] (0 if unavailable).
inline std::int64_t processCpuNanos() {
  timespec ts{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return 0;
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace hoist::rt
