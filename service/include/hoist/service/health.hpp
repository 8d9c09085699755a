// hoist/service/health.hpp -- timing statistics and log rate limiting for the
// daemon's health report (pure: no I/O, no clock, no allocation).
#pragma once

#include <array>
#include <cstdint>

#include "hoist/rt/histogram.hpp"

namespace hoist::svc {

/// The step-time and lateness histogram: the project's one histogram type
/// (hoist/rt/histogram.hpp), shared with hoist-replay --timing-test.
using LatencyHistogram = hoist::rt::LatencyHistogram;

/// At most `per_second` log lines per key per one-second window; the rest are
/// counted so the next allowed line can say how many were suppressed.
template <int Keys>
class LogRateLimiter {
 public:
  explicit LogRateLimiter(int per_second = 5) : limit_(per_second) {}
  void setLimit(int per_second) { limit_ = per_second; }
  /// True if a line for `key` may be logged at time `now` [s].  When it
  /// returns true, `suppressed` is set to the number of lines suppressed since
  /// the last allowed one (and reset).
  bool allow(int key, double now, std::int64_t& suppressed) {
    auto& s = st_[key];
    if (now - s.window_start >= 1.0 || now < s.window_start) {
      s.window_start = now;
      s.used = 0;
    }
    if (s.used < limit_) {
      ++s.used;
      suppressed = s.suppressed;
      s.suppressed = 0;
      return true;
    }
    ++s.suppressed;
    return false;
  }
  std::int64_t pending(int key) const { return st_[key].suppressed; }

 private:
  struct State {
    double window_start = -1e300;
    int used = 0;
    std::int64_t suppressed = 0;
  };
  int limit_;
  std::array<State, Keys> st_{};
};

}  // namespace hoist::svc
