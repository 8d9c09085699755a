// hoist-sim --write-measurements and hoist-estimate as programs: synthetic
// measurements of a shaft whose load the estimating config does not know,
// the load recovered from them; the CSV contract; exit status 2 naming the
// file, line, column or option on bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <fstream>
#include <sstream>

#include "process.hpp"
#include "test_util.hpp"

namespace fs = std::filesystem;
using hoist::test::CapturedRun;
using hoist::test::readCsv;
using hoist::test::Table;

namespace {

CapturedRun sim(const std::vector<std::string>& a) { return hoist::test::runCaptured(HOIST_SIM, a); }
CapturedRun estimate(const std::vector<std::string>& a) { return hoist::test::runCaptured(HOIST_ESTIMATE, a); }

class EstimateCli : public ::testing::Test {
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
  std::vector<std::string> lines(const std::string& name) const {
    std::ifstream in(path(name));
    std::vector<std::string> v;
    std::string l;
    while (std::getline(in, l)) v.push_back(l);
    return v;
  }
  fs::path dir_;
};

constexpr const char* kContract =
    "t,l,Fa,b,moment,sigma_Fa,sigma_moment,y_c,theta,sigma_y_c,sigma_theta,lambda_0,lambda_1,lambda_2,lambda_3,"
    "lambda_4,nis,nis_window,mismatch";

}  // namespace

// The end-to-end case: the truth at n = 100 with Fa 1500 N at
// b 0.6 m (the paper config says 1000 N at 1 m), estimated at n = 25 with the
// paper config written as hoist-twind's configuration.
TEST_F(EstimateCli, SimMeasurementsOfAnotherLoadAreRecovered) {
  const std::string truth = write("truth.toml", "[load]\neccentric_force = 1500.0\noffset = 0.6\n");
  const std::string profile = "trapezoid:vmax=5,amax=1,travel=150,t_end=45,dt=0.01";
  const CapturedRun s = sim({"--config", truth, "--profile", profile, "--modes", "100", "--write-measurements",
                             path("meas.csv"), "--seed", "7", "-q"});
  ASSERT_EQ(s.status, 0) << s.output;
  EXPECT_EQ(lines("meas.csv").front(), "t,l,v,a,f_y,omega,rope_load");
  const std::string cfg = write("twind.toml",
                                "[model]\nmodes = 40\n[service]\nmax_step = 0.0025\n[alarms]\n[forecast]\n"
                                "[sensors]\nimu_accel_noise = 0.002\nimu_rate_noise = 0.0001\nrope_load_noise = 20.0\n"
                                "[estimator]\nenabled = true\n");
  const CapturedRun e = estimate({"--config", cfg, "--measurements", path("meas.csv"), "--out", path("est.csv"),
                                  "--modes", "25"});
  ASSERT_EQ(e.status, 0) << e.output;
  EXPECT_EQ(lines("est.csv").front().rfind(kContract, 0), 0u) << lines("est.csv").front();
  const Table t = readCsv(path("est.csv"));
  const Table m = readCsv(path("meas.csv"));
  ASSERT_EQ(t.rows.size(), m.rows.size());
  const auto& last = t.rows.back();
  const double Fa = last[t.col("Fa")], M = last[t.col("moment")], b = last[t.col("b")];
  const double sFa = last[t.col("sigma_Fa")], sM = last[t.col("sigma_moment")];
  ::testing::Test::RecordProperty("Fa", std::to_string(Fa));
  ::testing::Test::RecordProperty("moment", std::to_string(M));
  EXPECT_NEAR(Fa, 1500.0, 15.0) << e.output;   // 1 %
  EXPECT_NEAR(M, 900.0, 45.0) << e.output;     // 5 %
  EXPECT_NEAR(b, 0.6, 0.03) << e.output;
  EXPECT_LT(std::abs(Fa - 1500.0), 3.0 * sFa + 1e-9) << "truth outside the 3-sigma band";
  EXPECT_LT(std::abs(M - 900.0), 3.0 * sM + 1e-9) << "truth outside the 3-sigma band";
  // The model is right: no MODEL_MISMATCH anywhere.
  for (double x : t.column("mismatch")) ASSERT_EQ(x, 0.0);
  EXPECT_EQ(last[t.col("sensors")], 7.0);
  // The summary names the final estimate and the mismatch verdict.
  EXPECT_NE(e.output.find("Fa = "), std::string::npos) << e.output;
  EXPECT_NE(e.output.find("first none"), std::string::npos) << e.output;
}

