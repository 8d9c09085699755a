// False and late sensors against the live daemon (hoist-twind --clock input,
// [estimator] enabled) over real UDP multicast on loopback (ports 7920-7925).
// The test publishes the winder and the sensors itself, a row every 10 ms of
// sample time: the shaft at rest at 150 m with the configured load, its
// sensors read through the sensor model (hoist::sensorModel of the static
// state) with seeded noise.
//   * a clock 2 s off and a utime going back: refused, counted in
//     HOIST_HEALTH, SENSOR_FAULT names the sensor, a log line says why;
//   * a forged load step at rest (0.1 s of IMU samples reading no tilt)
//     while CAGE_POS_Y is active: the load change is logged and the
//     alarm does not clear;
//   * an absurd f_y (99 m/s^2) and rope load (1e7 N) inside the sample
//     bounds: the estimate is not used (HOIST_ESTIMATE.in_use false,
//     not_used says why), SENSOR_FAULT, the switch is logged;
//   * a stream delayed by 3..7 rows (in order): the estimate equals the
//     undelayed run's within their sigmas;
//   * an IMU reading exactly 0 at rest while the open-loop twin raises
//     CAGE_POS_Y: SENSOR_FAULT names the IMU, the estimate is not used, the
//     alarm is raised and never cleared;
//   * a rope load stuck from 3 s on: SENSOR_FAULT names it within a few
//     seconds, the estimate is not used, the switch is logged.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <thread>

#include "hoist/alarm_t.hpp"
#include "hoist/cage_imu_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/fast_solver.hpp"
#include "hoist/health_t.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/rope_load_t.hpp"
#include "lcm_fixtures.hpp"
#include "lcm_messages.hpp"

using namespace hoist::test;
using namespace std::chrono_literals;

