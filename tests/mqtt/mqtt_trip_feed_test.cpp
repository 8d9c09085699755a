// hoist-mqtt's trip feed (hoist/mqtt/trip_feed.hpp) against a SQLite history
// database written by the Store: the trip/last summary carries the list
// columns and the identification as stored, the condition follows the
// trend (CRITICAL after a drop to 0.6), implausible records are left out,
// and the worker reports a shaft's last trip, then each new one, from a
// database that appears after it started.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "hoist/history/sqlite_store.hpp"
#include "hoist/mqtt/trip_feed.hpp"
#include "process.hpp"
#include "sample_record.hpp"

using hoist::mqtt::TripFeed;

using hoist::test::identifiedRecord;

TEST(MqttTripFeed, SummaryAndConditionFromTheStore) {
  const auto dir = hoist::test::testDir("trip_feed_read");
  auto s = hoist::history::openSqliteStore((dir / "h.sqlite").string());
  for (int t = 1; t <= 8; ++t) {
    auto r = identifiedRecord(t, t <= 4 ? 1.0 : 0.6, "north");
    s->put(r);
  }
  auto bad = identifiedRecord(9, 50.0, "north");
  s->put(bad);
  std::int64_t rejected = 0;
  const auto u = TripFeed::read(*s, "north", hoist::ConditionSettings{}, &rejected);
  EXPECT_EQ(rejected, 1);
  EXPECT_EQ(u.shaft, "north");
  EXPECT_EQ(u.cond.last_trip, 8);
  EXPECT_EQ(u.cond.trips_in_trend, 8);
  EXPECT_TRUE(u.cond.last_informative);
  EXPECT_EQ(u.cond.guide_preload_low, 2);
  EXPECT_NEAR(u.cond.preload_scale, 0.6, 0.06);
  EXPECT_GT(u.cond.preload_sigma, 0.0);
  const auto stored = *s->get("north", 8);
  const auto& j = u.last;
  EXPECT_EQ(j["trip"], 8);
  EXPECT_EQ(j["shaft"], "north");
  EXPECT_EQ(j["direction"], "up");
  EXPECT_EQ(j["Fa"].get<double>(), stored.Fa_end);
  EXPECT_EQ(j["sigma_Fa"].get<double>(), stored.sigma_Fa_end);
  EXPECT_TRUE(j["sigma_moment"].is_null());  // not observed in sampleRecord
  EXPECT_EQ(j["preload_scale"].get<double>(), 0.6);
  EXPECT_EQ(j["sigma_preload_scale"].get<double>(), 0.03);
  EXPECT_EQ(j["mismatch"], stored.mismatch);
  EXPECT_EQ(j["alarms"], stored.alarms);
  EXPECT_FALSE(j["identification"].contains("chi2"));  // the summary, not the whole record
  EXPECT_EQ(j["identification"]["loss30_separation"].get<double>(), stored.id.loss30_separation);
  EXPECT_EQ(j["condition"]["level"], "CRITICAL");
  EXPECT_NE(j["condition"]["text"].get<std::string>().find("0.6"), std::string::npos) << j.dump();
  EXPECT_EQ(j["wall_end"].get<std::string>().size(), 24u);
  // Another shaft, and one without trips.
  auto d = identifiedRecord(1, 1.0);
  s->put(d);
  EXPECT_EQ(TripFeed::read(*s, "default", hoist::ConditionSettings{}).cond.guide_preload_low, 0);
  EXPECT_TRUE(TripFeed::read(*s, "south", hoist::ConditionSettings{}).shaft.empty());
}

TEST(MqttTripFeed, WorkerReportsTheLastTripThenEachNewOne) {
  const auto dir = hoist::test::testDir("trip_feed_worker");
  const auto db = dir / "h.sqlite";
  hoist::history::StoreOptions so;
  so.db.target = db.string();
  TripFeed feed(so, hoist::ConditionSettings{}, 0.05);
  feed.watch("default");
  // Waits for the update that reports trip `want`. The worker may poll
  // between two of the writes below and report an earlier trip first; that
  // is right, as long as the trips it reports only go up.
  auto waitFor = [&](std::int64_t want) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    std::int64_t seen = 0;
    while (std::chrono::steady_clock::now() < end) {
      for (const auto& u : feed.take()) {
        EXPECT_EQ(u.shaft, "default");
        const std::int64_t t = u.last["trip"].get<std::int64_t>();
        EXPECT_GT(t, seen) << "the feed reported trip " << t << " after trip " << seen;
        seen = t;
        if (t == want) return u;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ADD_FAILURE() << "no update for trip " << want << " in 20 s (last seen: " << seen << ")";
    return hoist::mqtt::TripUpdate{};
  };
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // a few polls of a missing database
  EXPECT_TRUE(feed.take().empty());
  {
    auto s = hoist::history::openSqliteStore(db.string());
    for (int t = 1; t <= 3; ++t) {
      auto r = identifiedRecord(t, 1.0);
      s->put(r);
      // Longer than a poll: the worker sees trips 1 and 2 on their own.
      std::this_thread::sleep_for(std::chrono::milliseconds(120));
    }
  }
  auto u = waitFor(3);
  EXPECT_EQ(u.last["trip"], 3);
  {
    auto s = hoist::history::openSqliteStore(db.string());
    auto r = identifiedRecord(4, 0.9);
    s->put(r);
  }
  u = waitFor(4);
  EXPECT_EQ(u.cond.trips_in_trend, 4);
  EXPECT_TRUE(feed.take().empty());  // nothing new after trip 4
}
