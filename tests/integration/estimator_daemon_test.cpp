// The live load estimator ([estimator] enabled in hoist-twind) against the
// offline one (hoist-estimate) on the same data, over real UDP multicast on
// loopback (ports 8140-8142, 7867): hoist-sim writes the measurements of a shaft whose
// load differs from the config, hoist-replay --measurements publishes them,
// the daemon runs --clock input, and every HOIST_ESTIMATE equals
// hoist-estimate's row to 1e-12.  Also: the alarms say where they came from,
// and HOIST_HEALTH counts the sensor samples.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "hoist/alarm_t.hpp"
#include "hoist/cage_imu_t.hpp"
#include "hoist/rope_load_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/health_t.hpp"
#include "lcm_fixtures.hpp"

using namespace hoist::test;
using namespace std::chrono_literals;

namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, ',')) out.push_back(f);
  return out;
}

/// hoist-estimate's output: one map column -> value per row.
std::vector<std::map<std::string, double>> readEstimateCsv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, double>> rows;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header.empty()) {
      header = split(line);
      continue;
    }
    const auto f = split(line);
    std::map<std::string, double> r;
    for (std::size_t i = 0; i < f.size() && i < header.size(); ++i) r[header[i]] = std::strtod(f[i].c_str(), nullptr);
    rows.push_back(r);
  }
  return rows;
}

