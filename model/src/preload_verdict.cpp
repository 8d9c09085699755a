// MODEL_MISMATCH's trip-end preload test (hoist/preload_verdict.hpp).
#include "hoist/preload_verdict.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hoist {

PreloadVerdict judgeTripPreload(const PreloadIdentification& id, double twin_scale, double limit) {
  PreloadVerdict v;
  v.limit = limit;
  v.twin_scale = twin_scale;
  v.scale = id.scale;
  v.moment = id.moment;
  v.sigma_moment = id.sigma_moment;
  if (!id.attempted || !(id.sigma_scale > 0.0) || !std::isfinite(id.scale) || !std::isfinite(id.sigma_scale) ||
      !(twin_scale > 0.0))
    return v;
  v.judged = true;
  v.sigma_scale = id.sigma_scale;
  v.z = (id.scale - twin_scale) / id.sigma_scale;
  v.mismatch = std::abs(v.z) > limit;
  return v;
}

PreloadVerdict judgeTrendPreload(const PreloadDecision& d, double twin_scale, double limit) {
  PreloadVerdict v;
  v.limit = limit;
  v.twin_scale = twin_scale;
  v.scale = d.scale;
  v.trend_trips = static_cast<int>(d.trips.size());
  if (!d.trips.empty()) {
    v.first_trip = d.trips.front();
    v.last_trip = d.trips.back();
  }
  if (!d.valid || !(d.sigma > 0.0) || !std::isfinite(d.scale) || !std::isfinite(d.sigma) || !(twin_scale > 0.0))
    return v;
  v.judged = true;
  v.trend_trips = std::max(v.trend_trips, 1);
  v.sigma_scale = d.sigma;
  v.z = (d.scale - twin_scale) / d.sigma;
  v.mismatch = std::abs(v.z) > limit;
  return v;
}

void describe(const PreloadVerdict& v, char* buf, std::size_t n) {
  if (n == 0) return;
  if (!v.judged) {
    std::snprintf(buf, n, "the trip did not identify the guide-rope preload: nothing judged");
    return;
  }
  // Short enough for alarm_t.message (255 bytes) with its prefix and " [unacknowledged]".
  if (v.trend_trips > 0) {
    char from[64];
    if (v.first_trip > 0 && v.last_trip > v.first_trip)
      std::snprintf(from, sizeof from, "trips %lld-%lld", static_cast<long long>(v.first_trip),
                    static_cast<long long>(v.last_trip));
    else if (v.last_trip > 0)
      std::snprintf(from, sizeof from, "trip %lld", static_cast<long long>(v.last_trip));
    else
      std::snprintf(from, sizeof from, "the stored trips");
    if (v.mismatch)
      std::snprintf(buf, n,
                    "preload trend of %s: x%.2f +- %.2f, %.1f sigma from the twin's x%.3g (bound %.3g): shaft %s, "
                    "moment reads %s; adopt (hoist-alarm-ack --adopt-preload) or re-tension",
                    from, v.scale, v.sigma_scale, std::abs(v.z), v.twin_scale, v.limit,
                    v.z < 0.0 ? "softer" : "stiffer", v.z < 0.0 ? "high" : "low");
    else
      std::snprintf(buf, n, "preload trend of %s: x%.2f +- %.2f, %.1f sigma from the twin's x%.3g (bound %.3g): consistent",
                    from, v.scale, v.sigma_scale, std::abs(v.z), v.twin_scale, v.limit);
    return;
  }
  if (v.mismatch)
    std::snprintf(buf, n,
                  "whole-trip fit: preload x%.2f +- %.2f, %.1f sigma from the twin's x%.3g (bound %.3g): shaft %s, "
                  "moment reads %s (fit: M = %.0f +- %.0f N m); adopt (hoist-alarm-ack --adopt-preload) or "
                  "re-tension",
                  v.scale, v.sigma_scale, std::abs(v.z), v.twin_scale, v.limit, v.z < 0.0 ? "softer" : "stiffer",
                  v.z < 0.0 ? "high" : "low", v.moment, std::max(v.sigma_moment, 0.0));
  else
    std::snprintf(buf, n,
                  "whole-trip fit: preload x%.2f +- %.2f, %.1f sigma from the twin's x%.3g (bound %.3g): consistent",
                  v.scale, v.sigma_scale, std::abs(v.z), v.twin_scale, v.limit);
}

}  // namespace hoist
