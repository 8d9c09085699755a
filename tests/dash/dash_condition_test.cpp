// The Shaft condition view's data (tools/dash/src/condition.hpp): the
// snapshot of a SQLite history database made by the Store, checked against
// the records written (trend points, the combined estimate's decision, the
// heat map's grid, the last record); records with implausible values left
// out and counted; and the worker: a missing database is a clear error
// (never a crash), the view appears when the file does, and a new trip
// moves it.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "condition.hpp"
#include "hoist/history/sqlite_store.hpp"
#include "process.hpp"
#include "sample_record.hpp"

namespace fs = std::filesystem;
using hoist::dash::ConditionView;
using Json = nlohmann::json;

namespace {

hoist::TripRecord rec(std::int64_t trip, double s) {
  hoist::TripRecord r = hoist::test::sampleRecord(trip, "", 12);
  r.id.scale = s;
  r.id.sigma_scale = 0.03;
  r.id.informative = true;
  return r;
}

/// Waits (polling, at most 20 s) until the view's snapshot satisfies `ok`.
Json waitFor(const ConditionView& v, const std::function<bool(const Json&)>& ok) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  Json j;
  while (std::chrono::steady_clock::now() < end) {
    j = Json::parse(v.snapshot());
    if (ok(j)) return j;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ADD_FAILURE() << "timed out; last snapshot: " << j.dump();
  return j;
}

}  // namespace

TEST(DashCondition, SnapshotShowsTheStoredTrips) {
  const auto dir = hoist::test::testDir("dash_condition_snapshot");
  auto s = hoist::history::openSqliteStore((dir / "h.sqlite").string());
  for (int t = 1; t <= 8; ++t) {
    auto r = rec(t, t <= 4 ? 1.0 : 0.6);
    s->put(r);
  }
  auto bad = rec(9, 50.0);  // finite, storable, implausible: left out
  s->put(bad);
  hoist::ConditionSettings cond;
  const Json j = ConditionView::build(*s, "", cond, 500);
  EXPECT_TRUE(j["ok"].get<bool>());
  EXPECT_EQ(j["trips"], 8);
  EXPECT_EQ(j["rejected"], 1);
  EXPECT_NE(j["rejected_notes"][0].get<std::string>().find("trip 9: id_scale"), std::string::npos);
  ASSERT_EQ(j["trend"].size(), 8u);
  EXPECT_EQ(j["trend"][6]["trip"], 7);
  EXPECT_DOUBLE_EQ(j["trend"][6]["s"].get<double>(), 0.6);
  EXPECT_DOUBLE_EQ(j["trend"][6]["sigma"].get<double>(), 0.03);
  // Four trips at 0.6 +- 0.03 after four at 1.0: the filter is near 0.6, the alarm CRITICAL.
  EXPECT_NEAR(j["preload"]["scale"].get<double>(), 0.6, 0.06);
  EXPECT_EQ(j["preload"]["level"], "CRITICAL");
  EXPECT_EQ(j["thresholds"]["warning"], cond.preload_warning);
  // Heat map: 8 trips x 12 bins, each cell the bin's resid_rms.
  ASSERT_EQ(j["heatmap"]["trips"].size(), 8u);
  ASSERT_EQ(j["heatmap"]["depths"].size(), 12u);
  EXPECT_DOUBLE_EQ(j["heatmap"]["cells"][2][5].get<double>(), rec(3, 1.0).bins[5].resid_rms);
  EXPECT_EQ(j["last"]["trip"], 8);
  EXPECT_EQ(j["last"]["bins"].size(), 12u);
  // max_trips: only the latest enter the trend and the map (the decision still sees all).
  const Json k = ConditionView::build(*s, "", cond, 3);
  EXPECT_EQ(k["trend"].size(), 3u);
  EXPECT_EQ(k["trend"][0]["trip"], 6);
  EXPECT_EQ(k["heatmap"]["trips"].size(), 3u);
  EXPECT_EQ(k["preload"]["level"], "CRITICAL");
}

TEST(DashCondition, NominalTripsRaiseNothing) {
  const auto dir = hoist::test::testDir("dash_condition_nominal");
  auto s = hoist::history::openSqliteStore((dir / "h.sqlite").string());
  for (int t = 1; t <= 10; ++t) {
    auto r = rec(t, 1.0 + 0.02 * ((t % 3) - 1));
    s->put(r);
  }
  const Json j = ConditionView::build(*s, "", hoist::ConditionSettings{}, 500);
  EXPECT_EQ(j["preload"]["level"], "NONE");
  EXPECT_NEAR(j["preload"]["scale"].get<double>(), 1.0, 0.05);
  EXPECT_FALSE(j["fingerprint"]["active"].get<bool>());
}

TEST(DashCondition, MissingDatabaseIsAnErrorThenTheViewFollowsTheFile) {
  const auto dir = hoist::test::testDir("dash_condition_worker");
  const fs::path db = dir / "later.sqlite";
  fs::remove(db);
  hoist::dash::ConditionOptions o = hoist::dash::conditionOptions(db.string(), "", "");
  o.poll_s = 0.1;
  ConditionView v(o);
  Json j = waitFor(v, [](const Json& x) { return x.contains("ok") && !x["ok"].get<bool>() && !x.value("loading", false); });
  EXPECT_NE(j["error"].get<std::string>().find("no such file"), std::string::npos) << j.dump();
  EXPECT_NE(j["error"].get<std::string>().find(db.string()), std::string::npos) << j.dump();
  {
    auto s = hoist::history::openSqliteStore(db.string());
    for (int t = 1; t <= 3; ++t) {
      auto r = rec(t, 1.0);
      s->put(r);
    }
  }
  j = waitFor(v, [](const Json& x) { return x["ok"].get<bool>() && x["trips"] == 3; });
  EXPECT_EQ(j["last"]["trip"], 3);
  {
    auto s = hoist::history::openSqliteStore(db.string());
    auto r = rec(4, 0.9);
    s->put(r);
  }
  j = waitFor(v, [](const Json& x) { return x["ok"].get<bool>() && x["trips"] == 4; });
  EXPECT_EQ(j["last"]["trip"], 4);
}

TEST(DashCondition, OptionsNameTheBadKey) {
  try {
    hoist::dash::conditionOptions("postgresql://u:secret@host/db", "", "");
    ADD_FAILURE() << "a password in the URL was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--history"), std::string::npos) << e.what();
  }
  EXPECT_THROW(hoist::dash::conditionOptions("", "", ""), std::invalid_argument);
}