// Noise-free measurements are the sensor model on the run itself: the rope
// load is the result's lambda_0, and at the (static) start a tilted cage reads
// g theta.  The noise is seeded and has the asked standard deviation.
TEST_F(EstimateCli, SimMeasurementsFollowTheSensorModelAndTheSeed) {
  const std::string cfg = write("c.toml", "[load]\neccentric_force = 2000.0\noffset = -0.5\n[model]\nmodes = 10\n"
                                          "[sensors]\nrope_load_noise = 50.0\n");
  // An S-curve starts at rest (a = 0): the static start is an equilibrium.
  const std::string prof = "scurve:vmax=4,amax=1,jmax=1,travel=30,t_end=14,dt=0.01";
  ASSERT_EQ(sim({"--config", cfg, "--profile", prof, "--out", path("r.csv"), "--write-measurements",
                 path("clean.csv"), "--sensor-noise", "0,0,0", "-q"}).status, 0);
  const Table r = readCsv(path("r.csv")), c = readCsv(path("clean.csv"));
  ASSERT_EQ(r.rows.size(), c.rows.size());
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    // The row's time as a sensor clock stamps it (whole microseconds, what
    // hoist-replay's utime carries exactly), the step's to half a microsecond.
    const double tm = c.rows[i][c.col("t")];
    ASSERT_EQ(tm, std::round(tm * 1e6) / 1e6) << "row " << i;
    ASSERT_NEAR(tm, r.rows[i][r.col("t")], 0.5e-6) << "row " << i;
    ASSERT_EQ(c.rows[i][c.col("l")], r.rows[i][r.col("l")]);
    ASSERT_EQ(c.rows[i][c.col("rope_load")], r.rows[i][r.col("lambda_0")]);
  }
  const double theta0 = r.rows[0][r.col("theta")];
  ASSERT_NE(theta0, 0.0);
  EXPECT_NEAR(c.rows[0][c.col("f_y")], 9.81 * theta0, 1e-6 * std::abs(9.81 * theta0));
  EXPECT_NEAR(c.rows[0][c.col("omega")], 0.0, 1e-12);

  // Default noise: the config's [sensors] (rope 50 N; the IMU's defaults).
  ASSERT_EQ(sim({"--config", cfg, "--profile", prof, "--write-measurements", path("n1.csv"), "-q"}).status, 0);
  ASSERT_EQ(sim({"--config", cfg, "--profile", prof, "--write-measurements", path("n1b.csv"), "--seed", "1", "-q"})
                .status,
            0);
  ASSERT_EQ(sim({"--config", cfg, "--profile", prof, "--write-measurements", path("n2.csv"), "--seed", "2", "-q"})
                .status,
            0);
  EXPECT_EQ(lines("n1.csv"), lines("n1b.csv")) << "the default seed is 1";
  EXPECT_NE(lines("n1.csv"), lines("n2.csv"));
  const Table n = readCsv(path("n1.csv"));
  auto stdOf = [&](const char* col) {
    double s2 = 0;
    for (std::size_t i = 0; i < n.rows.size(); ++i) {
      const double d = n.rows[i][n.col(col)] - c.rows[i][c.col(col)];
      s2 += d * d;
    }
    return std::sqrt(s2 / n.rows.size());
  };
  EXPECT_NEAR(stdOf("rope_load"), 50.0, 5.0);
  EXPECT_NEAR(stdOf("f_y"), 0.002, 0.0002);
  EXPECT_NEAR(stdOf("omega"), 1e-4, 1e-5);

  // --write-profile does not end the run when measurements are asked for.
  ASSERT_EQ(sim({"--config", cfg, "--profile", prof, "--write-profile", path("p.csv"), "--write-measurements",
                 path("n3.csv"), "-q"}).status, 0);
  EXPECT_EQ(lines("n3.csv"), lines("n1.csv"));
  // Bad options are bad input.
  EXPECT_EQ(sim({"--profile", prof, "--out", path("x.csv"), "--seed", "3"}).status, 2) << "--seed alone";
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--sensor-noise", "1,2"}, {"--sensor-noise", "1,-2,3"}, {"--sensor-noise", "a,b,c"},
        {"--method", "paper", "--static-correction", "off"}}) {
    std::vector<std::string> a = {"--profile", prof, "--write-measurements", path("x.csv")};
    a.insert(a.end(), bad.begin(), bad.end());
    const CapturedRun x = sim(a);
    EXPECT_EQ(x.status, 2) << bad[0] << ": " << x.output;
  }
}

