// The SQLite history store (hoist/history/store.hpp): every field round
// trip, idempotent put, numbering, baseline, retention, migrations from
// version 1, and refusal of newer, foreign, garbage and bad contents (the
// bad contents are planted with Debian's sqlite3 CLI, as an outsider would).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "hoist/history/schema.hpp"
#include "hoist/history/sqlite_store.hpp"
#include "process.hpp"
#include "sample_record.hpp"

namespace fs = std::filesystem;
using namespace hoist;
using namespace hoist::history;
using hoist::test::runCaptured;
using hoist::test::sampleRecord;

namespace {

std::string sql(const fs::path& db, const std::string& script) {
  auto r = runCaptured("/usr/bin/sqlite3", {db.string(), script});
  EXPECT_EQ(r.status, 0) << r.output;
  return r.output;
}

using hoist::test::storeErrorOf;

}  // namespace

TEST(SqliteStore, EveryFieldRoundTripsWithItsBins) {
  const auto dir = hoist::test::testDir("sqlite_roundtrip");
  auto s = openSqliteStore((dir / "h.sqlite").string());
  EXPECT_EQ(s->schemaVersion(), kSchemaVersion);
  std::vector<TripRecord> put;
  for (int t = 1; t <= 8; ++t) {
    put.push_back(sampleRecord(t, t % 2 ? "" : "north"));
    EXPECT_EQ(s->put(put.back()), PutResult::Stored);
  }
  for (const auto& r : put) {
    SCOPED_TRACE(r.trip);
    auto got = s->get(r.shaft, r.trip);
    ASSERT_TRUE(got);
    hoist::test::expectSameRecord(r, *got);
  }
  // A fresh connection reads the same (nothing cached).
  s.reset();
  auto again = openSqliteStore((dir / "h.sqlite").string(), true);
  ListFilter f;
  f.with_bins = true;
  const auto all = again->list(f);
  ASSERT_EQ(all.size(), put.size());
  EXPECT_EQ(all[0].shaft, "");  // ordered by (shaft, trip)
  EXPECT_EQ(all.back().shaft, "north");
  for (const auto& r : all) hoist::test::expectSameRecord(sampleRecord(r.trip, r.shaft), r);
  f.shaft = "north";
  f.with_bins = false;
  const auto north = again->list(f);
  ASSERT_EQ(north.size(), 4u);
  EXPECT_TRUE(north[0].bins.empty());
  // limit: the first rows in (shaft, trip) order within the bounds (the condition judge's paging).
  f.from_trip = north[1].trip;
  f.limit = 2;
  const auto page = again->list(f);
  ASSERT_EQ(page.size(), 2u);
  EXPECT_EQ(page[0].trip, north[1].trip);
  EXPECT_EQ(page[1].trip, north[2].trip);
  EXPECT_EQ(sql(dir / "h.sqlite", "PRAGMA journal_mode;"), "wal\n");
}

TEST(SqliteStore, PutIsIdempotentAndNumbersTrips) {
  const auto dir = hoist::test::testDir("sqlite_idempotent");
  auto s = openSqliteStore((dir / "h.sqlite").string());
  EXPECT_EQ(s->nextTrip(""), 1);
  auto r = sampleRecord(1);
  EXPECT_EQ(s->put(r), PutResult::Stored);
  auto changed = sampleRecord(1);
  changed.peak_speed = 99.0;  // the same key again: left as it was
  EXPECT_EQ(s->put(changed), PutResult::Duplicate);
  EXPECT_EQ(s->get("", 1)->peak_speed, r.peak_speed);
  EXPECT_EQ(s->list().size(), 1u);
  EXPECT_EQ(sql(dir / "h.sqlite", "SELECT count(*) FROM bins;"), "12\n");
  auto next = sampleRecord(7);
  next.trip = 0;  // the store numbers it
  EXPECT_EQ(s->put(next), PutResult::Stored);
  EXPECT_EQ(next.trip, 2);
  EXPECT_EQ(s->nextTrip(""), 3);
  EXPECT_EQ(s->nextTrip("south"), 1);
  EXPECT_EQ(s->stats().stored, 2);
  EXPECT_EQ(s->stats().duplicates, 1);
}