class EstimatorDaemon : public LcmProcessTest {
 protected:
  // hoist-sim writes a short trip (50 m -> 62 m in 10 s, 1001 rows at 100
  // Hz) of a shaft whose load (1500 N at 0.6 m) the config does not know;
  // hoist-estimate runs on it offline; hoist-replay publishes it to the
  // daemon (--clock input).  Every HOIST_ESTIMATE must equal hoist-estimate's
  // row to 1e-12: the same samples at the same times, through the same code.
  // (hoist-sim stamps its rows in whole microseconds, as a sensor clock
  // does: utime then carries each row's very t.  With t = 0.35000000000000003
  // the daemon stepped at 0.35, and the offset-and-moment filter, nearly
  // singular at rest, carried that ulp to M's 12th digit.)
  // Returns the live estimates.  The daemon's last HOIST_HEALTH after the
  // run counts every sample, and the two bad ones published after the replay.
  std::vector<hoist::estimate_t> liveAgainstOffline(const std::string& sensors_toml) {
    hoist::health_t health{};
    const std::string truth = (dir_ / "truth.toml").string(), cfg = (dir_ / "twin.toml").string();
    {
      std::ofstream t(truth);
      t << "[load]\neccentric_force = 1500.0\noffset = 0.6\n[model]\nmodes = 25\n";
      std::ofstream c(cfg);
      c << "[model]\nmodes = 25\n[estimator]\nenabled = true\n" << sensors_toml;
    }
    const std::string meas = (dir_ / "meas.csv").string(), est = (dir_ / "est.csv").string();
    EXPECT_EQ(runProcess({HOIST_SIM, "--config", truth, "--profile", "trapezoid:vmax=2,amax=1,travel=12,t_end=10",
                          "--write-measurements", meas, "--sensor-noise", "0.002,0.0001,20", "--seed", "7", "-q"},
                         (dir_ / "sim.log").string(), 60s),
              0)
        << readFile((dir_ / "sim.log").string());
    EXPECT_EQ(runProcess({HOIST_ESTIMATE, "--config", cfg, "--measurements", meas, "--out", est},
                         (dir_ / "estimate.log").string(), 60s),
              0)
        << readFile((dir_ / "estimate.log").string());
    const auto offline = readEstimateCsv(est);
    EXPECT_EQ(offline.size(), 1001u);
    if (offline.size() != 1001u) return {};

    listener_->subscribe("HOIST_ESTIMATE|HOIST_ALARM");
    std::vector<std::string> argv{HOIST_TWIND, "--lcm-url", url_, "--config", cfg, "--clock", "input"};
    auto d = startDaemonAndWait(*listener_, argv, (dir_ / "twind.log").string());
    {
      Process r({HOIST_REPLAY, "--lcm-url", url_, "--measurements", meas, "--speed", "4", "-q"},
                (dir_ / "replay.log").string());
      listener_->waitFor([&] { return !r.running(); }, 30s);
      EXPECT_EQ(r.wait(1s), 0) << readFile((dir_ / "replay.log").string());
    }
    EXPECT_TRUE(listener_->waitFor([&] { return listener_->count("HOIST_ESTIMATE") >= 1001; }, 10s));
    // Bad samples are refused and counted: an implausible IMU, an old rope-load seq.
    {
      hoist::cage_imu_t imu{};
      imu.utime = 1;
      imu.seq = 5000;
      imu.f_y = std::nan("");
      imu.omega = 1e9;
      listener_->lcm().publish("HOIST_CAGE_IMU", &imu);
      hoist::rope_load_t rope{};
      rope.utime = 1;
      rope.seq = 3;  // the replay's last was 1000
      rope.force = 8000.0;
      listener_->lcm().publish("HOIST_ROPE_LOAD", &rope);
    }
    // The health after the run counts every sensor sample.
    const std::size_t h0 = listener_->count("HOIST_HEALTH");
    EXPECT_TRUE(listener_->waitFor([&] { return listener_->count("HOIST_HEALTH") > h0; }, 5s));
    const auto healths = listener_->decoded<hoist::health_t>("HOIST_HEALTH");
    EXPECT_FALSE(healths.empty());
    if (!healths.empty()) health = healths.back();
    stopDaemonCleanly(*d, (dir_ / "twind.log").string());

    const auto live = listener_->decoded<hoist::estimate_t>("HOIST_ESTIMATE");
    EXPECT_EQ(live.size(), offline.size()) << readFile((dir_ / "twind.log").string());
    if (live.size() != offline.size()) return {};
    auto same = [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b)); };
    for (std::size_t i = 0; i < live.size(); ++i) {
      const hoist::estimate_t& e = live[i];
      const auto& o = offline[i];
      EXPECT_EQ(e.t, o.at("t")) << "row " << i << ": t (the same times, to the bit)";
      EXPECT_TRUE(same(e.Fa, o.at("Fa"))) << "row " << i << ": Fa " << e.Fa << " vs " << o.at("Fa");
      EXPECT_TRUE(same(e.moment, o.at("moment"))) << "row " << i << ": M " << e.moment << " vs " << o.at("moment");
      EXPECT_TRUE(same(e.sigma_moment, o.at("sigma_moment"))) << "row " << i;
      EXPECT_TRUE(same(e.theta, o.at("theta"))) << "row " << i << ": theta " << e.theta << " vs " << o.at("theta");
      EXPECT_TRUE(same(e.lambdas[0], o.at("lambda_0"))) << "row " << i;
      EXPECT_TRUE(same(e.lambdas[1], o.at("lambda_1"))) << "row " << i;
      EXPECT_TRUE(same(e.nis_window, o.at("nis_window"))) << "row " << i;
      EXPECT_EQ(e.mismatch, o.at("mismatch") != 0.0) << "row " << i;
      if (::testing::Test::HasFailure()) return {};  // the first row that differs, not a thousand
    }
    // It did estimate: the load the config does not know (the moment: each test).
    EXPECT_NEAR(live.back().Fa, 1500.0, 20.0);
    EXPECT_TRUE(live.back().in_use);
    EXPECT_EQ(live.back().sensors, 7);
    EXPECT_EQ(health.sensor_accepted, 2 * 1001);
    EXPECT_EQ(health.sensor_rejected, 2);
    EXPECT_TRUE(health.estimate_in_use);
    // The start-up log says whether the moment's sigma carries the offset.
    const std::string log = readFile((dir_ / "twind.log").string());
    const bool free = sensors_toml.find("imu_accel_offset_sigma = 0\n") == std::string::npos;
    EXPECT_NE(log.find(free ? "the accelerometer's offset is estimated (uncalibrated"
                            : "the accelerometer is declared calibrated"),
              std::string::npos)
        << log;
    return live;
  }
};

}  // namespace

// An uncalibrated accelerometer (the offset a state of the filter, prior
// sigma 0.005 m/s^2): the live and offline estimates are the same; the
// moment's sigma is wide (on a 12-m trip M and the offset are told apart
// only by the depth shape of the tilt) and honest: the truth is inside it.
TEST_F(EstimatorDaemon, LiveEstimateEqualsHoistEstimateOnTheSameData) {
  start(8140, "EstimatorDaemon", {"HOIST_HEALTH"});
  const auto live = liveAgainstOffline("[sensors]\nimu_accel_offset_sigma = 0.005\n");
  ASSERT_EQ(live.size(), 1001u);
  const hoist::estimate_t& last = live.back();
  EXPECT_GT(last.sigma_moment, 20.0);  // the offset's share: not the calibrated few N m
  EXPECT_NEAR(last.moment, 900.0, 3.0 * last.sigma_moment) << "sigma " << last.sigma_moment;
}

