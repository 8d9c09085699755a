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
  // One sentence (at most about 260 characters): an alarm text carries it
  // whole with its prefix and state.
  // What was judged: one trip's fit, or the trend over the trips it rests on.
  char head[80];
  if (v.trend_trips == 0)
    std::snprintf(head, sizeof head, "whole-trip fit: preload ");
  else if (v.first_trip > 0 && v.last_trip > v.first_trip)
    std::snprintf(head, sizeof head, "preload trend of trips %lld-%lld: ", static_cast<long long>(v.first_trip),
                  static_cast<long long>(v.last_trip));
  else if (v.last_trip > 0)
    std::snprintf(head, sizeof head, "preload trend of trip %lld: ", static_cast<long long>(v.last_trip));
  else
    std::snprintf(head, sizeof head, "preload trend of the stored trips: ");
  // The verdict: consistent, or what the mismatch means and what to do (a
  // trip's fit also names its moment).
  char fit[64] = "";
  if (v.trend_trips == 0)
    std::snprintf(fit, sizeof fit, " (fit: M = %.0f +- %.0f N m)", v.moment, std::max(v.sigma_moment, 0.0));
  char verdict[160] = "consistent";
  if (v.mismatch)
    std::snprintf(verdict, sizeof verdict, "shaft %s, moment reads %s%s; adopt (hoist-alarm-ack --adopt-preload) or "
                  "re-tension", v.z < 0.0 ? "softer" : "stiffer", v.z < 0.0 ? "high" : "low", fit);
  std::snprintf(buf, n, "%sx%.2f +- %.2f, %.1f sigma from the twin's x%.3g (bound %.3g): %s", head, v.scale,
                v.sigma_scale, std::abs(v.z), v.twin_scale, v.limit, verdict);
}

}  // namespace hoist