namespace {

constexpr std::int64_t kT0 = 1'700'000'000'000'000;
constexpr double kRestLength = 150.0;

/// The config's shaft at n = 12 (what the daemon runs), its load 1000 N at
/// 3 m: a static tilt that the IMU reads at 12 times its noise.
constexpr double kOffset = 3.0;
hoist::ShaftParams shaft() {
  hoist::ShaftParams p;
  p.n = 12;
  p.static_correction = true;
  p.b = kOffset;
  return p;
}

/// The static state at rest with the configured load: its sensor readings
/// and its excursion toward +y.
struct Rest {
  hoist::SensorValues z;
  double excursion_pos = 0.0;
};
Rest restState() {
  const hoist::ShaftParams p = shaft();
  hoist::FastSolver s(std::make_shared<const hoist::ShaftModel>(p));
  s.initialize(0.0, hoist::Kinematics{kRestLength, 0.0, 0.0});
  const hoist::CageResponse& r = s.response();
  Rest out;
  out.z = hoist::sensorModel(r, p.g);
  out.excursion_pos = std::max(r.y_c - p.h * r.theta, r.y_c + p.h * r.theta);
  return out;
}

/// One row: what each sensor sends (utime offsets, values) and whether it sends.
struct Row {
  std::int64_t imu_dt = 0, rope_dt = 0;  // utime offset from the row's [us]
  double f_y = 0.0, omega = 0.0, force = 0.0;
  bool imu = true, rope = true;
};

class SensorAttack : public LcmProcessTest {
 protected:
  /// Write the daemon's config: estimator on, n = 12, the gap and hold given.
  std::string config(double gap_pos_y, double clear_hold, const std::string& name) {
    const std::string path = (dir_ / name).string();
    std::ofstream c(path);
    c << "[model]\nmodes = 12\n[load]\noffset = " << kOffset << "\n[hoisting_rope]\ninitial_length = " << kRestLength << "\n"
      << "[alarms]\ngap_pos_y = " << gap_pos_y << "\noff_delay = 0.0\n"
      << "[forecast]\nenabled = false\n"  // no synchronous forecasts stalling the input clock
      << "[estimator]\nenabled = true\nclear_hold = " << clear_hold << "\n";
    return path;
  }
  /// Publish `rows` (sensors first, then the winder row; 1 ms apart in wall time).
  void publish(const std::vector<Row>& rows) {
    std::int64_t imu_seq = 0, rope_seq = 0;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const std::int64_t ut = kT0 + static_cast<std::int64_t>(k) * 10'000;
      const Row& r = rows[k];
      if (r.imu) {
        hoist::cage_imu_t m{};
        m.utime = ut + r.imu_dt;
        m.seq = ++imu_seq;
        m.f_y = r.f_y;
        m.omega = r.omega;
        listener_->lcm().publish("HOIST_CAGE_IMU", &m);
      }
      if (r.rope) {
        hoist::rope_load_t m{};
        m.utime = ut + r.rope_dt;
        m.seq = ++rope_seq;
        m.force = r.force;
        listener_->lcm().publish("HOIST_ROPE_LOAD", &m);
      }
      const hoist::winder_t w = winder(static_cast<std::int64_t>(k), ut, 0.0, kRestLength);
      listener_->lcm().publish("HOIST_WINDER", &w);
      listener_->pump(2ms);
    }
  }
  /// The daemon has taken every row: the last row's estimate arrived, or
  /// (should the listener have lost that one) the daemon's newest health
  /// report -- this daemon's: startDaemonAndWait waited for one of its own --
  /// has reached the last row's model time.  Only the newest messages are
  /// decoded: decoding all of them at every poll falls behind a sanitized
  /// daemon, and LCM then drops what queues up.
  bool lastArrived(std::size_t rows) const {
    const std::int64_t last = kT0 + static_cast<std::int64_t>(rows - 1) * 10'000;
    const auto& est = listener_->messages("HOIST_ESTIMATE");
    for (std::size_t i = est.size(), seen = 0; i > 0 && seen < 8; --i, ++seen) {
      hoist::estimate_t e;
      const auto& m = est[i - 1];
      if (e.decode(m.data.data(), 0, static_cast<int>(m.data.size())) > 0 && e.utime == last) return true;
    }
    const auto& health = listener_->messages("HOIST_HEALTH");
    if (health.empty()) return false;
    hoist::health_t h;
    const auto& m = health.back();
    return h.decode(m.data.data(), 0, static_cast<int>(m.data.size())) > 0 &&
           h.t >= static_cast<double>(rows - 1) * 0.01 - 1e-6;
  }
  /// Genuine rows at rest with seeded noise.
  std::vector<Row> genuine(std::size_t n, unsigned seed) {
    const Rest rest = restState();
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> N01(0.0, 1.0);
    const hoist::SensorNoise noise;
    std::vector<Row> rows(n);
    for (Row& r : rows) {
      r.f_y = rest.z.f_y + noise.imu_accel * N01(rng);
      r.omega = rest.z.omega + noise.imu_rate * N01(rng);
      r.force = rest.z.rope_load + noise.rope_load * N01(rng);
    }
    return rows;
  }
  /// Run the daemon on `rows`; returns its log.
  std::string run(const std::string& cfg, const std::vector<Row>& rows, const std::string& name) {
    listener_->clear();
    const std::string log = (dir_ / (name + ".log")).string();
    auto d = startDaemonAndWait(*listener_, {HOIST_TWIND, "--lcm-url", url_, "--config", cfg, "--clock", "input"}, log);
    publish(rows);
    EXPECT_TRUE(listener_->waitFor([&] { return lastArrived(rows.size()); }, 10s))
        << listener_->count("HOIST_ESTIMATE") << " of " << rows.size() << "\n" << readFile(log);
    const std::size_t h0 = listener_->count("HOIST_HEALTH");
    EXPECT_TRUE(listener_->waitFor([&] { return listener_->count("HOIST_HEALTH") > h0; }, 5s));
    stopDaemonCleanly(*d, log);
    return readFile(log);
  }
  std::vector<hoist::alarm_t> alarms(const std::string& kind, std::int8_t type) const {
    std::vector<hoist::alarm_t> out;
    for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM"))
      if (a.kind == kind && a.event_type == type) out.push_back(a);
    return out;
  }
};

}  // namespace

