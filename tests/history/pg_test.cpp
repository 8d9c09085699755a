// The PostgreSQL history store against a real server (label `postgres`;
// pg_server.hpp starts it from Debian's package and stops it on every exit
// path; skipped with a message when PostgreSQL is not installed).
//   RoundTripCredentialsMigrations: every field, idempotent put, baseline,
//     retention, a wrong password refused, migration from version 1, newer
//     and bad contents refused.
//   OutageOfTwoMinutes (the test): records every 0.5 s; the server
//     stopped for 120 s while they keep coming; restarted: every record
//     arrives exactly once, in order, field for field, and the queue is
//     empty.  A record that had committed before the loss (a lost COMMIT
//     acknowledgement) is queued again too: it stays single.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "hoist/history/queue.hpp"
#include "hoist/history/schema.hpp"
#include "hoist/history/store.hpp"
#include "pg_server.hpp"
#include "sample_record.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using namespace hoist;
using namespace hoist::history;
using hoist::test::PgServer;
using hoist::test::sampleRecord;

namespace {

constexpr const char* kPassword = "s3cret-hist'ory";

/// Options as the daemon would resolve them, the password through systemd's
/// credential folder.
StoreOptions options(const PgServer& pg, const fs::path& dir, double retry = 10.0) {
  fs::create_directories(dir / "creds");
  { std::ofstream(dir / "creds" / "history-password") << kPassword << "\n"; }
  ::setenv("CREDENTIALS_DIRECTORY", (dir / "creds").c_str(), 1);
  HistoryConfig c;
  c.url = pg.url();
  c.retry_seconds = retry;
  auto o = resolveStoreOptions(c, dir.string());
  ::unsetenv("CREDENTIALS_DIRECTORY");
  return o;
}

using hoist::test::storeErrorOf;

#define NEED_POSTGRES()                                                                         \
  if (PgServer::binDir().empty()) GTEST_SKIP() << "PostgreSQL is not installed (apt-get install postgresql)"

}  // namespace

TEST(PgStore, RoundTripCredentialsMigrations) {
  NEED_POSTGRES();
  const auto dir = hoist::test::testDir("pg_roundtrip");
  PgServer pg(7931, kPassword);
  ASSERT_TRUE(pg.ok()) << pg.log();
  const auto o = options(pg, dir);
  EXPECT_EQ(o.password, kPassword);
  {
    auto s = openStore(o);
    EXPECT_EQ(s->schemaVersion(), kSchemaVersion);
    for (int t = 1; t <= 6; ++t) {
      auto r = sampleRecord(t, t % 2 ? "" : "north");
      EXPECT_EQ(s->put(r), PutResult::Stored);
    }
    for (int t = 1; t <= 6; ++t) hoist::test::expectSameRecord(sampleRecord(t, t % 2 ? "" : "north"), *s->get(t % 2 ? "" : "north", t));
    {  // limit: the first rows in (shaft, trip) order within the bounds (the condition judge's paging)
      ListFilter lf;
      lf.shaft = "";
      lf.from_trip = 2;
      lf.limit = 1;
      const auto first = s->list(lf);
      ASSERT_EQ(first.size(), 1u);
      EXPECT_EQ(first[0].trip, 3);
      lf.limit = 5;
      EXPECT_EQ(s->list(lf).size(), 2u);  // trips 3 and 5
    }
    auto again = sampleRecord(3);
    again.peak_speed = 1.0;
    EXPECT_EQ(s->put(again), PutResult::Duplicate);
    EXPECT_EQ(s->get("", 3)->peak_speed, sampleRecord(3).peak_speed);
    EXPECT_EQ(s->nextTrip(""), 6);  // trips 1, 3, 5 on the default shaft
    auto fresh = sampleRecord(9);
    fresh.trip = 0;
    EXPECT_EQ(s->put(fresh), PutResult::Stored);
    EXPECT_EQ(fresh.trip, 6);
    s->markBaseline("", 1, true, 10);
    s->markBaseline("", 3, true, 10);
    EXPECT_EQ(s->baseline(""), (std::vector<std::int64_t>{1, 3}));
    EXPECT_NE(storeErrorOf([&] { s->markBaseline("", 77, true, 1); }).find("no trip 77"), std::string::npos);
    const std::int64_t day = 86400LL * 1000000LL;
    EXPECT_EQ(s->prune(1, sampleRecord(1).wall_end_us + day + 1), 1);
    EXPECT_EQ(s->baseline(""), (std::vector<std::int64_t>{3}));
    EXPECT_EQ(pg.psql("SELECT count(*) FROM bins WHERE trip = 1").output, "0\n");
    EXPECT_EQ(s->stats().queued, 0);
  }
  // A wrong password: refused at open, the password never in the message.
  {
    auto bad = o;
    bad.password = "wrong-password";
    const auto e = storeErrorOf([&] { openStore(bad); });
    EXPECT_NE(e.find("refused"), std::string::npos) << e;
    EXPECT_EQ(e.find("wrong-password"), std::string::npos) << e;
  }
  // Version 1 (version 2's additions removed by hand) is migrated, its trips kept.
  ASSERT_EQ(pg.psql("DROP TABLE baseline; DROP INDEX trips_wall_end; UPDATE schema_version SET version = 1;").status, 0);
  {
    auto s = openStore(o);
    EXPECT_EQ(s->schemaVersion(), 2);
    hoist::test::expectSameRecord(sampleRecord(5), *s->get("", 5));
    EXPECT_TRUE(s->baseline("").empty());
  }
  // Bad contents planted by hand: a clear error naming trip and column.
  ASSERT_EQ(pg.psql("UPDATE trips SET peak_speed = 'NaN' WHERE trip = 5").status, 0);
  {
    auto s = openStore(o);
    const auto e = storeErrorOf([&] { s->list(); });
    EXPECT_NE(e.find("trip 5: column peak_speed: not a finite number"), std::string::npos) << e;
  }
  ASSERT_EQ(pg.psql("UPDATE schema_version SET version = 42").status, 0);
  EXPECT_NE(storeErrorOf([&] { openStore(o); }).find("schema version 42 is newer"), std::string::npos);
}

