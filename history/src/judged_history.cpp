// The stored trips a shaft's condition is judged from: see judged_history.hpp.
#include "hoist/history/judged_history.hpp"

#include <algorithm>

namespace hoist::history {

JudgedHistory readJudgedHistory(Store& db, const std::string& shaft, const ConditionSettings& cond) {
  JudgedHistory h;
  h.marks = db.baseline(shaft);
  h.last_trip = db.nextTrip(shaft) - 1;
  if (h.last_trip <= 0) return h;
  ListFilter f;
  f.shaft = shaft;
  f.with_bins = true;
  const std::int64_t window = cond.seed_trips;
  const std::int64_t from = window > 0 && h.last_trip > window ? h.last_trip - window + 1 : 0;
  f.from_trip = from;
  h.trips = db.list(f);
  if (from == 0) return h;  // the whole history
  h.windowed = true;
  const auto before = [&](std::int64_t trip) { return trip < from; };
  if (!h.marks.empty()) {
    for (std::int64_t m : h.marks)
      if (before(m))
        if (auto r = db.get(shaft, m)) h.baseline.push_back(std::move(*r));
    return h;
  }
  // The automatic baseline: the first baseline_trips trips of each direction
  // (pruned trips are gone: the oldest stored ones), found a page of rows
  // without bins at a time, then read with their bins.
  int down = 0, up = 0;
  const int need = cond.baseline_trips;
  ListFilter page;
  page.shaft = shaft;
  page.to_trip = from - 1;
  page.limit = 4 * static_cast<std::int64_t>(need);
  std::vector<std::int64_t> wanted;
  for (std::int64_t next = 1; (down < need || up < need) && next < from;) {
    page.from_trip = next;
    const std::vector<TripRecord> rows = db.list(page);
    if (rows.empty()) break;
    for (const TripRecord& r : rows) {
      int& n = r.direction == TripDirection::Down ? down : up;
      if (n < need) {
        ++n;
        wanted.push_back(r.trip);
      }
    }
    next = rows.back().trip + 1;
  }
  for (std::int64_t trip : wanted)
    if (auto r = db.get(shaft, trip)) h.baseline.push_back(std::move(*r));
  return h;
}

void primeFingerprint(const std::vector<TripRecord>& baseline, const std::vector<TripRecord>& window,
                      const std::vector<std::int64_t>& marks, ShaftFingerprint& finger) {
  const auto marked = [&](std::int64_t trip) { return std::binary_search(marks.begin(), marks.end(), trip); };
  for (const auto& r : baseline) {
    if (marked(r.trip)) finger.markBaseline(r);
    else finger.add(r);
  }
  for (const auto& r : window)
    if (marked(r.trip)) finger.markBaseline(r);
}

}  // namespace hoist::history