TEST_F(SensorAttack, AClockTwoSecondsOffAndABackwardsUtimeAreRefusedAndReported) {
  start(7920, "SensorAttackClock", {"HOIST_HEALTH", "HOIST_ESTIMATE", "HOIST_ALARM"});
  auto rows = genuine(400, 1);
  rows[100].imu_dt = 2'000'000;  // the IMU's clock 2 s ahead, once
  rows[200].rope_dt = -50'000;   // a rope-load utime before the previous sample's
  const std::string log = run(config(0.3, 2.0, "twin.toml"), rows, "twind");
  const auto health = listener_->decoded<hoist::health_t>("HOIST_HEALTH");
  ASSERT_FALSE(health.empty());
  EXPECT_EQ(health.back().sensor_clock_refused, 1);
  EXPECT_EQ(health.back().sensor_time_backwards, 1);
  EXPECT_EQ(health.back().sensor_rejected, 2);
  const auto raised = alarms("SENSOR_FAULT", hoist::alarm_t::EVENT_RAISE);
  ASSERT_FALSE(raised.empty()) << log;
  EXPECT_NE(raised.front().message.find("HOIST_CAGE_IMU"), std::string::npos) << raised.front().message;
  EXPECT_NE(raised.front().message.find("clock"), std::string::npos) << raised.front().message;
  EXPECT_NEAR(raised.front().value, 2.0, 0.02);
  EXPECT_NE(log.find("sensors.max_clock_offset = 0.5 s"), std::string::npos) << log;
  EXPECT_NE(log.find("time went backwards"), std::string::npos) << log;
  // The estimate went on with the good samples.
  EXPECT_TRUE(listener_->decoded<hoist::estimate_t>("HOIST_ESTIMATE").back().in_use);
}

TEST_F(SensorAttack, AForgedStepAtRestCannotClearAnActiveAlarm) {
  start(7921, "SensorAttackForge", {"HOIST_HEALTH", "HOIST_ESTIMATE", "HOIST_ALARM"});
  const double gap = restState().excursion_pos / 0.6;  // CAGE_POS_Y WARNING on at rest, CRITICAL off
  auto rows = genuine(800, 2);
  // 0.1 s of an IMU reading no tilt (12 sigma from the genuine one): a zeroed
  // or forged IMU; the estimate would say the cage hangs straight.
  const double tilt = restState().z.f_y;
  for (std::size_t k = 300; k < 310; ++k) rows[k].f_y -= tilt;
  const std::string log = run(config(gap, 2.0, "hold.toml"), rows, "hold");
  ASSERT_FALSE(alarms("CAGE_POS_Y", hoist::alarm_t::EVENT_RAISE).empty()) << log;
  EXPECT_TRUE(alarms("CAGE_POS_Y", hoist::alarm_t::EVENT_CLEAR).empty()) << log;
  EXPECT_NE(log.find("load change detected"), std::string::npos) << log;
  // (What the hold itself does is tested on the gate alone:
  // EstimateGate.ALoadChangeClearsOnlyAfterTheHold.  With the estimator's
  // change detector this forgery no longer clears the alarm even without the
  // hold: the revealing sample is not applied, and a zeroed tilt is quiet.)
}

TEST_F(SensorAttack, AbsurdReadingsInsideTheSampleBoundsAreNotUsed) {
  start(7922, "SensorAttackAbsurd", {"HOIST_HEALTH", "HOIST_ESTIMATE", "HOIST_ALARM"});
  auto rows = genuine(600, 3);
  for (std::size_t k = 200; k < 600; ++k) {
    rows[k].f_y = 99.0;     // inside |f_y| <= 100
    rows[k].force = 1.0e7;  // inside |force| <= 1e8
  }
  const std::string log = run(config(0.3, 2.0, "twin.toml"), rows, "twind");
  const auto est = listener_->decoded<hoist::estimate_t>("HOIST_ESTIMATE");
  ASSERT_GE(est.size(), 500u);
  EXPECT_TRUE(est[150].in_use);
  // Once the estimator took the absurd readings, its estimate is never used.
  int used_absurd = 0;
  for (const auto& e : est)
    if (e.in_use && (std::abs(e.theta) > 0.1 || std::abs(e.Fa) > 1.0e6)) ++used_absurd;
  EXPECT_EQ(used_absurd, 0);
  EXPECT_FALSE(est.back().in_use);
  EXPECT_NE(est.back().not_used, 0);
  EXPECT_FALSE(alarms("SENSOR_FAULT", hoist::alarm_t::EVENT_RAISE).empty()) << log;
  EXPECT_NE(log.find("alarms now judge the open-loop twin"), std::string::npos) << log;
}