// Absent sensor columns: what is not observed is nan with its sigma.
TEST_F(EstimateCli, UnobservedValuesAreNan) {
  std::string text = "t,l,v,a,f_y,omega\n";
  for (int i = 0; i <= 200; ++i) {
    text += std::to_string(0.01 * i);
    text += ",50,0,0,0.0005,0\n";
  }
  write("imu.csv", text);
  const CapturedRun e = estimate({"--config", write("c.toml", "[model]\nmodes = 10\n"), "--measurements",
                                  path("imu.csv"), "--out", path("o.csv"), "-q"});
  ASSERT_EQ(e.status, 0) << e.output;
  const Table t = readCsv(path("o.csv"));
  const auto& last = t.rows.back();
  EXPECT_TRUE(std::isnan(last[t.col("Fa")]));
  EXPECT_TRUE(std::isnan(last[t.col("sigma_Fa")]));
  EXPECT_TRUE(std::isnan(last[t.col("b")]));
  EXPECT_TRUE(std::isfinite(last[t.col("moment")]));
  EXPECT_GT(last[t.col("sigma_moment")], 0.0);
  EXPECT_EQ(last[t.col("sensors")], 3.0);
  EXPECT_EQ(last[t.col("fa_observed")], 0.0);
  EXPECT_EQ(last[t.col("moment_observed")], 1.0);
  for (double x : t.column("mismatch")) ASSERT_EQ(x, 0.0);  // a cage at rest that reads steadily: no mismatch
}

// A cage "at rest" whose IMU reads a 1 Hz oscillation of 5 sigma: no load
// explains it, so the window's NIS exceeds its bound; the summary names the
// first time, the window's NIS and the bound.
TEST_F(EstimateCli, MismatchIsReportedWithTheWindowsNisAndBound) {
  std::string text = "t,l,v,a,f_y,omega\n";
  char row[128];
  for (int i = 0; i <= 1000; ++i) {
    std::snprintf(row, sizeof row, "%.2f,50,0,0,%.17g,0\n", 0.01 * i, 0.01 * std::sin(2.0 * M_PI * 0.01 * i));
    text += row;
  }
  const CapturedRun e = estimate({"--config", write("c.toml", "[model]\nmodes = 5\n"), "--measurements",
                                  write("m.csv", text), "--out", path("o.csv")});
  ASSERT_EQ(e.status, 0) << e.output;
  const Table t = readCsv(path("o.csv"));
  double first = -1.0;
  for (const auto& r : t.rows)
    if (r[t.col("mismatch")] == 1.0) {
      first = r[t.col("t")];
      EXPECT_EQ(r[t.col("nis_exceeded")], 1.0);
      EXPECT_GT(r[t.col("nis_window")], r[t.col("nis_bound")]);
      break;
    }
  ASSERT_GT(first, 0.0) << "MODEL_MISMATCH never rose";
  char want[64];
  std::snprintf(want, sizeof want, "first at t = %.2f s (window NIS ", first);
  EXPECT_NE(e.output.find(want), std::string::npos) << e.output;
  EXPECT_NE(e.output.find("> bound "), std::string::npos) << e.output;
}

