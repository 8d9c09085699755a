// hoist-test-history-fill DB FIRST LAST [--preload-step TRIP] -- writes
// trips FIRST..LAST of the default shaft into the SQLite history database DB
// with the Store (hoist/history/store.hpp), for the dashboard's Shaft
// condition tests (condition_test.mjs, dash_condition_test).  The records
// are sampleRecord()'s (tests/history/sample_record.hpp: every field set)
// with an identified preload scale of 1.0 +- 0.03, or 0.6 +- 0.03 from
// trip TRIP on (a slack guide rope: GUIDE_PRELOAD_LOW CRITICAL), and a
// residual that grows at 300 m from that trip (the heat map's spot).
#include <cstdio>
#include <cstdlib>
#include <string>

#include "hoist/history/sqlite_store.hpp"
#include "sample_record.hpp"

int main(int argc, char** argv) {
  if (argc != 4 && argc != 6) {
    std::fprintf(stderr, "usage: hoist-test-history-fill DB FIRST LAST [--preload-step TRIP]\n");
    return 2;
  }
  const long first = std::atol(argv[2]), last = std::atol(argv[3]);
  const long step = argc == 6 ? std::atol(argv[5]) : 0;
  auto s = hoist::history::openSqliteStore(argv[1]);
  for (long t = first; t <= last; ++t) {
    hoist::TripRecord r = hoist::test::sampleRecord(t, "", 40);
    const bool slack = step > 0 && t >= step;
    r.id.scale = (slack ? 0.6 : 1.0) + 0.03 * std::sin(1.7 * t);  // deterministic scatter within 1 sigma
    r.id.sigma_scale = 0.03;
    r.id.informative = true;
    r.id.note.clear();
    r.alarms.clear();
    if (slack) r.alarms = {"GUIDE_PRELOAD_LOW"};
    for (auto& b : r.bins)
      if (slack && b.depth_lo == 300.0) b.resid_rms = 0.02;
    s->put(r);
  }
  std::printf("wrote trips %ld..%ld to %s\n", first, last, argv[1]);
  return 0;
}