// A calibrated accelerometer (imu_accel_offset_sigma = 0: the one-state
// filter of M): the same equality, and M to 10 %.
TEST_F(EstimatorDaemon, LiveEstimateEqualsHoistEstimateCalibrated) {
  start(7867, "EstimatorDaemonCalibrated", {"HOIST_HEALTH"});
  const auto live = liveAgainstOffline("[sensors]\nimu_accel_offset_sigma = 0\n");
  ASSERT_EQ(live.size(), 1001u);
  EXPECT_NEAR(live.back().moment, 900.0, 90.0);
  EXPECT_LT(live.back().sigma_moment, 20.0);
}

// A recording of this very twin played back beside it (lcm-logplayer): its
// HOIST_HEALTH carries our instance id but an old utime.  The daemon says so
// (DUPLICATE_PUBLISHER, a log line naming the replay) instead of staying quiet.
TEST_F(EstimatorDaemon, AReplayedRecordingOfThisTwinIsDetected) {
  start(8141, "ReplayedOutputs", {"HOIST_HEALTH"});
  listener_->subscribe("HOIST_ALARM");
  std::vector<std::string> argv{HOIST_TWIND, "--lcm-url", url_, "--clock", "wall"};
  auto d = startDaemonAndWait(*listener_, argv, (dir_ / "twind.log").string());
  auto health = listener_->decoded<hoist::health_t>("HOIST_HEALTH");
  ASSERT_FALSE(health.empty());
  hoist::health_t old = health.back();  // ours: same instance id
  old.utime -= 3600LL * 1000000;        // recorded an hour ago
  for (int i = 0; i < 3; ++i) {
    listener_->lcm().publish("HOIST_HEALTH", &old);
    listener_->waitFor([] { return false; }, 100ms);
  }
  auto raised = [&] {
    for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM"))
      if (a.kind == "DUPLICATE_PUBLISHER" && a.active) return true;
    return false;
  };
  EXPECT_TRUE(listener_->waitFor(raised, 5s)) << readFile((dir_ / "twind.log").string());
  stopDaemonCleanly(*d, (dir_ / "twind.log").string());
  EXPECT_NE(readFile((dir_ / "twind.log").string()).find("a recording of this twin is being played"),
            std::string::npos);
}

// A tcpq:// URL with no server: one line naming the URL and the cause, exit 1
// (not "fatal: assign: Bad file descriptor").
TEST(DaemonLcmUrl, TcpqWithoutServerNamesTheUrl) {
  const auto dir = std::filesystem::path(HOIST_TEST_WORK_DIR) / "DaemonLcmUrl";
  std::filesystem::create_directories(dir);
  const std::string log = (dir / "twind.log").string();
  const int rc = runProcess({HOIST_TWIND, "--lcm-url", "tcpq://127.0.0.1:1"}, log, 20s);
  EXPECT_EQ(rc, 1);
  const std::string text = readFile(log);
  EXPECT_NE(text.find("cannot receive from LCM at tcpq://127.0.0.1:1"), std::string::npos) << text;
  EXPECT_EQ(text.find("Bad file descriptor"), std::string::npos) << text;
}