TEST_F(EstimateCli, BadInputExitsTwoNamingTheThing) {
  const std::string cfg = write("c.toml", "[model]\nmodes = 10\n");
  const std::string good = write("m.csv", "t,l,v,a,rope_load\n0,50,0,0,10000\n0.01,50,0,0,10010\n");
  struct Case {
    std::vector<std::string> args;
    std::string want;
  };
  const std::vector<Case> cases = {
      {{"--config", cfg, "--measurements", write("b1.csv", "t,v,a\n0,0,0\n"), "--out", path("o.csv")},
       "b1.csv:1: l: required column missing"},
      {{"--config", cfg, "--measurements",
        write("b2.csv", "t,l,v,a,omega\n0,50,0,0,0\n0.01,50,0,0,x\n"), "--out", path("o.csv")},
       "b2.csv:3: omega: not a number"},
      {{"--config", write("b3.toml", "[model]\nmodes = 10\n[estimator]\nnis_windw = 3.0\n"), "--measurements", good,
        "--out", path("o.csv")},
       "b3.toml:4: estimator.nis_windw: unknown key (did you mean 'nis_window'?)"},
      {{"--config", write("b4.toml", "[sensors]\nrope_load_noise = -1.0\n"), "--measurements", good, "--out",
        path("o.csv")},
       "b4.toml:2: sensors.rope_load_noise"},
      {{"--config", write("b5.toml", "[service]\nmax_step = \"fast\"\n"), "--measurements", good, "--out",
        path("o.csv")},
       "b5.toml:2: service.max_step: must be a number"},
      {{"--config", cfg, "--measurements", write("b6.csv", "t,l,v,a\n0,5000,0,0\n0.01,5000,0,0\n"), "--out",
        path("o.csv")},
       "b6.csv"},
      {{"--config", cfg, "--measurements", good, "--out", path("o.csv"), "--modes", "0"}, "--modes"},
      {{"--config", cfg, "--measurements", good}, "--out"},
      {{"--config", cfg, "--measurements", path("none.csv"), "--out", path("o.csv")}, "none.csv"},
  };
  for (const auto& c : cases) {
    const CapturedRun r = estimate(c.args);
    EXPECT_EQ(r.status, 2) << c.want << ": " << r.output;
    EXPECT_NE(r.output.find(c.want), std::string::npos) << "want '" << c.want << "' in: " << r.output;
  }
  // Unwritable output: exit 1 naming it.
  const CapturedRun w = estimate({"--config", cfg, "--measurements", good, "--out", "/nonexistent/dir/o.csv"});
  EXPECT_EQ(w.status, 1) << w.output;
  EXPECT_NE(w.output.find("/nonexistent/dir/o.csv"), std::string::npos) << w.output;
}

TEST_F(EstimateCli, HelpVersionAndProgress) {
  const CapturedRun h = estimate({"--help"});
  EXPECT_EQ(h.status, 0);
  EXPECT_NE(h.output.find("hoist-estimate"), std::string::npos);
  EXPECT_NE(h.output.find("--measurements"), std::string::npos);
  const CapturedRun v = estimate({"--version"});
  EXPECT_EQ(v.status, 0);
  EXPECT_EQ(v.output.rfind("hoist-estimate ", 0), 0u) << v.output;
  std::string text = "t,l,v,a,rope_load\n";
  for (int i = 0; i <= 300; ++i) {
    text += std::to_string(0.01 * i);
    text += ",50,0,0,10000\n";
  }
  const CapturedRun p = estimate({"--config", write("c.toml", "[model]\nmodes = 5\n"), "--measurements",
                                  write("m.csv", text), "--out", path("o.csv"), "--progress", "-q"});
  EXPECT_EQ(p.status, 0) << p.output;
  EXPECT_NE(p.output.find("progress 100 %"), std::string::npos) << p.output;
}