TEST_F(SensorAttack, ADelayedJitteredStreamGivesTheUndelayedEstimate) {
  start(7923, "SensorAttackDelay", {"HOIST_HEALTH", "HOIST_ESTIMATE"});
  // A load the config does not know: the rope reads 500 N more, the IMU the
  // genuine tilt (the estimate must move, and move the same in both runs).
  auto rows = genuine(600, 4);
  for (Row& r : rows) r.force += 500.0;  // Fa = 1500 N
  const std::string cfg = config(0.3, 2.0, "twin.toml");
  run(cfg, rows, "on_time");
  const auto a = listener_->decoded<hoist::estimate_t>("HOIST_ESTIMATE");
  // The same samples, each published 3..7 rows later (in order), stamped with its own time.
  std::mt19937_64 rng(6);
  std::uniform_int_distribution<int> lag(3, 7);
  std::size_t last = 0;
  std::vector<std::pair<std::size_t, std::size_t>> moves;  // (sample, row it is published with)
  for (std::size_t k = 0; k < rows.size(); ++k) {
    last = std::max(last, k + static_cast<std::size_t>(lag(rng)));
    if (last < rows.size()) moves.emplace_back(k, last);
  }
  // Each winder row goes with the sensor samples that arrive by then.
  listener_->clear();
  const std::string log = (dir_ / "late.log").string();
  auto d = startDaemonAndWait(*listener_, {HOIST_TWIND, "--lcm-url", url_, "--config", cfg, "--clock", "input"}, log);
  std::size_t m = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const std::int64_t ut = kT0 + static_cast<std::int64_t>(k) * 10'000;
    for (; m < moves.size() && moves[m].second == k; ++m) {
      const std::size_t s = moves[m].first;
      const std::int64_t us = kT0 + static_cast<std::int64_t>(s) * 10'000;
      hoist::cage_imu_t imu{};
      imu.utime = us;
      imu.seq = static_cast<std::int64_t>(s) + 1;
      imu.f_y = rows[s].f_y;
      imu.omega = rows[s].omega;
      listener_->lcm().publish("HOIST_CAGE_IMU", &imu);
      hoist::rope_load_t rope{};
      rope.utime = us;
      rope.seq = static_cast<std::int64_t>(s) + 1;
      rope.force = rows[s].force;
      listener_->lcm().publish("HOIST_ROPE_LOAD", &rope);
    }
    const hoist::winder_t w = winder(static_cast<std::int64_t>(k), ut, 0.0, kRestLength);
    listener_->lcm().publish("HOIST_WINDER", &w);
    listener_->pump(2ms);
  }
  EXPECT_TRUE(listener_->waitFor([&] { return lastArrived(rows.size()); }, 10s));
  const std::size_t h0 = listener_->count("HOIST_HEALTH");
  EXPECT_TRUE(listener_->waitFor([&] { return listener_->count("HOIST_HEALTH") > h0; }, 5s));
  stopDaemonCleanly(*d, log);
  const auto b = listener_->decoded<hoist::estimate_t>("HOIST_ESTIMATE");
  const auto health = listener_->decoded<hoist::health_t>("HOIST_HEALTH");
  ASSERT_FALSE(health.empty());
  EXPECT_EQ(health.back().sensor_dropped, 0);
  std::map<std::int64_t, const hoist::estimate_t*> by_utime;
  for (const auto& e : b) by_utime[e.utime] = &e;
  int compared = 0;
  for (std::size_t i = 100; i < a.size(); i += 25) {
    const auto it = by_utime.find(a[i].utime);
    if (it == by_utime.end()) continue;  // a datagram the listener lost
    const hoist::estimate_t& l = *it->second;
    // Two estimates of the same load agree within their sigmas (at rest the
    // 5 N/sqrt(s) walk gives the filter a memory of about 40 samples, so the
    // 7 samples the late one has not yet seen move it by about 0.4 sigma),
    // and each holds the truth (the config's 1000 N + 500 N) within 3 sigma.
    const double sF = std::hypot(a[i].sigma_Fa, l.sigma_Fa), sM = std::hypot(a[i].sigma_moment, l.sigma_moment);
    EXPECT_LT(std::abs(a[i].Fa - l.Fa), sF) << "t " << a[i].t;
    EXPECT_LT(std::abs(a[i].moment - l.moment), sM) << "t " << a[i].t;
    EXPECT_LT(std::abs(l.Fa - 1500.0), 3.0 * l.sigma_Fa) << "t " << a[i].t;
    ++compared;
  }
  EXPECT_GE(compared, 9);
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  EXPECT_NEAR(b.back().Fa, a.back().Fa, a.back().sigma_Fa);
  EXPECT_GT(std::abs(a.back().Fa - 1000.0), 300.0);  // it did move: the load the config does not know
}

