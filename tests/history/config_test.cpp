// [history] and the database URL (hoist/history/config.hpp), the record's
// JSON form and the outage queue's files (queue.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "hoist/history/condition_config.hpp"
#include "hoist/history/config.hpp"
#include "hoist/history/queue.hpp"
#include "hoist/history/record_json.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/error.hpp"
#include "process.hpp"
#include "sample_record.hpp"

namespace fs = std::filesystem;
using namespace hoist;
using namespace hoist::history;

namespace {

std::string urlError(const std::string& url) {
  try {
    parseDatabaseUrl(url, "--db");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

std::string configError(const std::string& text) {
  try {
    historyConfigFromToml(io::parseToml(text, "h.toml"), "h.toml");
  } catch (const io::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(HistoryConfig, DatabaseUrls) {
  EXPECT_EQ(parseDatabaseUrl("sqlite:///var/lib/h.sqlite", "k").target, "/var/lib/h.sqlite");
  EXPECT_EQ(parseDatabaseUrl("sqlite:///var/lib/h.sqlite", "k").backend, Backend::Sqlite);
  EXPECT_EQ(parseDatabaseUrl("h.sqlite", "k", "/etc/hoist").target, "/etc/hoist/h.sqlite");
  EXPECT_EQ(parseDatabaseUrl("sqlite:rel/h.sqlite", "k", "/d").target, "/d/rel/h.sqlite");
  EXPECT_EQ(parseDatabaseUrl("/abs/h.sqlite", "k", "/d").target, "/abs/h.sqlite");
  const auto pg = parseDatabaseUrl("postgresql://hoist@db.plant:5432/twin?sslmode=require", "k");
  EXPECT_EQ(pg.backend, Backend::Postgres);
  EXPECT_EQ(pg.target, "postgresql://hoist@db.plant:5432/twin?sslmode=require");
  EXPECT_EQ(parseDatabaseUrl("postgres://hoist@/twin?host=/run/postgresql", "k").backend, Backend::Postgres);

  EXPECT_EQ(urlError(""), "--db: empty (sqlite:///path, a path, or postgresql://...)");
  EXPECT_NE(urlError("postgresql://hoist:secret@db/twin").find("--db: a password in the URL is refused"), std::string::npos);
  EXPECT_NE(urlError("postgresql://hoist@db/twin?password=secret").find("password parameter"), std::string::npos);
  EXPECT_EQ(urlError("postgresql://hoist:secret@db/twin").find("secret"), std::string::npos);  // never echoed
  EXPECT_NE(urlError("mysql://db/twin").find("unknown scheme 'mysql'"), std::string::npos);
  EXPECT_NE(urlError("sqlite://rel.sqlite").find("three slashes"), std::string::npos);
  EXPECT_NE(urlError("/var/lib/").find("is a folder"), std::string::npos);
}

TEST(HistoryConfig, SectionKeysAndValidation) {
  const auto c = historyConfigFromToml(io::parseToml("[history]\nurl = \"/x/h.sqlite\"\nkeep_days = 400\n"), "h.toml");
  EXPECT_EQ(c.url, "/x/h.sqlite");
  EXPECT_EQ(c.keep_days, 400);
  const auto d = historyConfigFromToml(io::parseToml("[service]\nx = 1\n"), "h.toml");  // absent: defaults
  EXPECT_EQ(d.keep_days, 0);
  EXPECT_TRUE(d.url.empty());

  EXPECT_NE(configError("[history]\nkeep_days = -1\n").find("h.toml:2: history.keep_days: must be >= 0"), std::string::npos);
  EXPECT_NE(configError("[history]\nkeep_day = 3\n").find("did you mean 'keep_days'"), std::string::npos);
  EXPECT_NE(configError("[history]\nurl = 3\n").find("history.url"), std::string::npos);
  EXPECT_NE(configError("[history]\nurl = \"ftp://x\"\n").find("h.toml:2: history.url: unknown scheme"), std::string::npos);
  EXPECT_NE(configError("[history]\nretry_seconds = 0\n").find("history.retry_seconds"), std::string::npos);
  EXPECT_NE(configError("[history]\nurl = \"/a.sqlite\"\npassword_file = \"/p\"\n").find("history.password_file"),
            std::string::npos);
}

TEST(HistoryConfig, DefaultsBesideTheConfigAndCredentials) {
  const auto dir = hoist::test::testDir("history_credentials");
  HistoryConfig c;
  auto o = resolveStoreOptions(c, dir.string());
  EXPECT_EQ(o.db.target, (dir / "history.sqlite").string());
  EXPECT_EQ(o.queue_dir, (dir / "history-queue").string());
  EXPECT_TRUE(o.password.empty());

  c.url = "postgresql://hoist@/twin";
  c.password_file = "pw.txt";
  { std::ofstream(dir / "pw.txt") << "from-file\r\nsecond line\n"; }
  ::unsetenv("CREDENTIALS_DIRECTORY");
  EXPECT_EQ(resolveStoreOptions(c, dir.string()).password, "from-file");
  // systemd's LoadCredential wins over the file; a blank credential does not count.
  fs::create_directories(dir / "creds");
  { std::ofstream(dir / "creds" / "history-password") << "  \n"; }
  ::setenv("CREDENTIALS_DIRECTORY", (dir / "creds").c_str(), 1);
  EXPECT_EQ(resolveStoreOptions(c, dir.string()).password, "from-file");
  { std::ofstream(dir / "creds" / "history-password") << "from-credential\n"; }
  EXPECT_EQ(resolveStoreOptions(c, dir.string()).password, "from-credential");
  ::unsetenv("CREDENTIALS_DIRECTORY");
  { std::ofstream(dir / "pw.txt"); }
  try {
    resolveStoreOptions(c, dir.string());
    ADD_FAILURE() << "an empty password file was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("history.password_file"), std::string::npos);
  }
}

TEST(RecordJson, RoundTripsAndRefusesBadValues) {
  for (int t = 1; t <= 6; ++t) {
    const auto r = hoist::test::sampleRecord(t, "s");
    hoist::test::expectSameRecord(r, recordFromJson(nlohmann::json::parse(recordToJson(r).dump())));
  }
  auto j = recordToJson(hoist::test::sampleRecord(2));
  j["bins"][1]["samples"] = "many";
  EXPECT_THROW(recordFromJson(j), std::invalid_argument);
  j = recordToJson(hoist::test::sampleRecord(2));
  j.erase("peak_speed");
  try {
    recordFromJson(j);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "peak_speed: missing");
  }
}

TEST(RecordQueue, KeepsOrderAndMovesDamagedFilesAside) {
  const auto dir = hoist::test::testDir("history_queue");
  RecordQueue q((dir / "q").string());
  EXPECT_TRUE(q.pending().empty());
  for (int t = 1; t <= 12; ++t) q.push(hoist::test::sampleRecord(t));
  EXPECT_EQ(fs::status(dir / "q").permissions() & fs::perms::all, fs::perms::owner_all);
  auto p = q.pending();
  ASSERT_EQ(p.size(), 12u);
  for (std::size_t i = 0; i < p.size(); ++i) {
    TripRecord r;
    std::string why;
    ASSERT_TRUE(q.read(p[i], r, why)) << why;
    EXPECT_EQ(r.trip, static_cast<std::int64_t>(i + 1));  // in order, past 9 too
  }
  EXPECT_EQ(q.maxTrip(""), 12);
  // One byte changed in the body: the CRC catches it.
  {
    std::fstream f(p[4].path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-5, std::ios::end);
    f.put('7');
  }
  TripRecord r;
  std::string why;
  EXPECT_FALSE(q.read(p[4], r, why));
  EXPECT_NE(why.find("CRC mismatch"), std::string::npos) << why;
  EXPECT_TRUE(fs::exists(p[4].path + ".bad"));
  EXPECT_EQ(q.rejected(), 1);
  EXPECT_EQ(q.pending().size(), 11u);
  q.remove(p[0]);
  EXPECT_EQ(q.pending().front().seq, p[1].seq);
  EXPECT_EQ(crc32("123456789", 9), 0xCBF43926u);  // the standard check value
}

TEST(ConditionConfig, KeysDefaultsAndErrorsWithTheLine) {
  const auto c = conditionSettingsFromToml(
      io::parseToml("[condition]\ndepth_bin = 20.0\nmax_sigma = 0.05\nbaseline_trips = 6\npreload_warning = 0.9\n"),
      "c.toml");
  EXPECT_EQ(c.depth_bin, 20.0);
  EXPECT_EQ(c.max_sigma, 0.05);
  EXPECT_EQ(c.baseline_trips, 6);
  EXPECT_EQ(c.preload_warning, 0.9);
  EXPECT_EQ(c.preload_critical, 0.70);  // untouched keys keep their defaults
  auto err = [](const std::string& text) {
    try {
      conditionSettingsFromToml(io::parseToml(text, "c.toml"), "c.toml");
    } catch (const io::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(err("[condition]\n\npreload_critical = 0.9\n").find("c.toml:3: condition.preload_critical"), std::string::npos);
  EXPECT_NE(err("[condition]\ndepth_bin = -1\n").find("c.toml:2: condition.depth_bin: must be > 0"), std::string::npos);
  EXPECT_NE(err("[condition]\ndepth_bins = 5\n").find("did you mean 'depth_bin'"), std::string::npos);
  EXPECT_NE(err("[condition]\nbaseline_trips = 2.5\n").find("condition.baseline_trips"), std::string::npos);
  // seed_trips: 500 by default, 0 (every trip) or at least two baselines' worth.
  EXPECT_EQ(c.seed_trips, 500);
  EXPECT_EQ(conditionSettingsFromToml(io::parseToml("[condition]\nseed_trips = 0\n"), "c.toml").seed_trips, 0);
  EXPECT_NE(err("[condition]\nseed_trips = 15\n").find("c.toml:2: condition.seed_trips: must be 0 (every stored trip) or >= 2 x baseline_trips"),
            std::string::npos) << err("[condition]\nseed_trips = 15\n");
  // hoist-twind's configuration may hold [history] and [condition] beside the shaft's sections.
  const auto sections = configSections();
  EXPECT_NE(std::find(sections.begin(), sections.end(), "history"), sections.end());
  EXPECT_NE(std::find(sections.begin(), sections.end(), "condition"), sections.end());
  EXPECT_NO_THROW(io::shaftParamsFromToml(io::parseToml("[history]\nkeep_days = 1\n[condition]\n"), "c.toml", sections));
}

// The preload fit's offset prior is [sensors] imu_accel_offset_sigma of the
// same file (the estimator's default without it); only that key is read, so
// the daemon's own [estimator] keys (clear_hold) are no error here.
TEST(ConditionConfig, OffsetPriorComesFromSensors) {
  EXPECT_EQ(conditionSettingsFromToml(io::parseToml("[condition]\n"), "c.toml").accel_offset_sigma, 0.005);
  const auto c = conditionSettingsFromToml(
      io::parseToml("[sensors]\nimu_accel_offset_sigma = 0.0\n[estimator]\nclear_hold = 3.0\n"), "c.toml");
  EXPECT_EQ(c.accel_offset_sigma, 0.0);
  try {
    conditionSettingsFromToml(io::parseToml("[sensors]\n\nimu_accel_offset_sigma = -1.0\n", "c.toml"), "c.toml");
    ADD_FAILURE() << "a negative prior was accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("c.toml:3: sensors.imu_accel_offset_sigma"), std::string::npos) << e.what();
  }
}
