// hoist-trips as a program: every subcommand on a database of sample trips
// (list in its three formats, show, trend and depth-map PNGs, baseline,
// export), ingest of a hoist-sim recording through the trip pipeline (and a
// second ingest that doubles nothing), and bad options: exit 2 naming the
// option, the password never echoed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "hoist/history/schema.hpp"
#include "hoist/history/sqlite_store.hpp"
#include "process.hpp"
#include "sample_record.hpp"
#include "trip_profile.hpp"

namespace fs = std::filesystem;
using hoist::test::CapturedRun;
using namespace hoist::history;

namespace {

CapturedRun trips(const std::vector<std::string>& a) { return hoist::test::runCaptured(HOIST_TRIPS, a); }

class TripsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = hoist::test::testDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    db_ = (dir_ / "h.sqlite").string();
    auto s = openSqliteStore(db_);
    for (int t = 1; t <= 14; ++t) {
      auto r = hoist::test::sampleRecord(t);
      if (t > 8) r.id.scale -= 0.25;  // the preload falls
      s->put(r);
    }
  }
  std::string path(const std::string& n) const { return (dir_ / n).string(); }
  static std::string file(const std::string& p) { return hoist::test::readFile(p); }
  static bool isPng(const std::string& p) {
    const std::string s = file(p);
    return s.size() > 2000 && s.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
  }
  fs::path dir_;
  std::string db_;
};

}  // namespace

TEST_F(TripsCli, ListInThreeFormats) {
  const auto t = trips({"list", "--db", db_});
  ASSERT_EQ(t.status, 0) << t.output;
  EXPECT_NE(t.output.find("14 trip(s) in sqlite " + db_), std::string::npos) << t.output;
  EXPECT_NE(t.output.find("MODEL_MISMATCH;GUIDE_PRELOAD_LOW"), std::string::npos);

  ASSERT_EQ(trips({"list", "--db", db_, "--format", "csv", "--out", path("l.csv")}).status, 0);
  std::istringstream csv(file(path("l.csv")));
  std::string header, row;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("trip,direction,t_start,t_end,Fa,sigma_Fa,moment,sigma_moment,preload_scale,"
                         "sigma_preload_scale,mismatch,alarms,", 0), 0u) << header;
  int rows = 0;
  std::string third;
  while (std::getline(csv, row)) {
    if (++rows == 3) third = row;
  }
  EXPECT_EQ(rows, 14);
  const auto r3 = hoist::test::sampleRecord(3);
  EXPECT_EQ(third.rfind("3,down,", 0), 0u) << third;
  EXPECT_NE(third.find(",1,MODEL_MISMATCH;GUIDE_PRELOAD_LOW,"), std::string::npos) << third;  // mismatch, alarms

  const auto j = trips({"list", "--db", db_, "--format", "json"});
  ASSERT_EQ(j.status, 0);
  const auto a = nlohmann::json::parse(j.output);
  ASSERT_EQ(a.size(), 14u);
  EXPECT_EQ(a[2]["peak_speed"].get<double>(), r3.peak_speed);  // exact
  EXPECT_EQ(trips({"list", "--db", db_, "--shaft", "north"}).output.find("0 trip(s)") != std::string::npos, true);
}

TEST_F(TripsCli, ShowHasEveryColumnAndTheBinTable) {
  const auto s = trips({"show", "5", "--db", db_});
  ASSERT_EQ(s.status, 0) << s.output;
  for (const auto& f : tripFields()) EXPECT_NE(s.output.find("  " + std::string(f.column) + ": "), std::string::npos) << f.column;
  EXPECT_NE(s.output.find("depth bins (12, 10 m)"), std::string::npos);
  EXPECT_NE(s.output.find("resid_rms"), std::string::npos);
  const auto j = trips({"show", "5", "--db", db_, "--format", "json"});
  ASSERT_EQ(j.status, 0);
  EXPECT_EQ(nlohmann::json::parse(j.output)["bins"].size(), 12u);
  const auto missing = trips({"show", "99", "--db", db_});
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find("no trip 99"), std::string::npos);
}