TEST_F(SensorAttack, AZeroImuCannotHideTheOpenLoopAlarm) {
  start(7924, "SensorAttackZeroImu", {"HOIST_HEALTH", "HOIST_ESTIMATE", "HOIST_ALARM"});
  // The open-loop twin (the configured load) raises CAGE_POS_Y at rest; the
  // IMU reads exactly 0 from the start (a dead gateway, or a forger).
  const double gap = restState().excursion_pos / 0.6;
  auto rows = genuine(600, 5);
  for (Row& r : rows) r.f_y = r.omega = 0.0;
  const std::string log = run(config(gap, 2.0, "twin.toml"), rows, "twind");
  const auto fault = alarms("SENSOR_FAULT", hoist::alarm_t::EVENT_RAISE);
  ASSERT_FALSE(fault.empty()) << log;
  EXPECT_NE(fault.front().message.find("HOIST_CAGE_IMU"), std::string::npos) << fault.front().message;
  // The alarm the open-loop twin raises is raised, and never cleared.
  EXPECT_FALSE(alarms("CAGE_POS_Y", hoist::alarm_t::EVENT_RAISE).empty()) << log;
  EXPECT_TRUE(alarms("CAGE_POS_Y", hoist::alarm_t::EVENT_CLEAR).empty()) << log;
  const auto est = listener_->decoded<hoist::estimate_t>("HOIST_ESTIMATE");
  ASSERT_FALSE(est.empty());
  EXPECT_FALSE(est.back().in_use);
  EXPECT_NE(est.back().not_used & hoist::estimate_t::NOT_USED_SENSOR_FAULT, 0);
}

TEST_F(SensorAttack, AStuckRopeLoadIsFoundAndNotUsed) {
  start(7925, "SensorAttackStuckRope", {"HOIST_HEALTH", "HOIST_ESTIMATE", "HOIST_ALARM"});
  auto rows = genuine(700, 6);
  for (std::size_t k = 300; k < rows.size(); ++k) rows[k].force = rows[299].force;  // stuck from 3 s on
  const std::string log = run(config(0.3, 2.0, "twin.toml"), rows, "twind");
  const auto est = listener_->decoded<hoist::estimate_t>("HOIST_ESTIMATE");
  ASSERT_GE(est.size(), 500u);
  const auto fault = alarms("SENSOR_FAULT", hoist::alarm_t::EVENT_RAISE);
  ASSERT_FALSE(fault.empty()) << log;
  EXPECT_NE(fault.front().message.find("HOIST_ROPE_LOAD"), std::string::npos) << fault.front().message;
  // Found within a few seconds (the monitor's stuck_time is 1 s).
  EXPECT_LT(fault.front().t, 3.0 + 3.0) << fault.front().message;
  EXPECT_FALSE(est.back().in_use);
  EXPECT_NE(log.find("alarms now judge the open-loop twin"), std::string::npos) << log;
}
