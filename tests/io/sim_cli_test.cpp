// hoist-sim as a program: the documented contract (README, docs/model.md) (columns, exit status 2 on
// bad input with a message naming the key/line), and agreement with the
// independent reference solutions in tests/data at the default settings.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "process.hpp"
#include "hoist/forecast.hpp"
#include "hoist/scenario.hpp"
#include "hoist/simulator.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;
using hoist::test::nrms;
using hoist::test::readCsv;
using hoist::test::Table;

namespace {

using SimRun = hoist::test::CapturedRun;

SimRun sim(const std::vector<std::string>& args) { return hoist::test::runCaptured(HOIST_SIM, args); }

class SimCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(HOIST_TEST_WORK_DIR) / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }
  fs::path dir_;
};

const std::string kData = HOIST_TEST_DATA_DIR;

void expectMatchesReference(const Table& got, const Table& ref, double tol) {
  ASSERT_EQ(got.rows.size(), ref.rows.size());
  for (const char* c : {"x_c", "y_c", "theta", "lambda_0", "lambda_1", "lambda_2", "lambda_3", "lambda_4"}) {
    const double e = nrms(got.column(c), ref.column(c));
    EXPECT_LT(e, tol) << c;
    ::testing::Test::RecordProperty(std::string("nrms_") + c, std::to_string(e));
  }
}

}  // namespace

TEST_F(SimCli, HeaderIsTheContract) {
  const SimRun r = sim({"--profile", "trapezoid:t_end=1", "--out", path("o.csv"), "-q"});
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(path("o.csv"));
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "t,l,v,a,x_c,y_c,theta,lambda_0,lambda_1,lambda_2,lambda_3,lambda_4");
  const Table t = readCsv(path("o.csv"));
  EXPECT_EQ(t.rows.size(), 101u);
  EXPECT_NEAR(t.rows.back()[0], 1.0, 1e-12);
}

TEST_F(SimCli, PaperCaseStaticStartMatchesReference) {
  // The reference is the paper's truncation: static correction off.
  const SimRun r = sim({"--config", kData + "/c1-paper/shaft.toml", "--profile", kData + "/c1-paper/profile.csv", "--out",
                     path("o.csv"), "--shape-out", path("s.csv"), "--static-correction", "off"});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("peak |y_c|"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("steps/s"), std::string::npos) << r.output;
  // The contract is 2 %; we are far inside it at the default dt = 0.01.
  expectMatchesReference(readCsv(path("o.csv")), readCsv(kData + "/c1-paper/reference.csv"), 2e-3);

  // Shapes at 18, 36, 60 s (paper Fig. 4) against shape.csv.
  const Table s = readCsv(path("s.csv"));
  const Table ref = readCsv(kData + "/c1-paper/shape.csv");
  ASSERT_EQ(s.cols, (std::vector<std::string>{"t", "x", "y1", "y2"}));
  ASSERT_EQ(s.rows.size(), 3 * ref.rows.size());
  const char* cols[3][2] = {{"y1_t18", "y2_t18"}, {"y1_t36", "y2_t36"}, {"y1_t60", "y2_t60"}};
  for (int k = 0; k < 3; ++k) {
    std::vector<double> y1, y2;
    for (std::size_t i = 0; i < ref.rows.size(); ++i) {
      const auto& row = s.rows[k * ref.rows.size() + i];
      EXPECT_NEAR(row[1], ref.rows[i][0], 1e-9);
      y1.push_back(row[2]);
      y2.push_back(row[3]);
    }
    EXPECT_LT(nrms(y1, ref.column(cols[k][0])), 2e-3) << cols[k][0];
    EXPECT_LT(nrms(y2, ref.column(cols[k][1])), 2e-3) << cols[k][1];
  }
}

TEST_F(SimCli, PaperCaseRestStartMatchesReference) {
  const SimRun r = sim({"--config", kData + "/c1-paper-rest/shaft.toml", "--profile", "paper", "--out", path("o.csv"),
                     "-q", "--static-correction", "off"});
  ASSERT_EQ(r.status, 0) << r.output;
  expectMatchesReference(readCsv(path("o.csv")), readCsv(kData + "/c1-paper-rest/reference.csv"), 1e-2);
}

