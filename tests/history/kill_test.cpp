// kill -9 of a writer mid-write (issue 32 "Durability"): a helper process
// writes trip records in a loop and is killed at random moments, several
// times over; after each kill the database passes Debian's sqlite3
// `PRAGMA integrity_check`, and every trip the writer reported committed is
// there, field for field, with no gap and nothing half-written.
#include <gtest/gtest.h>

#include <csignal>
#include <random>
#include <sstream>
#include <thread>

#include "hoist/history/sqlite_store.hpp"
#include "process.hpp"
#include "sample_record.hpp"

using namespace std::chrono_literals;
using namespace hoist::history;

TEST(SqliteKill, Kill9MidWriteLosesNothingCommitted) {
  const auto dir = hoist::test::testDir("sqlite_kill9");
  const auto db = (dir / "h.sqlite").string();
  std::mt19937 g(32);
  std::uniform_int_distribution<int> wait_ms(30, 400);
  std::int64_t committed = 0;
  for (int round = 0; round < 8; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    const auto log = dir / ("writer" + std::to_string(round) + ".log");
    {
      hoist::test::Process p({HISTORY_WRITER, db, "100000"}, log.string());
      ASSERT_TRUE(p.started());
      std::this_thread::sleep_for(std::chrono::milliseconds(wait_ms(g) + (round == 0 ? 300 : 0)));
      ASSERT_TRUE(p.running()) << hoist::test::readFile(log.string());
      p.signal(SIGKILL);
      EXPECT_EQ(p.wait(10s), 128 + SIGKILL);
    }
    std::istringstream out(hoist::test::readFile(log.string()));
    std::string word;
    std::int64_t n = 0;
    while (out >> word >> n) committed = std::max(committed, n);
    auto check = hoist::test::runCaptured("/usr/bin/sqlite3", {db, "PRAGMA integrity_check;"});
    EXPECT_EQ(check.output, "ok\n");
    auto s = openSqliteStore(db);
    ListFilter f;
    f.with_bins = true;
    const auto all = s->list(f);
    // Every reported trip is there; at most the one in progress beyond it.
    ASSERT_GE(static_cast<std::int64_t>(all.size()), committed);
    EXPECT_LE(static_cast<std::int64_t>(all.size()), committed + 1);
    for (std::size_t i = 0; i < all.size(); ++i) {
      ASSERT_EQ(all[i].trip, static_cast<std::int64_t>(i + 1));
      ASSERT_EQ(all[i].bins.size(), 200u);
    }
    hoist::test::expectSameRecord(hoist::test::sampleRecord(all.back().trip, "", 200), all.back());
    committed = static_cast<std::int64_t>(all.size());
  }
  EXPECT_GT(committed, 8);  // the writer did get work done between the kills
  std::printf("kill -9: 8 kills, %lld trips committed, integrity_check ok after each\n",
              static_cast<long long>(committed));
}
