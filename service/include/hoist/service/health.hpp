// hoist/service/health.hpp -- timing statistics and log rate limiting for the
// daemon's health report (pure: no I/O, no clock, no allocation).
#pragma once

#include <array>
#include <cstdint>

namespace hoist::svc {

/// Histogram of durations in microseconds on fixed log-spaced bins
/// (kBinsPerDecade per decade from 0.1 us to 10 s), plus the exact maximum.
/// Quantiles are read at the geometric centre of the bin (relative error
/// below 10^(1/(2*kBinsPerDecade)) - 1, i.e. < 6 %).  add() is O(1); nothing
/// allocates.
class LatencyHistogram {
 public:
  static constexpr int kBinsPerDecade = 20;
  static constexpr double kMinUs = 0.1;
  static constexpr int kDecades = 8;  // 0.1 us .. 10 s
  static constexpr int kBins = kBinsPerDecade * kDecades + 2;  // + underflow and overflow

  void add(double us);
  void reset();
  std::int64_t count() const { return count_; }
  double max() const { return count_ ? max_ : 0.0; }
  /// q in [0, 1]; 0 when empty.  Never more than max().
  double quantile(double q) const;
  /// Raw bin counts (for reports): bin 0 holds samples below kMinUs, bin b in
  /// [1, kBins-2] holds [binLowerUs(b), binLowerUs(b+1)), the last bin the rest.
  std::int64_t binCount(int b) const { return bins_[static_cast<std::size_t>(b)]; }
  static double binLowerUs(int b);

 private:
  std::array<std::int64_t, kBins> bins_{};
  std::int64_t count_ = 0;
  double max_ = 0.0;
};

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
