// PreloadTrend: recursive estimate of s with a random walk (hoist/preload_trend.hpp).
#include "hoist/preload_trend.hpp"

#include <algorithm>
#include <cstdio>

namespace hoist {

namespace {
constexpr double kZ95 = 1.6448536269514722;  // one-sided 95 % quantile of the normal
constexpr double kKeepWeight = 1e-3;         // weights below are dropped (bounded memory)
constexpr double kNameWeight = 0.05;         // trips named in the text
}  // namespace

PreloadTrend::PreloadTrend(const ConditionSettings& cond) : cond_(cond) { cond_.validate(); }

bool PreloadTrend::add(const TripRecord& r) {
  const std::int64_t trip = r.trip > 0 ? r.trip : seen_ + 1;
  const std::int64_t steps = std::max<std::int64_t>(1, trip - last_trip_);
  seen_ = std::max(seen_, trip);
  const PreloadIdentification& id = r.id;
  if (!id.attempted || !id.informative || !(id.sigma_scale > 0.0) || !std::isfinite(id.scale)) return false;
  const double R = id.sigma_scale * id.sigma_scale;
  if (!valid_) {
    valid_ = true;
    s_ = id.scale;
    P_ = R;
    w_.assign(1, {trip, 1.0});
  } else {
    P_ += static_cast<double>(steps) * cond_.trend_walk * cond_.trend_walk;
    const double K = P_ / (P_ + R);
    s_ += K * (id.scale - s_);
    P_ *= 1.0 - K;
    for (auto& w : w_) w.second *= 1.0 - K;
    w_.emplace_back(trip, K);
    w_.erase(std::remove_if(w_.begin(), w_.end(), [](const auto& w) { return w.second < kKeepWeight; }), w_.end());
  }
  last_trip_ = trip;
  return true;
}

PreloadDecision PreloadTrend::decision() const {
  PreloadDecision d;
  if (!valid_) {
    d.text = "no informative trip yet: the guide-rope preload is not known from the data";
    return d;
  }
  d.valid = true;
  d.scale = s_;
  d.sigma = std::sqrt(P_);
  d.upper95 = s_ + kZ95 * d.sigma;
  std::string trips, weights;
  for (const auto& [t, w] : w_) {
    if (w < kNameWeight) continue;
    d.trips.push_back(t);
    char b[48];
    std::snprintf(b, sizeof b, "%s%lld", trips.empty() ? "" : ", ", static_cast<long long>(t));
    trips += b;
    std::snprintf(b, sizeof b, "%s%.0f %%", weights.empty() ? "" : ", ", 100.0 * w);
    weights += b;
  }
  if (d.upper95 < cond_.preload_critical) d.level = ConditionLevel::Critical;
  else if (d.upper95 < cond_.preload_warning) d.level = ConditionLevel::Warning;
  char buf[512];
  if (d.level == ConditionLevel::None) {
    std::snprintf(buf, sizeof buf,
                  "guide-rope preload scale %.3f +- %.3f (95 %% upper bound %.3f, warning below %.2f), from trips %s "
                  "(weights %s)",
                  d.scale, d.sigma, d.upper95, cond_.preload_warning, trips.c_str(), weights.c_str());
  } else {
    const double thr = d.level == ConditionLevel::Critical ? cond_.preload_critical : cond_.preload_warning;
    std::snprintf(buf, sizeof buf,
                  "guide-rope preload scale %.3f +- %.3f: below %.2f of the configured preload with 95 %% "
                  "confidence (upper bound %.3f), from trips %s (weights %s); check the tensioning weights or "
                  "hydraulic tensioners first, then survey the guide ropes",
                  d.scale, d.sigma, thr, d.upper95, trips.c_str(), weights.c_str());
  }
  d.text = buf;
  return d;
}

}  // namespace hoist
