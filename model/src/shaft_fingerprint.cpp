// ShaftFingerprint: per-direction baseline of the depth bins' residual (hoist/shaft_fingerprint.hpp).
#include "hoist/shaft_fingerprint.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hoist {

ShaftFingerprint::ShaftFingerprint(const ConditionSettings& cond) : cond_(cond) { cond_.validate(); }

long ShaftFingerprint::binIndex(double depth_lo) const { return std::lround(depth_lo / cond_.depth_bin); }

void ShaftFingerprint::addToBaseline(Direction& d, const TripRecord& r) {
  for (const DepthBinStats& b : r.bins) {
    if (b.samples < kMinSamples) continue;
    BinStat& s = d.base[binIndex(b.depth_lo)];
    ++s.n;
    s.sum += b.resid_mean;
    s.sum2 += b.resid_mean * b.resid_mean;
  }
  ++d.base_trips;
}

void ShaftFingerprint::markBaseline(const TripRecord& r) {
  Direction& d = dir(r.direction);
  if (!d.operator_marked) {  // the operator's baseline replaces the automatic one
    d.base.clear();
    d.base_trips = 0;
    d.recent.clear();
    d.last_z.clear();
    d.operator_marked = true;
  }
  addToBaseline(d, r);
}

bool ShaftFingerprint::baselineComplete(TripDirection dd) const {
  const Direction& d = dir(dd);
  return d.operator_marked ? d.base_trips >= 2 : d.base_trips >= cond_.baseline_trips;
}

bool ShaftFingerprint::add(const TripRecord& r) {
  Direction& d = dir(r.direction);
  if (!baselineComplete(r.direction)) {
    if (!d.operator_marked) addToBaseline(d, r);
    return false;
  }
  std::map<long, double> z;
  for (const DepthBinStats& b : r.bins) {
    if (b.samples < kMinSamples) continue;
    const auto it = d.base.find(binIndex(b.depth_lo));
    if (it == d.base.end() || it->second.n < 2) continue;
    const BinStat& s = it->second;
    const double mean = s.sum / s.n;
    const double var = std::max(0.0, (s.sum2 - s.n * mean * mean) / (s.n - 1));
    const double se2 = b.resid_rms * b.resid_rms / b.samples;
    const double sd = std::sqrt(var + se2);
    if (sd > 0.0) z[it->first] = (b.resid_mean - mean) / sd;
  }
  d.last_z = z;
  d.recent.push_back(std::move(z));
  if (d.recent.size() > 3) d.recent.erase(d.recent.begin());
  return true;
}

FingerprintDecision ShaftFingerprint::decision() const {
  FingerprintDecision out;
  for (TripDirection dd : {TripDirection::Down, TripDirection::Up}) {
    const Direction& d = dir(dd);
    if (d.recent.empty()) continue;
    std::map<long, std::pair<int, double>> over;  // bin -> (trips beyond, sum |z|)
    for (const auto& trip : d.recent)
      for (const auto& [bin, z] : trip)
        if (std::abs(z) > cond_.fingerprint_sigma) {
          ++over[bin].first;
          over[bin].second += std::abs(z);
        }
    for (const auto& [bin, c] : over) {
      if (c.first < 2) continue;
      FingerprintHit h;
      h.direction = dd;
      h.depth_lo = bin * cond_.depth_bin;
      h.trips_over = c.first;
      h.strength = c.second / c.first;
      const auto it = d.recent.back().find(bin);
      h.z_last = it == d.recent.back().end() ? 0.0 : it->second;
      out.hits.push_back(h);
    }
  }
  std::stable_sort(out.hits.begin(), out.hits.end(),
                   [](const FingerprintHit& a, const FingerprintHit& b) { return a.strength > b.strength; });
  std::string where;
  for (const FingerprintHit& h : out.hits) {
    const Direction& d = dir(h.direction);
    char b[200];
    std::snprintf(b, sizeof b, "%sdepth %.0f-%.0f m (%s trips: %d of the last %zu beyond %.1f sd, last z = %.1f)",
                  where.empty() ? "" : "; also at ", h.depth_lo, h.depth_lo + cond_.depth_bin,
                  h.direction == TripDirection::Down ? "down" : "up", h.trips_over, d.recent.size(),
                  cond_.fingerprint_sigma, h.z_last);
    where += b;
  }
  out.active = !out.hits.empty();
  out.text = out.active ? "the shaft left its commissioning fingerprint at " + where +
                              ": survey the guides and steelwork there"
                        : "the shaft matches its commissioning fingerprint";
  return out;
}

}  // namespace hoist