TEST_F(SimCli, PaperMethodAgreesWithFastMethod) {
  const SimRun a = sim({"--profile", "paper", "--t-end", "3", "--out", path("fast.csv"), "-q", "--modes", "20",
                     "--static-correction", "off"});
  const SimRun b = sim({"--profile", "paper", "--t-end", "3", "--out", path("paper.csv"), "-q", "--modes", "20",
                     "--method", "paper"});
  ASSERT_EQ(a.status, 0) << a.output;
  ASSERT_EQ(b.status, 0) << b.output;
  const Table f = readCsv(path("fast.csv")), p = readCsv(path("paper.csv"));
  ASSERT_EQ(f.rows.size(), 301u);
  for (const char* c : {"x_c", "y_c", "theta", "lambda_0", "lambda_1", "lambda_3"})
    EXPECT_LT(nrms(p.column(c), f.column(c)), 1e-3) << c;
}

TEST_F(SimCli, StaticCorrectionOption) {
  // Default on; --static-correction overrides the config; the paper method refuses it.
  const std::string off = write("off.toml", "[model]\nstatic_correction = false\n");
  SimRun r = sim({"--print-config"});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("static_correction = true"), std::string::npos) << r.output;
  r = sim({"--config", off, "--print-config"});
  EXPECT_NE(r.output.find("static_correction = false"), std::string::npos) << r.output;
  r = sim({"--config", off, "--static-correction", "on", "--print-config"});
  EXPECT_NE(r.output.find("static_correction = true"), std::string::npos) << r.output;
  r = sim({"--method", "paper", "--print-config"});
  EXPECT_NE(r.output.find("static_correction = false"), std::string::npos) << "paper implies off:\n" << r.output;
  r = sim({"--method", "paper", "--static-correction", "on", "--out", path("o.csv")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--method paper has no static correction"), std::string::npos) << r.output;
  r = sim({"--static-correction", "maybe", "--out", path("o.csv")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--static-correction"), std::string::npos) << r.output;
  const std::string bad = write("b.toml", "[model]\nstatic_correction = \"yes\"\n");
  r = sim({"--config", bad, "--out", path("o.csv")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("b.toml:2: model.static_correction"), std::string::npos) << r.output;
  // At n = 20 the corrected static tilt at l = 50 m is the exact continuum value 8.055e-4 rad.
  r = sim({"--modes", "20", "--t-end", "0.01", "--out", path("o.csv"), "-q"});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NEAR(readCsv(path("o.csv")).column("theta").front(), 8.055e-4, 0.01 * 8.055e-4);
}

TEST_F(SimCli, CommandLineOverridesTheConfig) {
  const std::string cfg = write("c.toml", "[model]\nmodes = 30\ninitial = \"static\"\n");
  const SimRun r = sim({"--config", cfg, "--modes", "12", "--initial", "rest", "--print-config"});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("modes = 12"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("initial = \"rest\""), std::string::npos) << r.output;
}

TEST_F(SimCli, WriteProfileWritesThePaperTrapezoid) {
  const SimRun r = sim({"--profile", "paper", "--write-profile", path("p.csv")});
  ASSERT_EQ(r.status, 0) << r.output;
  const Table p = readCsv(path("p.csv")), ref = readCsv(kData + "/c1-paper/profile.csv");
  ASSERT_EQ(p.rows.size(), ref.rows.size());
  for (std::size_t i = 0; i < p.rows.size(); ++i)
    for (int j = 0; j < 4; ++j) ASSERT_NEAR(p.rows[i][j], ref.rows[i][j], 1e-9) << i << "," << j;
}

TEST_F(SimCli, BadInputExitsWithStatus2AndNamesTheProblem) {
  struct Case {
    std::vector<std::string> args;
    std::string expect;
  };
  const std::string bad_key = write("k.toml", "[cage]\nmass = 800\ninertia = 870\nhalf_hieght = 8\n");
  const std::string bad_val = write("v.toml", "[load]\neccentric_force = nan\n");
  const std::string bad_csv = write("p.csv", "t,v,a\n0,0,0\n0.5,0,0\n0.4,0,0\n");
  const std::string no_col = write("q.csv", "t,l,v\n0,50,0\n1,50,0\n");
  const std::vector<Case> cases = {
      {{"--config", bad_key, "--out", path("o.csv")}, "k.toml:4: cage.half_hieght: unknown key (did you mean 'half_height'?)"},
      {{"--config", bad_val, "--out", path("o.csv")}, "v.toml:2: load.eccentric_force"},
      {{"--profile", bad_csv, "--out", path("o.csv")}, "p.csv:4: t:"},
      {{"--profile", no_col, "--out", path("o.csv")}, "q.csv:1: a: required column missing"},
      {{"--profile", "trapezoid:travel=340,t_end=100", "--out", path("o.csv")}, "leaves the shaft"},
      {{"--profile", "trapzoid", "--out", path("o.csv")}, "did you mean 'trapezoid'"},
      {{"--out", path("o.csv"), "--dt", "-1"}, "--dt"},
      {{"--out", path("o.csv"), "--method", "exact"}, "--method"},
      {{"--out", path("o.csv"), "--modes", "0"}, "--modes"},
      {{"--out", path("o.csv"), "--shape-out", path("s.csv"), "--shape-times", "18,x"}, "--shape-times"},
      {{"--out", path("o.csv"), "--shape-out", path("s.csv"), "--shape-times", "100"}, "outside the run"},
      {{"--profile", "paper"}, "--out"},
      {{"--config", path("missing.toml"), "--out", path("o.csv")}, "missing.toml"},
  };
  for (const auto& c : cases) {
    const SimRun r = sim(c.args);
    EXPECT_EQ(r.status, 2) << c.args[1] << ":\n" << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << "want '" << c.expect << "' in:\n" << r.output;
  }
}

TEST_F(SimCli, HelpDescribesTheOptions) {
  const SimRun r = sim({"--help"});
  EXPECT_EQ(r.status, 0);
  for (const char* opt : {"--config", "--profile", "--out", "--dt", "--modes", "--initial", "--method",
                          "--static-correction", "--shape-out",
                          "--shape-times", "trapezoid:"})
    EXPECT_NE(r.output.find(opt), std::string::npos) << opt;
}

// `hoist-sim --estop-at T` is the same run as the look-ahead
// forecast's "estop" scenario made from the twin's state at T.
TEST_F(SimCli, EstopAtIsTheForecastsEstopScenario) {
  const SimRun r = sim({"--profile", "paper", "--modes", "20", "--estop-at", "20", "--estop-decel", "2.5",
                        "--estop-jerk", "8", "--t-end", "35", "-q", "--out", path("o.csv")});
  ASSERT_EQ(r.status, 0) << r.output;
  const Table t = readCsv(path("o.csv"));
  // The forecast from the snapshot at 20 s, horizon 15 s.
  hoist::ShaftParams p;
  p.n = 20;
  auto model = std::make_shared<const hoist::ShaftModel>(p);
  hoist::ForecastOptions o;
  o.horizon = 15.0;
  hoist::FastSolver s(model);
  hoist::SimulationOptions so;
  so.dt = 0.01;
  so.max_step = 0.0025;
  so.t_end = 20.0;
  hoist::simulate(s, hoist::HoistProfile::trapezoid(), so, {});
  hoist::FastSolverState st(20);
  s.saveState(st);
  hoist::ForecastWorkspace ws(model, o);
  hoist::ForecastSummary f;
  const hoist::MotionProfile stop = hoist::estopProfile(st.t, st.kin, 2.5, 8.0);
  hoist::forecast(ws, st, stop, f);
  ASSERT_EQ(f.status, hoist::ForecastStatus::Ok);
  double l0min = 1e300, l0max = -1e300, yc = 0, th = 0, lam1 = 0;
  const int ct = t.col("t"), cl0 = t.col("lambda_0"), cy = t.col("y_c"), cth = t.col("theta"), c1 = t.col("lambda_1");
  int n = 0;
  for (const auto& row : t.rows) {
    if (row[ct] < 20.0 - 1e-9) continue;
    ++n;
    l0min = std::min(l0min, row[cl0]);
    l0max = std::max(l0max, row[cl0]);
    yc = std::max(yc, std::abs(row[cy]));
    th = std::max(th, std::abs(row[cth]));
    lam1 = std::max(lam1, std::abs(row[c1]));
  }
  EXPECT_EQ(n, 1501);
  auto rel = [](double a, double b) { return std::abs(a - b) / std::max(std::abs(a), std::abs(b)); };
  EXPECT_LE(rel(l0min, f.lambda0_min), 1e-9) << l0min << " " << f.lambda0_min;
  EXPECT_LE(rel(l0max, f.lambda0_max), 1e-9);
  EXPECT_LE(rel(yc, f.peak_y_c), 1e-9);
  EXPECT_LE(rel(th, f.peak_theta), 1e-9);
  EXPECT_LE(rel(lam1, f.peak_lambda[0]), 1e-9);
  // The stop itself: at rest at the scenario's end length from its end on.
  EXPECT_NEAR(t.rows.back()[t.col("l")], stop.end().l, 1e-12);
  EXPECT_EQ(t.rows.back()[t.col("v")], 0.0);
  // Bad values are bad input.
  EXPECT_EQ(sim({"--estop-at", "100", "-q", "--out", path("x.csv")}).status, 2);
  EXPECT_EQ(sim({"--estop-at", "20", "--estop-decel", "0", "-q", "--out", path("x.csv")}).status, 2);
}

// ---- hostile and careless runs ------------------------------------

// A state that leaves the plausible range stops the run with exit
// status 1, naming the time and the quantity.  A real input reaches it: a
// 200 kN eccentric load on the paper's 800-kg cage (accepted: the load has no
// upper bound) applied as a step (rest start) tilts the cage so far that its
// sleeves are more than 1 m off the axis after 0.1 s.
TEST_F(SimCli, ImplausibleStateExitsOneNamingTimeAndQuantity) {
  const std::string cfg = write("ecc.toml", "[load]\neccentric_force = 2e5\n");
  const SimRun r = sim({"--config", cfg, "--profile", "paper", "--initial", "rest", "--out", path("o.csv"), "-q"});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("implausible state at t = 0.1 s: y_c = "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(plausible: |y_c| <= 1;"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("10 good rows are written"), std::string::npos) << r.output;
  // The good rows are in the file, complete (streamed before the failure).
  const Table t = readCsv(path("o.csv"));
  ASSERT_EQ(t.rows.size(), 10u);
  EXPECT_NEAR(t.rows.back()[0], 0.09, 1e-12);
}

// Rows are streamed, so --t-end no longer sizes a vector
// (--t-end 1e9 died with std::bad_alloc); runs that cannot fit are refused
// up front, naming the option.
TEST_F(SimCli, HugeTEndIsRefusedNamingTheOptionNotBadAlloc) {
  // 1e11 rows (~18 TB) onto a regular file: more than the disk has.
  SimRun r = sim({"--profile", "paper", "--t-end", "1e9", "--out", path("o.csv")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("hoist-sim: error: --t-end 1e+09: the output would be about 18.0 TB (1e+11 rows"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("are free for --out"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("bad_alloc"), std::string::npos) << r.output;
  // More than 1e12 output steps: refused whatever the output (here a device).
  r = sim({"--profile", "paper", "--t-end", "1e11", "--out", "/dev/null"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--t-end 1e+11: 1e+13 output steps at --dt 0.01 s, more than 1e+12"), std::string::npos)
      << r.output;
  r = sim({"--profile", "paper", "--t-end", "nan", "--out", path("o.csv")});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--t-end"), std::string::npos) << r.output;
}

using hoist::test::vmRssKb;

// A long run (1e8 rows, to /dev/null) states its estimated rows,
// size and time before it starts, and its memory stays flat while it runs
// (it used to keep every row: 9.6 GB for these 1e8 rows).
TEST_F(SimCli, LongRunStatesItsSizeAndStreamsWithFlatMemory) {
  const std::string log = path("sim.log");
  hoist::test::Process p({HOIST_SIM, "--profile", "paper", "--t-end", "1e6", "--max-step", "0.01", "--out",
                          "/dev/null"},
                         log);
  ASSERT_TRUE(p.started());
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (hoist::test::readFile(log).find("large run") == std::string::npos && p.running() &&
         std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::string text = hoist::test::readFile(log);
  ASSERT_TRUE(p.running()) << text;
  EXPECT_NE(text.find("hoist-sim: large run: about 1e+08 rows, 18.0 GB to /dev/null, about "), std::string::npos)
      << text;
  EXPECT_NE(text.find("us per step measured)"), std::string::npos) << text;
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  const long rss1 = vmRssKb(p.pid());
  std::this_thread::sleep_for(std::chrono::milliseconds(2000));
  const long rss2 = vmRssKb(p.pid());
  ASSERT_TRUE(p.running());
  p.signal(SIGKILL);
  EXPECT_GT(rss1, 0);
#ifndef HOIST_SANITIZED  // a sanitizer runtime has its own, larger footprint
  EXPECT_LT(rss2, 64 * 1024) << "KiB";
#endif
  EXPECT_LT(rss2 - rss1, 2048) << "RSS grew from " << rss1 << " to " << rss2 << " KiB in 2 s of streaming";
}

// Without a terminal, --progress gives one line per 10 %; -q alone is silent.
TEST_F(SimCli, ProgressLinesWithoutATerminal) {
  SimRun r = sim({"--profile", "trapezoid:t_end=2", "--out", path("o.csv"), "-q", "--progress"});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("hoist-sim: progress  10 %"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("hoist-sim: progress 100 %"), std::string::npos) << r.output;
  r = sim({"--profile", "trapezoid:t_end=2", "--out", path("o.csv"), "-q"});
  ASSERT_EQ(r.status, 0);
  EXPECT_EQ(r.output, "");
}

// Every file written to its last byte, or exit 1 naming the
// option, the path and the errno text (the streaming writer included).
TEST_F(SimCli, FullDiskAndUnwritablePathsExitOneNamingTheFile) {
  // The full disk: a 64 KiB file size limit (runCapturedWithFileSizeLimit;
  // /dev/full is refused now, as every device node: last case).
  struct Case {
    std::vector<std::string> args;
    std::string expect;
    bool full;
  };
  const std::vector<Case> cases = {
      {{"--profile", "paper", "--out", path("full.csv")}, "--out " + path("full.csv") + ": write failed: File too large",
       true},
      {{"--profile", "paper", "--out", "/dev/null", "--shape-out", path("s.csv"), "--shape-times", "18,36,60",
        "--shape-points", "2001"},
       "--shape-out " + path("s.csv") + ": write failed: File too large", true},
      {{"--profile", "paper", "--write-profile", path("p.csv")},
       "--write-profile " + path("p.csv") + ": write failed: File too large", true},
      {{"--profile", "paper", "--out", path("no/such/dir/o.csv")},
       "--out " + path("no/such/dir/o.csv") + ": cannot open for writing: No such file or directory", false},
      {{"--profile", "paper", "--out", "/dev/full"}, "--out /dev/full: exists and is a character device", false},
  };
  for (const auto& c : cases) {
    const SimRun r = c.full ? hoist::test::runCapturedWithFileSizeLimit(HOIST_SIM, c.args, 64) : sim(c.args);
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("hoist-sim: error: " + c.expect), std::string::npos) << "want '" << c.expect << "' in:\n"
                                                                                 << r.output;
    EXPECT_EQ(r.output.find("wrote "), std::string::npos) << "success claimed:\n" << r.output;
  }
}

// Out of memory is exit 1 with the options of the run, never an
// uncaught std::bad_alloc (abort, exit 134).  The address space is limited
// below what n = 1000 modes need (not under a sanitizer: its shadow memory
// needs the address space).
TEST_F(SimCli, OutOfMemoryIsExitOneNamingTheOptions) {
#ifdef HOIST_SANITIZED
  GTEST_SKIP() << "ulimit -v and a sanitizer runtime do not mix";
#endif
  const SimRun r = hoist::test::runCaptured(
      "/bin/sh", {"-c", "ulimit -v 120000 && exec \"$0\" --modes 1000 --profile paper --t-end 1 -q --out \"$1\"",
                  HOIST_SIM, path("o.csv")});
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("hoist-sim: error: out of memory (std::bad_alloc) in: hoist-sim --modes 1000 --profile "
                          "paper --t-end 1 -q --out"),
            std::string::npos)
      << r.output;
}