// The calibration options: --known-load validated (exit 2 naming it), the
// learned offset written by --offset-out and read back by --offset-in; a
// corrupt offset file is refused naming its key.
TEST_F(EstimateCli, KnownLoadAndOffsetFiles) {
  const std::string truth = write("truth.toml", "[load]\neccentric_force = 0.0\noffset = 0.0\n");
  const CapturedRun s = sim({"--config", truth, "--profile", "trapezoid:vmax=5,amax=1,travel=150,t_end=45,dt=0.01",
                             "--modes", "25", "--write-measurements", path("meas.csv"), "--seed", "3", "-q"});
  ASSERT_EQ(s.status, 0) << s.output;
  const std::string cfg = write("twind.toml", "[sensors]\nimu_accel_offset_sigma = 0.005\n");
  auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = {"--config", cfg, "--measurements", path("meas.csv"), "--out", path("est.csv")};
    a.insert(a.end(), extra.begin(), extra.end());
    return estimate(a);
  };
  for (const char* bad : {"1,2,3", "5,1,0,0", "0,10,-5,0", "0,10,0,x", "0,10,0,99"}) {
    const CapturedRun e = run({"--known-load", bad});
    EXPECT_EQ(e.status, 2) << bad << ": " << e.output;
    EXPECT_NE(e.output.find("--known-load"), std::string::npos) << e.output;
  }
  const CapturedRun c = run({"--known-load", "-1,1000,0,0", "--known-load", "2000,2001,0,0", "--offset-out",
                             path("offset.txt")});
  ASSERT_EQ(c.status, 0) << c.output;
  EXPECT_NE(c.output.find("accelerometer offset"), std::string::npos) << c.output;
  const std::vector<std::string> f = lines("offset.txt");
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[1].rfind("accel_offset = ", 0), 0u);
  const double off = std::stod(f[1].substr(15)), sig = std::stod(f[2].substr(8));
  EXPECT_GT(sig, 0.0);
  EXPECT_LT(sig, 0.001);              // the known load teaches it
  EXPECT_LT(std::abs(off), 3.0 * sig);  // hoist-sim's IMU has no offset
  const CapturedRun r = run({"--offset-in", path("offset.txt")});
  EXPECT_EQ(r.status, 0) << r.output;
  write("bad.txt", "accel_offset = 0.01\nsigma = -1\n");
  const CapturedRun b = run({"--offset-in", path("bad.txt")});
  EXPECT_EQ(b.status, 2) << b.output;
  EXPECT_NE(b.output.find("sigma"), std::string::npos) << b.output;
}

