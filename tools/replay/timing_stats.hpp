// timing_stats.hpp -- a fixed-size latency histogram for hoist-replay
// --timing-test (no allocation after construction, O(1) add).
//
// Log-spaced bins, kPerDecade per decade from 0.1 us to 100 s, plus an
// underflow and an overflow bin; the exact minimum and maximum are kept.
// Quantiles use the nearest-rank definition and are read at the geometric
// centre of the bin, clamped to [min, max]: relative error below
// 10^(1/(2 kPerDecade)) - 1, i.e. < 1.2 %.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace hoist::replay {

class Histogram {
 public:
  static constexpr int kPerDecade = 100;
  static constexpr double kMinUs = 0.1;
  static constexpr int kDecades = 9;  // 0.1 us .. 100 s
  static constexpr int kBins = kPerDecade * kDecades + 2;

  void add(double us) {
    if (!std::isfinite(us)) us = 1e300;
    if (us < 0.0) us = 0.0;
    int bin;
    if (us < kMinUs) {
      bin = 0;
    } else {
      const double pos = std::log10(us / kMinUs) * kPerDecade;
      bin = 1 + static_cast<int>(std::min(pos, static_cast<double>(kBins - 2)));
    }
    ++bins_[static_cast<std::size_t>(bin)];
    if (count_ == 0 || us > max_) max_ = us;
    if (count_ == 0 || us < min_) min_ = us;
    sum_ += us;
    ++count_;
  }
  void merge(const Histogram& o) {
    if (o.count_ == 0) return;
    for (int b = 0; b < kBins; ++b) bins_[static_cast<std::size_t>(b)] += o.bins_[static_cast<std::size_t>(b)];
    max_ = count_ ? std::max(max_, o.max_) : o.max_;
    min_ = count_ ? std::min(min_, o.min_) : o.min_;
    sum_ += o.sum_;
    count_ += o.count_;
  }
  std::int64_t count() const { return count_; }
  double max() const { return count_ ? max_ : 0.0; }
  double min() const { return count_ ? min_ : 0.0; }
  double mean() const { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }
  /// q in [0, 1]; 0 when empty.
  double quantile(double q) const {
    if (count_ == 0) return 0.0;
    q = std::clamp(q, 0.0, 1.0);
    const auto rank =
        std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(q * static_cast<double>(count_))));
    std::int64_t seen = 0;
    for (int b = 0; b < kBins; ++b) {
      seen += bins_[static_cast<std::size_t>(b)];
      if (seen < rank) continue;
      if (b == 0) return min_;
      if (b == kBins - 1) return max_;
      const double centre = kMinUs * std::pow(10.0, (static_cast<double>(b - 1) + 0.5) / kPerDecade);
      return std::clamp(centre, min_, max_);
    }
    return max_;
  }

 private:
  std::array<std::int64_t, kBins> bins_{};
  std::int64_t count_ = 0;
  double max_ = 0.0, min_ = 0.0, sum_ = 0.0;
};

}  // namespace hoist::replay