// With the estimator in use, the forecasts start from the state the estimated
// load implies and continue under that load: every HOIST_FORECAST says so
// (from_estimate) and carries the load of the HOIST_ESTIMATE of the same
// step; before any sensor sample they are the open-loop twin's, under the
// configured load.  (That the shifted state is exactly the state under the
// other load, and its forecast that load's forecast, is LoadSuperposition.*.)
TEST_F(EstimatorDaemon, ForecastsStartFromTheEstimatedLoad) {
  start(8142, "EstimatorForecast", {"HOIST_HEALTH"});
  const std::string truth = (dir_ / "truth.toml").string(), cfg = (dir_ / "twin.toml").string();
  {
    // The true load leans the other way from the configured one (1000 N at +1 m).
    std::ofstream t(truth);
    t << "[load]\neccentric_force = 1500.0\noffset = -0.6\n[model]\nmodes = 16\n";
    std::ofstream c(cfg);
    c << "[model]\nmodes = 16\n[estimator]\nenabled = true\n[forecast]\nenabled = true\nrate = 5.0\nhorizon = 5.0\n";
  }
  const std::string meas = (dir_ / "meas.csv").string();
  ASSERT_EQ(runProcess({HOIST_SIM, "--config", truth, "--profile", "trapezoid:vmax=2,amax=1,travel=12,t_end=10",
                        "--write-measurements", meas, "--sensor-noise", "0.002,0.0001,20", "--seed", "11", "-q"},
                       (dir_ / "sim.log").string(), 60s),
            0)
      << readFile((dir_ / "sim.log").string());
  // The first second without sensors: open loop.
  {
    std::ifstream in(meas);
    std::ofstream out((dir_ / "meas2.csv").string());
    std::string line;
    while (std::getline(in, line)) {
      const auto f = split(line);
      if (!line.empty() && line[0] != '#' && f.size() >= 7 && f[0] != "t" && std::strtod(f[0].c_str(), nullptr) < 1.0)
        out << f[0] << ',' << f[1] << ',' << f[2] << ',' << f[3] << ",,,\n";
      else
        out << line << '\n';
    }
  }
  listener_->subscribe("HOIST_ESTIMATE|HOIST_FORECAST");
  std::vector<std::string> argv{HOIST_TWIND, "--lcm-url", url_, "--config", cfg, "--clock", "input"};
  auto d = startDaemonAndWait(*listener_, argv, (dir_ / "twind.log").string());
  {
    Process r({HOIST_REPLAY, "--lcm-url", url_, "--measurements", (dir_ / "meas2.csv").string(), "--speed", "4", "-q"},
              (dir_ / "replay.log").string());
    listener_->waitFor([&] { return !r.running(); }, 30s);
    ASSERT_EQ(r.wait(1s), 0) << readFile((dir_ / "replay.log").string());
  }
  EXPECT_TRUE(listener_->waitFor([&] { return listener_->count("HOIST_FORECAST") >= 48; }, 10s));
  stopDaemonCleanly(*d, (dir_ / "twind.log").string());
  const auto est = listener_->decoded<hoist::estimate_t>("HOIST_ESTIMATE");
  const auto fc = listener_->decoded<hoist::forecast_t>("HOIST_FORECAST");
  ASSERT_GE(fc.size(), 48u) << readFile((dir_ / "twind.log").string());
  std::map<std::int64_t, const hoist::estimate_t*> by_utime;
  for (const auto& e : est) by_utime[e.utime] = &e;
  int open = 0, shifted = 0;
  for (const auto& f : fc) {
    const auto it = by_utime.find(f.utime);
    ASSERT_NE(it, by_utime.end()) << "a forecast at utime " << f.utime << " with no estimate of that step";
    const hoist::estimate_t& e = *it->second;
    ASSERT_EQ(f.from_estimate, e.in_use) << "t = " << f.t_start;
    if (f.from_estimate) {
      ++shifted;
      EXPECT_NEAR(f.Fa, e.Fa, 1e-12 * std::abs(e.Fa)) << "t = " << f.t_start;
      EXPECT_NEAR(f.moment, e.moment, 1e-12 * std::abs(e.moment)) << "t = " << f.t_start;
    } else {
      ++open;
      EXPECT_EQ(f.Fa, 1000.0) << "t = " << f.t_start;
      EXPECT_EQ(f.moment, 1000.0) << "t = " << f.t_start;
    }
  }
  EXPECT_GE(open, 4);      // the first second, without sensors
  EXPECT_GE(shifted, 40);  // then from the estimate
  // By the end the forecasts assume (about) the true load, not the configured
  // one: within the estimate's 3 sigma (the accelerometer's offset is free by
  // default: on this 12-m trip M's sigma is about 15 %), on the true side.
  const hoist::estimate_t& e_end = *by_utime.at(fc.back().utime);
  EXPECT_NEAR(fc.back().Fa, 1500.0, 30.0);
  EXPECT_NEAR(fc.back().moment, -900.0, 3.0 * e_end.sigma_moment) << "sigma " << e_end.sigma_moment;
  EXPECT_LT(e_end.sigma_moment, 300.0);
  EXPECT_LT(fc.back().moment, -300.0);  // the configured load leans the other way (+1000 N m)
}
