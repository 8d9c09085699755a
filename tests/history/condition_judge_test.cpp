// hoist::history::ConditionJudge (condition_judge.hpp): seeded from a
// shaft's stored trips (that shaft only), it decides GUIDE_PRELOAD_LOW as the
// trend over them says, and appends each condition alarm to a new record
// once, whatever the record already names.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hoist/history/condition_judge.hpp"
#include "hoist/history/sqlite_store.hpp"
#include "process.hpp"
#include "sample_record.hpp"

using hoist::history::ConditionJudge;

namespace {

hoist::TripRecord identified(std::int64_t trip, double s, const std::string& shaft) {
  hoist::TripRecord r = hoist::test::identifiedRecord(trip, s, shaft, 0);
  r.alarms.clear();
  r.mismatch = false;
  return r;
}

long count(const std::vector<std::string>& v, const std::string& x) { return std::count(v.begin(), v.end(), x); }

}  // namespace

TEST(ConditionJudge, SeedsFromTheShaftsStoredTripsAndAppendsEachAlarmOnce) {
  const auto dir = hoist::test::testDir("condition_judge");
  auto db = hoist::history::openSqliteStore((dir / "h.sqlite").string());
  for (int t = 1; t <= 12; ++t) {
    auto r = identified(t, t <= 8 ? 1.0 : 0.6, "north");
    db->put(r);
  }
  for (int t = 1; t <= 5; ++t) {  // another shaft, nominal: must not mix in
    auto r = identified(t, 1.0, "south");
    db->put(r);
  }
  ConditionJudge north{hoist::ConditionSettings{}};
  EXPECT_EQ(north.seed(*db, "north"), 12);
  EXPECT_EQ(north.trips(), 12);
  EXPECT_EQ(north.lastTrip(), 12);
  const auto p = north.preload();
  EXPECT_EQ(p.level, hoist::ConditionLevel::Critical);
  EXPECT_NEAR(p.scale, 0.6, 0.05);
  EXPECT_NE(north.summary().find("below 0.70"), std::string::npos) << north.summary();

  // A new trip that already names one of them, with a mismatch: each once.
  auto r = identified(13, 0.62, "north");
  r.mismatch = true;
  r.alarms = {"GUIDE_PRELOAD_LOW", "CAGE_POS_Y"};
  north.judge(r);
  EXPECT_EQ(count(r.alarms, "GUIDE_PRELOAD_LOW"), 1);
  EXPECT_EQ(count(r.alarms, "MODEL_MISMATCH"), 1);
  EXPECT_EQ(count(r.alarms, "CAGE_POS_Y"), 1);
  EXPECT_EQ(count(r.alarms, "SHAFT_FINGERPRINT"), 0);  // no depth bins: nothing to compare
  EXPECT_EQ(north.lastTrip(), 13);

  ConditionJudge south{hoist::ConditionSettings{}};
  EXPECT_EQ(south.seed(*db, "south"), 5);
  EXPECT_EQ(south.preload().level, hoist::ConditionLevel::None);
  auto s6 = identified(6, 1.01, "south");
  south.judge(s6);
  EXPECT_TRUE(s6.alarms.empty());

  ConditionJudge none{hoist::ConditionSettings{}};
  EXPECT_EQ(none.seed(*db, "west"), 0);
  EXPECT_FALSE(none.preload().valid);
}

// A shaft with a long history (issue 32): the judge reads the newest
// [condition] seed_trips trips and the baseline before them, not every trip
// ever stored, and decides exactly as a full read does -- GUIDE_PRELOAD_LOW
// after the preload fell near the end, SHAFT_FINGERPRINT from a disturbance
// in the last down trips against the commissioning baseline of trips 1-20,
// the automatic baseline and an operator's marked one, with the oldest trips
// pruned too.
TEST(ConditionJudge, ALongHistoryIsJudgedFromItsNewestTripsAndItsBaselineAsAFullReadJudgesIt) {
  const auto dir = hoist::test::testDir("condition_judge_long");
  auto db = hoist::history::openSqliteStore((dir / "h.sqlite").string());
  const int n = 1200;
  for (int t = 1; t <= n; ++t) {
    auto r = hoist::test::identifiedRecord(t, t <= n - 40 ? 1.0 + 0.02 * std::sin(t) : 0.62, "north", 12);
    r.alarms.clear();
    if (r.direction == hoist::TripDirection::Down && t > n - 6) r.bins[5].resid_mean += 2e-3;  // a local push
    db->put(r);
  }
  auto judgeBoth = [&](const char* what, std::int64_t read_windowed) {
    hoist::ConditionSettings all, window;
    all.seed_trips = 0;
    window.seed_trips = 200;
    ConditionJudge full{all}, bounded{window};
    const std::int64_t read_all = full.seed(*db, "north");
    EXPECT_EQ(bounded.seed(*db, "north"), read_windowed) << what;
    EXPECT_FALSE(full.seededWindowed()) << what;
    EXPECT_TRUE(bounded.seededWindowed()) << what;
    EXPECT_EQ(bounded.storedLastTrip(), n) << what;
    EXPECT_GT(read_all, 4 * read_windowed) << what;
    const auto pf = full.preload(), pb = bounded.preload();
    EXPECT_EQ(pb.level, pf.level) << what;
    EXPECT_EQ(pf.level, hoist::ConditionLevel::Critical) << what;
    EXPECT_NEAR(pb.scale, pf.scale, 1e-12) << what;
    EXPECT_NEAR(pb.sigma, pf.sigma, 1e-12) << what;
    EXPECT_EQ(pb.trips, pf.trips) << what;
    EXPECT_EQ(pb.text, pf.text) << what;
    const auto ff = full.fingerprint(), fb = bounded.fingerprint();
    EXPECT_TRUE(ff.active) << what << ": " << ff.text;
    EXPECT_EQ(fb.active, ff.active) << what;
    EXPECT_EQ(fb.text, ff.text) << what;
    ASSERT_EQ(fb.hits.size(), ff.hits.size()) << what;
    for (std::size_t i = 0; i < ff.hits.size(); ++i) {
      EXPECT_EQ(fb.hits[i].depth_lo, ff.hits[i].depth_lo) << what;
      EXPECT_NEAR(fb.hits[i].z_last, ff.hits[i].z_last, 1e-9) << what;
    }
    // The next trip is judged alike.
    auto a = identified(n + 1, 0.6, "north"), b = a;
    full.judge(a);
    bounded.judge(b);
    EXPECT_EQ(a.alarms, b.alarms) << what;
    std::printf("[ %s ] full read %lld trips, bounded %lld: %s | %s\n", what, static_cast<long long>(read_all),
                static_cast<long long>(read_windowed), pb.text.c_str(), fb.text.c_str());
  };
  judgeBoth("automatic baseline", 200 + 20);  // the window and 10 trips of each direction
  // The oldest 300 trips pruned: the baseline is the oldest stored ones.
  const std::int64_t day_us = 86'400'000'000LL;
  const std::int64_t end300 = hoist::test::sampleRecord(300, "north").wall_end_us;
  EXPECT_EQ(db->prune(1, end300 + day_us + 1), 300);
  judgeBoth("pruned to trips 301-1200", 200 + 20);
  // An operator's baseline (two trips of each direction) replaces the automatic one.
  for (std::int64_t t : {401, 402, 403, 404}) db->markBaseline("north", t, true, 0);
  judgeBoth("marked baseline", 200 + 4);
}