// Detectability, stated (issue 30): each whole trip of the data (rest,
// motion, rest) gets the sentence of its preload identification in the
// summary -- "this IMU can / cannot see a 30 % preload loss on this trip"
// -- computed by the daemon's TripRecorder on the same estimates; none with
// --no-trips or -q.  A config whose sensor noise is far below the data's
// makes many load changes: the summary lists the first 8 and counts the rest.
// The same lines carry MODEL_MISMATCH's trip-end preload test
// (hoist/preload_verdict.hpp): quiet on the healthy trip, firing on one
// whose guide ropes are at x0.6.
TEST_F(EstimateCli, EachTripStatesWhetherTheImuCanSeeAPreloadLoss) {
  // 5 s at rest, 150 m down (vmax 5, amax 1), 15 s at rest.
  std::string prof = "t,v,a\n";
  for (int i = 0; i <= 5500; ++i) {
    const double t = i * 0.01, tt = t - 5.0;
    double v = 0.0, a = 0.0;
    if (tt >= 0.0 && tt < 5.0) v = tt, a = 1.0;
    else if (tt >= 5.0 && tt < 30.0) v = 5.0;
    else if (tt >= 30.0 && tt < 35.0) v = 5.0 - (tt - 30.0), a = -1.0;
    char row[96];
    std::snprintf(row, sizeof row, "%.2f,%.6f,%.1f\n", t, v, a);
    prof += row;
  }
  write("rest_trip.csv", prof);
  const std::string truth = write("truth.toml", "[load]\neccentric_force = 1500.0\noffset = 0.6\n");
  const std::string cfg = write("twin.toml", "[model]\nmodes = 25\n");
  ASSERT_EQ(sim({"--config", truth, "--profile", path("rest_trip.csv"), "--initial", "static", "--modes", "50",
                 "--write-measurements", path("m.csv"), "--seed", "4", "-q"})
                .status,
            0);
  const std::vector<std::string> base = {"--config", cfg, "--measurements", path("m.csv"), "--out", path("e.csv")};
  const CapturedRun e = estimate(base);
  ASSERT_EQ(e.status, 0) << e.output;
  const std::string all = e.output;
  // Which of the two is the identification's (tested in
  // preload_identification_test); here: the sentence of the one whole trip.
  EXPECT_TRUE(std::regex_search(all, std::regex(R"(hoist-estimate: trip 1 \(down 50 -> 200 m, t = 5\.0 \.\. 40\.0 s\): )"
                                                R"(this IMU can(not)? see a 30 % preload loss on this trip)")))
      << all;
  EXPECT_EQ(all.find("trip 2"), std::string::npos) << all;
  // MODEL_MISMATCH's trip-end preload test on this healthy trip: quiet.
  EXPECT_EQ(all.find("trip-end preload test fired"), std::string::npos) << all;
  EXPECT_EQ(all.find(": MODEL_MISMATCH."), std::string::npos) << all;
  // ... and on the same trip with both guide ropes at x0.6 (a calibrated IMU):
  // it fires, naming the preload the trip fits.
  const std::string weak = write("weak.toml", "[guide_ropes]\npreload = [18000.0, 18000.0]\n[load]\n"
                                              "eccentric_force = 1500.0\noffset = 0.6\n");
  ASSERT_EQ(sim({"--config", weak, "--profile", path("rest_trip.csv"), "--initial", "static", "--modes", "50",
                 "--write-measurements", path("weak.csv"), "--seed", "4", "-q"})
                .status,
            0);
  const std::string cal = write("cal.toml", "[model]\nmodes = 25\n[sensors]\nimu_accel_offset_sigma = 0.0\n");
  const CapturedRun w = estimate({"--config", cal, "--measurements", path("weak.csv"), "--out", path("w.csv")});
  ASSERT_EQ(w.status, 0) << w.output;
  EXPECT_TRUE(std::regex_search(w.output, std::regex(R"(trip 1 \(down[^\n]*whole-trip fit: preload x0\.[56][0-9] \+- )"
                                                     R"([^\n]*shaft softer, moment reads high[^\n]*: MODEL_MISMATCH\.)")))
      << w.output;
  EXPECT_NE(w.output.find("MODEL_MISMATCH's trip-end preload test fired on 1 of 1 trips"), std::string::npos)
      << w.output;

  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return estimate(a);
  };
  const CapturedRun n = with({"--no-trips"});
  EXPECT_EQ(n.status, 0);
  EXPECT_EQ(n.output.find("30 % preload loss"), std::string::npos) << n.output;
  const CapturedRun q = with({"-q"});
  EXPECT_EQ(q.status, 0);
  EXPECT_EQ(q.output.find("30 % preload loss"), std::string::npos);

  // The data of a cheap IMU (0.04 m/s^2) against a config that declares 0.002.
  ASSERT_EQ(sim({"--config", truth, "--profile", path("rest_trip.csv"), "--initial", "static", "--modes", "50",
                 "--write-measurements", path("cheap.csv"), "--sensor-noise", "0.04,0.004,60", "-q"})
                .status,
            0);
  const CapturedRun c = estimate({"--config", cfg, "--measurements", path("cheap.csv"), "--out", path("c.csv"),
                                  "--no-trips"});
  ASSERT_EQ(c.status, 0) << c.output;
  std::smatch m;
  const std::string call = c.output;
  ASSERT_TRUE(std::regex_search(call, m, std::regex(R"(Load changes at ((t = [0-9.]+ s; ){7}t = [0-9.]+ s) and (\d+) more;)")))
      << call.substr(0, 3000);
  EXPECT_GT(std::stoi(m[3].str()), 0);
}