TEST_F(TripsCli, TrendAndDepthMapArePngs) {
  const auto t = trips({"trend", "--db", db_, "--out", path("trend.png")});
  ASSERT_EQ(t.status, 0) << t.output;
  EXPECT_TRUE(isPng(path("trend.png")));
  EXPECT_NE(file(path("trend.gp")).find("preload_warning 0.85"), std::string::npos);
  EXPECT_NE(file(path("trend.dat")).find("\n14 "), std::string::npos);
  const auto d = trips({"depth-map", "--db", db_, "--out", path("depth.png"), "--value", "resid_mean"});
  ASSERT_EQ(d.status, 0) << d.output;
  EXPECT_TRUE(isPng(path("depth.png")));
  EXPECT_NE(d.output.find("14 trip(s) x 12 depth bins"), std::string::npos) << d.output;
  // An empty database still gives a (labelled) figure.
  { openSqliteStore(path("empty.sqlite")); }
  ASSERT_EQ(trips({"trend", "--db", path("empty.sqlite"), "--out", path("e.png")}).status, 0);
  EXPECT_TRUE(isPng(path("e.png")));
}

TEST_F(TripsCli, BaselineAndExport) {
  EXPECT_NE(trips({"baseline", "--db", db_}).output.find("none marked"), std::string::npos);
  const auto m = trips({"baseline", "--db", db_, "--mark", "1", "2", "3", "--unmark", "2"});
  ASSERT_EQ(m.status, 0) << m.output;
  EXPECT_NE(m.output.find("baseline of shaft '': 1 3"), std::string::npos) << m.output;
  const auto bad = trips({"baseline", "--db", db_, "--mark", "77"});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.output.find("no trip 77"), std::string::npos);

  ASSERT_EQ(trips({"export", "--db", db_, "--out", path("all.csv"), "--bins", path("bins.csv")}).status, 0);
  std::istringstream csv(file(path("all.csv")));
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, tripColumnList());
  std::istringstream bins(file(path("bins.csv")));
  int lines = 0;
  for (std::string l; std::getline(bins, l);) ++lines;
  EXPECT_EQ(lines, 1 + 14 * 12);
  ASSERT_EQ(trips({"export", "--db", db_, "--format", "json", "--out", path("all.json")}).status, 0);
  const auto j = nlohmann::json::parse(file(path("all.json")));
  ASSERT_EQ(j.size(), 14u);
  EXPECT_EQ(j[13]["id_note"], hoist::test::sampleRecord(14).id.note);
}

