// hoist/rt/log_rate_limiter.hpp -- at most N log lines per key per time
// window; the rest are counted so that the next allowed line can say how
// many were suppressed.  Pure: no I/O, no clock (the caller passes the
// time), no allocation; one instance per thread.
#pragma once

#include <array>
#include <cstdint>

namespace hoist::rt {

/// `Keys` independent keys (e.g. one per rejection reason), each allowing
/// `per_window` lines per `window` seconds (default: per second).
template <int Keys>
class LogRateLimiter {
 public:
  explicit LogRateLimiter(int per_window = 5, double window = 1.0) : limit_(per_window), window_(window) {}
  void setLimit(int per_window) { limit_ = per_window; }
  /// True if a line for `key` may be logged at time `now` [s].  When it
  /// returns true, `suppressed` is set to the number of lines suppressed since
  /// the last allowed one (and reset).
  bool allow(int key, double now, std::int64_t& suppressed) {
    auto& s = st_[key];
    if (now - s.window_start >= window_ || now < s.window_start) {
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
    double window_start = -1e300;  ///< start of the key's current window [s]
    int used = 0;                  ///< lines allowed in it
    std::int64_t suppressed = 0;   ///< lines suppressed since the last allowed one
  };
  int limit_;      ///< lines per window and key
  double window_;  ///< window length [s]
  std::array<State, Keys> st_{};
};

}  // namespace hoist::rt