TEST(SqliteStore, RefusesARecordItCannotStoreAndWritesNothing) {
  const auto dir = hoist::test::testDir("sqlite_refuse");
  auto s = openSqliteStore((dir / "h.sqlite").string());
  auto r = sampleRecord(1);
  r.bins[3].fy_rms = std::nan("");
  EXPECT_NE(storeErrorOf([&] { s->put(r); }).find("bins[3].fy_rms: not a finite number"), std::string::npos);
  r = sampleRecord(1);
  r.alarms = {"A;B"};
  EXPECT_NE(storeErrorOf([&] { s->put(r); }).find("alarms"), std::string::npos);
  r = sampleRecord(1);
  std::swap(r.bins[0], r.bins[1]);
  EXPECT_NE(storeErrorOf([&] { s->put(r); }).find("increasing depth"), std::string::npos);
  EXPECT_TRUE(s->list().empty());
  EXPECT_EQ(sql(dir / "h.sqlite", "SELECT count(*) FROM bins;"), "0\n");
}

TEST(SqliteStore, BaselineMarksAndPrune) {
  const auto dir = hoist::test::testDir("sqlite_baseline");
  auto s = openSqliteStore((dir / "h.sqlite").string());
  for (int t = 1; t <= 5; ++t) {
    auto r = sampleRecord(t);
    s->put(r);
  }
  s->markBaseline("", 2, true, 1);
  s->markBaseline("", 4, true, 1);
  s->markBaseline("", 4, true, 2);  // twice: still once
  EXPECT_EQ(s->baseline(""), (std::vector<std::int64_t>{2, 4}));
  s->markBaseline("", 4, false, 3);
  EXPECT_EQ(s->baseline(""), (std::vector<std::int64_t>{2}));
  EXPECT_NE(storeErrorOf([&] { s->markBaseline("", 9, true, 1); }).find("no trip 9"), std::string::npos);
  // Retention: trips ending more than keep_days before now go, with their bins and marks.
  const std::int64_t day = 86400LL * 1000000LL;
  const std::int64_t now = sampleRecord(3).wall_end_us + 10 * day + 1;  // trips 1..3 ended > 10 days ago
  EXPECT_EQ(s->prune(0, now), 0);
  EXPECT_EQ(s->prune(10, now), 3);
  EXPECT_EQ(s->list().size(), 2u);
  EXPECT_TRUE(s->baseline("").empty());
  EXPECT_EQ(sql(dir / "h.sqlite", "SELECT count(*) FROM bins;"), "24\n");
  EXPECT_EQ(s->nextTrip(""), 6);
}

TEST(SqliteStore, MigratesVersion1WithItsTrips) {
  const auto dir = hoist::test::testDir("sqlite_migrate");
  const auto db = dir / "h.sqlite";
  // A version-1 database made from version 1's own statements, holding a trip.
  std::string v1;
  for (const auto& st : schemaSteps(1)) v1 += st + ";\n";
  sql(db, v1);
  {
    auto s = openSqliteStore(db.string());  // migrates
    auto r = sampleRecord(1);
    s->put(r);
  }
  // Back to version 1 by hand (what version 2 added, removed) and reopen.
  sql(db, "DROP TABLE baseline; DROP INDEX trips_wall_end; UPDATE schema_version SET version = 1;");
  EXPECT_EQ(sql(db, "SELECT version FROM schema_version;"), "1\n");
  auto s = openSqliteStore(db.string());
  EXPECT_EQ(s->schemaVersion(), 2);
  EXPECT_EQ(sql(db, "SELECT version FROM schema_version;"), "2\n");
  hoist::test::expectSameRecord(sampleRecord(1), *s->get("", 1));
  s->markBaseline("", 1, true, 5);
  EXPECT_EQ(s->baseline(""), std::vector<std::int64_t>{1});
  // Read-only never migrates: it says what to do.
  sql(db, "DROP TABLE baseline; DROP INDEX trips_wall_end; UPDATE schema_version SET version = 1;");
  s.reset();
  EXPECT_NE(storeErrorOf([&] { openSqliteStore(db.string(), true); }).find("open it once read-write"), std::string::npos);
}