TEST(PgStore, OutageOfTwoMinutesLosesAndDoublesNothing) {
  NEED_POSTGRES();
  const auto dir = hoist::test::testDir("pg_outage");
  PgServer pg(7932, kPassword);
  ASSERT_TRUE(pg.ok()) << pg.log();
  const double outage_s = std::getenv("HOIST_PG_OUTAGE_S") ? std::atof(std::getenv("HOIST_PG_OUTAGE_S")) : 120.0;
  auto s = openStore(options(pg, dir, 1.0));
  std::int64_t next = 1, queued = 0;
  auto putOne = [&] {
    auto r = sampleRecord(next);
    r.trip = 0;  // numbered by the store, also while the server is down
    const auto res = s->put(r);
    EXPECT_EQ(r.trip, next);
    if (res == PutResult::Queued) ++queued;
    else EXPECT_EQ(res, PutResult::Stored);
    ++next;
    std::this_thread::sleep_for(500ms);
    return res;
  };
  for (int i = 0; i < 10; ++i) EXPECT_EQ(putOne(), PutResult::Stored);
  ASSERT_TRUE(pg.stop());
  const auto down = std::chrono::steady_clock::now();
  // A trip whose COMMIT went through but whose acknowledgement was lost is
  // queued as well: the retry must not double it.
  RecordQueue((dir / "history-queue").string()).push(sampleRecord(4));
  while (std::chrono::steady_clock::now() - down < std::chrono::duration<double>(outage_s))
    EXPECT_EQ(putOne(), PutResult::Queued);
  EXPECT_FALSE(s->stats().connected);
  EXPECT_GT(s->stats().pending, 0);
  EXPECT_FALSE(s->stats().last_error.empty());
  std::printf("outage: %.0f s, %lld records queued\n", outage_s, static_cast<long long>(queued));
  ASSERT_TRUE(pg.start()) << pg.log();
  const auto up = std::chrono::steady_clock::now();
  while (s->stats().pending > 0 && std::chrono::steady_clock::now() - up < 60s) putOne();
  for (int i = 0; i < 3; ++i) EXPECT_EQ(putOne(), PutResult::Stored);
  const auto st = s->stats();
  EXPECT_EQ(st.pending, 0);
  EXPECT_EQ(st.duplicates, 1);  // trip 4, queued again
  EXPECT_EQ(st.flushed, queued + 1);
  EXPECT_TRUE(st.connected);
  ListFilter f;
  f.with_bins = true;
  const auto all = s->list(f);
  ASSERT_EQ(static_cast<std::int64_t>(all.size()), next - 1);
  for (std::size_t i = 0; i < all.size(); ++i) {
    ASSERT_EQ(all[i].trip, static_cast<std::int64_t>(i + 1));
    hoist::test::expectSameRecord(sampleRecord(all[i].trip), all[i]);
  }
  EXPECT_EQ(pg.psql("SELECT count(*), count(DISTINCT trip) FROM trips").output,
            std::to_string(next - 1) + "|" + std::to_string(next - 1) + "\n");
  EXPECT_TRUE(fs::is_empty(dir / "history-queue"));
}
