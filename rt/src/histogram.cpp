// The one latency histogram: see hoist/rt/histogram.hpp.
#include "hoist/rt/histogram.hpp"

#include <algorithm>
#include <cmath>

namespace hoist::rt {

void LatencyHistogram::add(double us) {
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

void LatencyHistogram::reset() {
  bins_.fill(0);
  count_ = 0;
  max_ = min_ = sum_ = 0.0;
}

void LatencyHistogram::merge(const LatencyHistogram& o) {
  if (o.count_ == 0) return;
  for (std::size_t b = 0; b < bins_.size(); ++b) bins_[b] += o.bins_[b];
  max_ = count_ ? std::max(max_, o.max_) : o.max_;
  min_ = count_ ? std::min(min_, o.min_) : o.min_;
  sum_ += o.sum_;
  count_ += o.count_;
}

double LatencyHistogram::binLowerUs(int b) {
  if (b <= 0) return 0.0;
  return kMinUs * std::pow(10.0, static_cast<double>(b - 1) / kPerDecade);
}

double LatencyHistogram::quantile(double q) const {
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

}  // namespace hoist::rt