TEST(SqliteStore, RefusesNewerForeignGarbageAndMissing) {
  const auto dir = hoist::test::testDir("sqlite_refuse_db");
  const auto db = dir / "h.sqlite";
  { openSqliteStore(db.string()); }
  sql(db, "UPDATE schema_version SET version = 99;");
  EXPECT_NE(storeErrorOf([&] { openSqliteStore(db.string()); }).find("schema version 99 is newer"), std::string::npos);

  sql(dir / "other.sqlite", "CREATE TABLE trips (x INTEGER);");
  EXPECT_NE(storeErrorOf([&] { openSqliteStore((dir / "other.sqlite").string()); }).find("not a hoist-twin history database"),
            std::string::npos);

  { std::ofstream(dir / "garbage.sqlite") << std::string(4096, 'x'); }
  EXPECT_NE(storeErrorOf([&] { openSqliteStore((dir / "garbage.sqlite").string()); }).find("not a database"),
            std::string::npos);

  EXPECT_NE(storeErrorOf([&] { openSqliteStore((dir / "missing.sqlite").string(), true); }).find("no such file"),
            std::string::npos);
  fs::create_directories(dir / "adir");
  EXPECT_NE(storeErrorOf([&] { openSqliteStore((dir / "adir").string()); }).find("not a regular file"), std::string::npos);
}

TEST(SqliteStore, BadContentsAreAClearErrorNotACrash) {
  const auto dir = hoist::test::testDir("sqlite_bad_contents");
  const auto db = dir / "h.sqlite";
  {
    auto s = openSqliteStore(db.string());
    for (int t = 1; t <= 3; ++t) {
      auto r = sampleRecord(t);
      s->put(r);
    }
  }
  struct Case {
    const char* plant;
    const char* expect;
  } cases[] = {
      {"UPDATE trips SET fa_start = 'abc' WHERE trip = 2;", "trip 2: column fa_start: expected a real number, found text"},
      {"UPDATE trips SET peak_speed = -1e999 WHERE trip = 2;", "column peak_speed: not a finite number"},
      {"UPDATE trips SET peak_speed = 'NaN' WHERE trip = 2;", "column peak_speed: expected a real number, found text"},
      {"UPDATE trips SET direction = 5 WHERE trip = 2;", "column direction: must be 1 (down) or -1 (up)"},
      {"UPDATE trips SET mismatch = 7 WHERE trip = 2;", "column mismatch: a boolean must be 0 or 1"},
      {"UPDATE trips SET alarms = x'00ff' WHERE trip = 2;", "column alarms"},
      {"UPDATE bins SET samples = -4 WHERE trip = 2 AND idx = 3;", "bin: column samples: count out of range"},
      {"UPDATE bins SET resid_rms = 1e999 WHERE trip = 2 AND idx = 3;", "bin: column resid_rms: not a finite number"},
      {"UPDATE schema_version SET version = 'two';", "schema_version holds no valid version"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.plant);
    fs::copy_file(db, dir / "bad.sqlite", fs::copy_options::overwrite_existing);
    fs::remove(dir / "bad.sqlite-wal");
    sql(dir / "bad.sqlite", c.plant);
    const std::string e = storeErrorOf([&] {
      auto s = openSqliteStore((dir / "bad.sqlite").string());
      ListFilter f;
      f.with_bins = true;
      s->list(f);
    });
    EXPECT_NE(e.find(c.expect), std::string::npos) << e;
    EXPECT_NE(e.find("bad.sqlite"), std::string::npos) << e;  // names the database
  }
}
