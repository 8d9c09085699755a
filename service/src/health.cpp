// Timing statistics: see hoist/service/health.hpp.
#include "hoist/service/health.hpp"

#include <algorithm>
#include <cmath>

namespace hoist::svc {

void LatencyHistogram::add(double us) {
  if (!std::isfinite(us)) us = 1e300;
  if (us < 0.0) us = 0.0;
  int bin;
  if (us < kMinUs) {
    bin = 0;
  } else {
    const double pos = std::log10(us / kMinUs) * kBinsPerDecade;
    bin = 1 + static_cast<int>(std::min(pos, static_cast<double>(kBins - 2)));
  }
  ++bins_[static_cast<std::size_t>(bin)];
  if (count_ == 0 || us > max_) max_ = us;
  ++count_;
}

void LatencyHistogram::reset() {
  bins_.fill(0);
  count_ = 0;
  max_ = 0.0;
}

double LatencyHistogram::binLowerUs(int b) {
  if (b <= 0) return 0.0;
  return kMinUs * std::pow(10.0, static_cast<double>(b - 1) / kBinsPerDecade);
}

double LatencyHistogram::quantile(double q) const {
  if (count_ == 0) return 0.0;
  q = std::clamp(q, 0.0, 1.0);
  // Rank of the wanted sample (1-based), nearest-rank definition.
  const auto rank = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(q * static_cast<double>(count_))));
  std::int64_t seen = 0;
  for (int b = 0; b < kBins; ++b) {
    seen += bins_[static_cast<std::size_t>(b)];
    if (seen >= rank) {
      if (b == 0) return std::min(kMinUs * 0.5, max_);
      if (b == kBins - 1) return max_;  // overflow bin
      const double centre = kMinUs * std::pow(10.0, (static_cast<double>(b - 1) + 0.5) / kBinsPerDecade);
      return std::min(centre, max_);
    }
  }
  return max_;
}

}  // namespace hoist::svc
