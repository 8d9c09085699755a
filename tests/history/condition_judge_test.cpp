// hoist::history::ConditionJudge (condition_judge.hpp): seeded from a
// shaft's stored trips (that shaft only), it decides GUIDE_PRELOAD_LOW as the
// trend over them says, and appends each condition alarm to a new record
// once, whatever the record already names.
#include <gtest/gtest.h>

#include <algorithm>

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