TEST_F(TripsCli, BadOptionsExit2NamingTheOption) {
  struct Case {
    std::vector<std::string> args;
    const char* expect;
  } cases[] = {
      {{"list"}, "--db is required"},
      {{"list", "--db", db_, "--format", "xml"}, "--format"},
      {{"list", "--db", "mysql://db/x"}, "--db: unknown scheme 'mysql'"},
      {{"list", "--db", "postgresql://u:hunter2@db/x"}, "--db: a password in the URL is refused"},
      {{"show", "0", "--db", db_}, "trip"},
      {{"show", "--db", db_}, "trip"},
      {{"trend", "--db", db_, "--out", "x.jpg"}, "--out: 'x.jpg' must name a .png file"},
      {{"trend", "--db", db_}, "--out"},
      {{"depth-map", "--db", db_, "--out", "d.png", "--value", "speed"}, "--value"},
      {{"ingest", "--db", db_, "--measurements", db_}, "--config is required"},
      {{"ingest", "--db", db_, "--config", db_, "--measurements", "/nonexistent.csv"}, "--measurements"},
      {{"ingest", "--db", db_, "--config", db_, "--measurements", db_, "--wall-start", "yesterday"}, "--wall-start"},
      {{"list", "--db", db_, "--out", "/nonexistent-dir/x.csv"}, "--out"},
      {{"frobnicate"}, "frobnicate"},
      {{}, "subcommand"},
  };
  for (const auto& c : cases) {
    const auto r = trips(c.args);
    std::string joined;
    for (const auto& a : c.args) joined += a + " ";
    EXPECT_EQ(r.status, 2) << joined << "\n" << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << joined << "\n" << r.output;
    EXPECT_EQ(r.output.find("hunter2"), std::string::npos) << r.output;
  }
  const auto cfg = path("bad.toml");
  std::ofstream(cfg) << "[history]\nkeep_days = -3\n";
  const auto r = trips({"list", "--config", cfg});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("bad.toml:2: history.keep_days"), std::string::npos) << r.output;
  // Garbage as a database: a clear error, exit 1.
  std::ofstream(path("junk.sqlite")) << std::string(5000, 'j');
  const auto g = trips({"list", "--db", path("junk.sqlite")});
  EXPECT_EQ(g.status, 1);
  EXPECT_NE(g.output.find("not a database"), std::string::npos) << g.output;
  const auto h = trips({"--help"});
  EXPECT_EQ(h.status, 0);
  EXPECT_NE(h.output.find("Examples:"), std::string::npos);
  EXPECT_EQ(trips({"--version"}).output.rfind("hoist-trips ", 0), 0u);
}

// A hoist-sim recording (rest, down 100 m, rest, up 100 m, rest) through the
// trip pipeline: two trips, in order, stored; the same file again with the
// same --first-trip stores nothing twice.
TEST_F(TripsCli, IngestsARecordingThroughTheTripPipeline) {
  const double amax = 1.0, vmax = 4.0, travel = 100.0;
  hoist::test::writeDownUpProfile(path("profile.csv"), 4.0, travel, vmax, amax);
  const auto sim = hoist::test::runCaptured(HOIST_SIM, {"--profile", path("profile.csv"), "--modes", "12",
                                                        "--write-measurements", path("meas.csv"), "--seed", "3", "-q",
                                                        "--out", path("sim.csv")});
  ASSERT_EQ(sim.status, 0) << sim.output;
  std::ofstream(path("twind.toml")) << "[model]\nmodes = 8\n[sensors]\nimu_accel_noise = 0.002\n"
                                       "[estimator]\nenabled = true\n[condition]\ndepth_bin = 20.0\n"
                                       "[history]\nkeep_days = 3650\n";
  const std::vector<std::string> args = {"ingest", "--config", path("twind.toml"), "--measurements", path("meas.csv"),
                                         "--db", db_, "--first-trip", "101", "--wall-start", "2026-12-06T08:00:00Z"};
  const auto in = trips(args);
  ASSERT_EQ(in.status, 0) << in.output;
  EXPECT_NE(in.output.find("2 trip(s) from"), std::string::npos) << in.output;
  EXPECT_NE(in.output.find("2 stored, 0 already there"), std::string::npos) << in.output;
  auto s = openSqliteStore(db_, true);
  const auto down = s->get("", 101), up = s->get("", 102);
  ASSERT_TRUE(down && up);
  EXPECT_EQ(down->direction, hoist::TripDirection::Down);
  EXPECT_EQ(up->direction, hoist::TripDirection::Up);
  EXPECT_NEAR(down->depth_end - down->depth_start, travel, 1.0);
  EXPECT_NEAR(down->peak_speed, vmax, 0.05);
  EXPECT_EQ(down->depth_bin, 20.0);
  EXPECT_GE(down->bins.size(), 5u);
  EXPECT_EQ(down->wall_start_us, 1796544000LL * 1000000LL + std::llround(down->t_start * 1e6));  // 2026-12-06T08:00Z
  EXPECT_GT(up->t_start, down->t_end);
  const auto again = trips(args);
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_NE(again.output.find("0 stored, 2 already there"), std::string::npos) << again.output;
  EXPECT_EQ(s->list().size(), 16u);
}
