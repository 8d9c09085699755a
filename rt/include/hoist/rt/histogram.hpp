// hoist/rt/histogram.hpp -- the project's one latency histogram: the
// daemon's step time and tick lateness (HOIST_HEALTH, --report) and
// hoist-replay --timing-test's end-to-end latencies use the same type.
//
// Fixed log-spaced bins, kPerDecade per decade from kMinUs = 0.1 us to
// 100 s, plus an underflow and an overflow bin; the exact minimum, maximum
// and sum are kept.  Quantiles use the nearest-rank definition and are read
// at the geometric centre of the bin, clamped to [min, max]: relative error
// below 10^(1/(2 kPerDecade)) - 1 (< 1.2 %).  add() is O(1); nothing
// allocates (7 KB of counters, inline).
#pragma once

#include <array>
#include <cstdint>

namespace hoist::rt {

class LatencyHistogram {
 public:
  static constexpr int kPerDecade = 100;
  static constexpr double kMinUs = 0.1;
  static constexpr int kDecades = 9;  // 0.1 us .. 100 s
  static constexpr int kBins = kPerDecade * kDecades + 2;  // + underflow and overflow

  void add(double us);
  void reset();
  void merge(const LatencyHistogram& o);
  std::int64_t count() const { return count_; }
  double max() const { return count_ ? max_ : 0.0; }
  double min() const { return count_ ? min_ : 0.0; }
  double mean() const { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }
  /// q in [0, 1]; 0 when empty; within [min(), max()].
  double quantile(double q) const;
  /// Raw bin counts (for reports): bin 0 holds samples below kMinUs, bin b in
  /// [1, kBins-2] holds [binLowerUs(b), binLowerUs(b+1)), the last bin the rest.
  std::int64_t binCount(int b) const { return bins_[static_cast<std::size_t>(b)]; }
  static double binLowerUs(int b);

 private:
  std::array<std::int64_t, kBins> bins_{};
  std::int64_t count_ = 0;
  double max_ = 0.0, min_ = 0.0, sum_ = 0.0;
};

}  // namespace hoist::rt
