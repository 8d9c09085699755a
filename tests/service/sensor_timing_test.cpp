// The load estimator's sensors in the twin (TwinCore, --clock input, no
// I/O): samples applied at their own time (a delayed, jittered stream gives
// the undelayed estimate within its sigma), a sensor clock off by more than
// max_clock_offset and a utime going back refused, counted and reported
// (SENSOR_FAULT), and a false sensor cannot silence an alarm: a forged load
// step at rest cannot clear an active CAGE_POS_Y within clear_hold, an
// absurd reading gives an implausible estimate that is not used.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "hoist/sensor_alignment.hpp"
#include "hoist/service/twin/twin_core.hpp"

using namespace hoist;
using namespace hoist::service;

namespace {

constexpr std::int64_t kT0 = 1'700'000'000'000'000;
constexpr double kDt = 0.01;

TwinConfig estimatorConfig() {
  TwinConfig c;
  c.shaft.n = 12;  // fast tests; the truth below runs the same n with another load
  c.shaft.static_correction = true;
  c.service.envelope_points = 101;
  c.service.shape_points = 21;
  c.estimator.enabled = true;
  return c;
}

/// Kinematics at time t: a trip profile, or at rest.
struct Motion {
  const HoistProfile* prof = nullptr;
  double rest_l = 150.0;
  Kinematics at(double t) const { return prof ? prof->at(prof->startTime() + t) : Kinematics{rest_l, 0.0, 0.0}; }
};

WinderSample winderAt(const Motion& p, long k) {
  const double t = static_cast<double>(k) * kDt;
  const Kinematics kin = p.at(t);
  WinderSample s;
  s.utime = kT0 + std::llround(static_cast<double>(k) * kDt * 1e6);
  s.seq = k;
  s.v = kin.v;
  s.a = kin.a;
  s.has_length = true;
  s.length = kin.l;
  return s;
}

/// What the sensors read on the shaft with load (Fa, b), every kDt, with seeded noise.
std::vector<SensorValues> truthReadings(ShaftParams p, const Motion& prof, double Fa, double b, long n,
                                        unsigned seed) {
  p.Fa = Fa;
  p.b = b;
  FastSolver s(std::make_shared<const ShaftModel>(p));
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N01(0.0, 1.0);
  const SensorNoise noise;
  std::vector<SensorValues> out;
  s.initialize(0.0, prof.at(0.0));
  for (long k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * kDt;
    if (k > 0)
      for (int j = 1; j <= 4; ++j) {
        const double tj = t - kDt + j * kDt / 4;
        s.step(tj, prof.at(tj));
      }
    const SensorValues z = sensorModel(s.response(), p.g);
    out.push_back({z.f_y + noise.imu_accel * N01(rng), z.omega + noise.imu_rate * N01(rng),
                   z.rope_load + noise.rope_load * N01(rng)});
  }
  return out;
}

bool raised(const AlarmEvents& ev, AlarmKind k, AlarmEventType type) {
  return std::any_of(ev.begin(), ev.end(), [&](const AlarmEvent& e) { return e.kind == k && e.type == type; });
}

}  // namespace

TEST(SensorAlignment, InterpolatesAndMovesASampleToNowExactly) {
  // Linear base and sensitivity in t: interpolation is exact, and a sample
  // of the load (dFa, dM) taken at ts, moved to now, reads what it would now.
  PredictionHistory hist(8);
  auto at = [](double t) {
    return SensorPrediction{t, {0.1 + 0.02 * t, -0.3 * t, 5000.0 + 40.0 * t}, {1e-5 * (1 + t), 2e-7 * t, 1.0 - 0.01 * t}};
  };
  for (int k = 0; k < 12; ++k) hist.push(at(0.01 * k));
  EXPECT_NEAR(hist.oldest(), 0.04, 1e-15);  // 8 kept
  SensorPrediction then;
  EXPECT_FALSE(hist.at(0.035, then));       // older than kept
  EXPECT_FALSE(hist.at(0.2, then));         // after the newest
  ASSERT_TRUE(hist.at(0.0537, then));
  EXPECT_NEAR(then.base.rope_load, at(0.0537).base.rope_load, 1e-9);
  EXPECT_NEAR(then.h.f_y, at(0.0537).h.f_y, 1e-18);
  const double dFa = 300.0, dM = -800.0;
  const SensorPrediction now = at(0.11);
  const SensorValues z{then.base.f_y + dM * then.h.f_y, then.base.omega + dM * then.h.omega,
                       then.base.rope_load + dFa * then.h.rope_load};
  const SensorValues moved = alignToNow(z, then, now, dFa, dM);
  EXPECT_NEAR(moved.f_y, now.base.f_y + dM * now.h.f_y, 1e-14);
  EXPECT_NEAR(moved.omega, now.base.omega + dM * now.h.omega, 1e-14);
  EXPECT_NEAR(moved.rope_load, now.base.rope_load + dFa * now.h.rope_load, 1e-9);
  // Time going back restarts the history.
  hist.push(at(0.0));
  EXPECT_DOUBLE_EQ(hist.oldest(), 0.0);
  EXPECT_DOUBLE_EQ(hist.newest(), 0.0);
}

TEST(SensorTiming, DelayedJitteredStreamGivesTheUndelayedEstimate) {
  // A 12-m trip at 2 m/s; the shaft carries 1500 N at 0.6 m, the config the paper's 1000 N at 1 m.
  const TwinConfig cfg = estimatorConfig();
  const HoistProfile trip = HoistProfile::trapezoid(50.0, 2.0, 1.0, 12.0, 12.0);
  const Motion prof{&trip};
  const long n = 1200;
  const auto z = truthReadings(cfg.shaft, prof, 1500.0, 0.6, n, 3);
  TwinCore on_time(cfg, ClockMode::Input), late(cfg, ClockMode::Input);
  // The late stream: each sample arrives 50 ms +- 20 ms (uniform) after it was
  // taken, in order, the two sensors independently.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  std::vector<double> arrive_imu(n), arrive_rope(n);
  for (long k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * kDt;
    arrive_imu[k] = std::max(k ? arrive_imu[k - 1] : 0.0, t + 0.05 + jitter(rng));
    arrive_rope[k] = std::max(k ? arrive_rope[k - 1] : 0.0, t + 0.05 + jitter(rng));
  }
  long next_imu = 0, next_rope = 0;
  int compared = 0;
  for (long k = 0; k < n; ++k) {
    const WinderSample w = winderAt(prof, k);
    const double t = static_cast<double>(k) * kDt;
    const std::int64_t ut = w.utime;
    ASSERT_EQ(on_time.onCageImu(ut, z[k].f_y, z[k].omega, 0.0, 0), SensorVerdict::Queued);
    ASSERT_EQ(on_time.onRopeLoad(ut, z[k].rope_load, 0.0, 0), SensorVerdict::Queued);
    for (; next_imu < n && arrive_imu[next_imu] <= t + 1e-9; ++next_imu)
      ASSERT_EQ(late.onCageImu(winderAt(prof, next_imu).utime, z[next_imu].f_y, z[next_imu].omega, 0.0, 0),
                SensorVerdict::Queued);
    for (; next_rope < n && arrive_rope[next_rope] <= t + 1e-9; ++next_rope)
      ASSERT_EQ(late.onRopeLoad(winderAt(prof, next_rope).utime, z[next_rope].rope_load, 0.0, 0),
                SensorVerdict::Queued);
    ASSERT_TRUE(on_time.onInput(w, t).stepped);
    ASSERT_TRUE(late.onInput(w, t).stepped);
    if (k >= 200 && k % 50 == 0) {
      const LoadEstimate& a = *on_time.estimate();
      const LoadEstimate& b = *late.estimate();
      EXPECT_LT(std::abs(b.moment - a.moment), a.sigma_moment) << "t = " << t;
      EXPECT_LT(std::abs(b.Fa - a.Fa), a.sigma_Fa) << "t = " << t;
      EXPECT_LT(std::abs(b.theta - a.theta), a.sigma_theta) << "t = " << t;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 20);
  // It estimated the load it was not told, and used every sample but the last few in flight.
  EXPECT_NEAR(late.estimate()->Fa, 1500.0, 3.0 * late.estimate()->sigma_Fa + 5.0);
  EXPECT_NEAR(late.estimate()->moment, 900.0, 3.0 * late.estimate()->sigma_moment + 20.0);
  EXPECT_GE(late.sensorTiming().applied, 2 * n - 20);
  EXPECT_EQ(late.sensorTiming().too_late + late.sensorTiming().superseded, 0);
  EXPECT_FALSE(raised(late.events(), AlarmKind::SensorFault, AlarmEventType::Raise));
}

// Samples stamped with their winder sample's utime (what hoist-replay
// --measurements sends) give hoist-estimate's numbers to the bit, with the
// accelerometer's offset a state (imu_accel_offset_sigma 0.005: nearly
// singular at rest, it carries a rounding difference to M's 12th digit).
// The sensors' model time is computed exactly as the winder's: the old
// (utime - base) * 1e-6 put 30 % of the samples one ulp before their step.
TEST(SensorTiming, OnTimeSamplesGiveHoistEstimatesNumbersToTheBit) {
  TwinConfig cfg = estimatorConfig();
  cfg.estimator.settings.accel_offset_sigma = 0.005;
  const HoistProfile trip = HoistProfile::trapezoid(50.0, 2.0, 1.0, 12.0, 12.0);
  const Motion prof{&trip};
  const long n = 600;
  const auto z = truthReadings(cfg.shaft, prof, 1500.0, 0.6, n, 4);
  TwinCore core(cfg, ClockMode::Input);
  std::vector<MeasurementSample> rows(static_cast<std::size_t>(n));
  std::vector<LoadEstimate> live;
  for (long k = 0; k < n; ++k) {
    const WinderSample w = winderAt(prof, k);
    ASSERT_EQ(core.onCageImu(w.utime, z[k].f_y, z[k].omega, 0.0, 0), SensorVerdict::Queued);
    ASSERT_EQ(core.onRopeLoad(w.utime, z[k].rope_load, 0.0, 0), SensorVerdict::Queued);
    ASSERT_TRUE(core.onInput(w, 0.0).stepped);
    live.push_back(*core.estimate());
    MeasurementSample& m = rows[static_cast<std::size_t>(k)];
    m.t = static_cast<double>(w.utime - kT0) / 1e6;  // the model time of the utime, as a recording has it
    m.k = Kinematics{w.length, w.v, w.a};
    m.z = z[k];
    m.present = kSensorImuAccel | kSensorImuRate | kSensorRopeLoad;
  }
  std::size_t i = 0;
  estimateRecorded(cfg.shaft, cfg.estimator.settings, cfg.service.max_step, rows,
                   [&](const LoadEstimate& e, const EstimatorCounters&) {
                     ASSERT_LT(i, live.size());
                     const LoadEstimate& a = live[i++];
                     ASSERT_EQ(a.t, e.t) << "row " << i - 1;
                     ASSERT_EQ(a.moment, e.moment) << "t = " << e.t;
                     ASSERT_EQ(a.sigma_moment, e.sigma_moment) << "t = " << e.t;
                     ASSERT_EQ(a.accel_offset, e.accel_offset) << "t = " << e.t;
                     ASSERT_EQ(a.Fa, e.Fa) << "t = " << e.t;
                     ASSERT_EQ(a.theta, e.theta) << "t = " << e.t;
                   });
  EXPECT_EQ(i, live.size());
  EXPECT_EQ(core.sensorTiming().applied, 2 * n);
}

TEST(SensorTiming, AClockTwoSecondsOffIsRefusedAndReported) {
  const TwinConfig cfg = estimatorConfig();
  const HoistProfile trip = HoistProfile::trapezoid(50.0, 2.0, 1.0, 12.0, 12.0);
  const Motion prof{&trip};
  const auto z = truthReadings(cfg.shaft, prof, 1000.0, 1.0, 800, 4);
  {  // --clock input: against the winder's utime
    TwinCore core(cfg, ClockMode::Input);
    for (long k = 0; k < 800; ++k) {
      const WinderSample w = winderAt(prof, k);
      if (k == 100) {
        EXPECT_EQ(core.onCageImu(w.utime + 2'000'000, z[k].f_y, z[k].omega, 0.0, 0), SensorVerdict::ClockOffset);
        EXPECT_TRUE(raised(core.events(), AlarmKind::SensorFault, AlarmEventType::Raise));
        EXPECT_EQ(core.lastSensorFault().sensor, SensorId::CageImu);
        EXPECT_EQ(core.lastSensorFault().reason, SensorFaultReason::ClockOffset);
        EXPECT_NEAR(core.lastSensorFault().value, 2.0, 0.011);
        EXPECT_DOUBLE_EQ(core.lastSensorFault().limit, 0.5);
        core.clearEvents();
      } else {
        // a late but good sensor is not a fault: 0.3 s behind
        EXPECT_EQ(core.onRopeLoad(w.utime - 300'000, z[std::max(k - 30, 0L)].rope_load, 0.0, 0),
                  SensorVerdict::Queued);
        EXPECT_EQ(core.onCageImu(w.utime, z[k].f_y, z[k].omega, 0.0, 0), SensorVerdict::Queued);
      }
      core.onInput(w, 0.0);
      const bool fault = core.alarms().find(AlarmKind::SensorFault, AlarmLevel::Warning)->active();
      if (k >= 100 && k < 100 + 490) {
        EXPECT_TRUE(fault) << k;
      }
      if (k >= 100 + 510) {
        EXPECT_FALSE(fault) << k;  // cleared kSensorFaultHold after its cause
      }
    }
    EXPECT_EQ(core.sensorTiming().clock_refused, 1);
    EXPECT_TRUE(raised(core.events(), AlarmKind::SensorFault, AlarmEventType::Clear) ||
                !core.alarms().find(AlarmKind::SensorFault, AlarmLevel::Warning)->active());
  }
  {  // --clock wall: against the wall clock at arrival
    TwinCore core(cfg, ClockMode::Wall);
    const std::int64_t wall_utime = kT0 + 10'000'000;
    EXPECT_EQ(core.onRopeLoad(wall_utime - 2'000'000, 12000.0, 10.0, wall_utime), SensorVerdict::ClockOffset);
    EXPECT_EQ(core.onRopeLoad(wall_utime + 2'000'000, 12000.0, 10.0, wall_utime), SensorVerdict::ClockOffset);
    EXPECT_EQ(core.lastSensorFault().sensor, SensorId::RopeLoad);
    EXPECT_EQ(core.onRopeLoad(wall_utime - 400'000, 12000.0, 10.0, wall_utime), SensorVerdict::Queued);
    EXPECT_EQ(core.sensorTiming().clock_refused, 2);
    EXPECT_TRUE(core.alarms().find(AlarmKind::SensorFault, AlarmLevel::Warning)->active());
  }
}

TEST(SensorTiming, AUtimeGoingBackIsRejectedAndCounted) {
  TwinCore core(estimatorConfig(), ClockMode::Input);
  const HoistProfile trip = HoistProfile::trapezoid(50.0, 2.0, 1.0, 12.0, 12.0);
  const Motion prof{&trip};
  for (long k = 0; k < 10; ++k) core.onInput(winderAt(prof, k), 0.0);
  const std::int64_t u = winderAt(prof, 9).utime;
  EXPECT_EQ(core.onCageImu(u, 0.01, 0.0, 0.0, 0), SensorVerdict::Queued);
  EXPECT_EQ(core.onCageImu(u, 0.01, 0.0, 0.0, 0), SensorVerdict::TimeBackwards);       // the same utime
  EXPECT_EQ(core.onCageImu(u - 5000, 0.01, 0.0, 0.0, 0), SensorVerdict::TimeBackwards);  // before it
  EXPECT_EQ(core.onRopeLoad(u - 5000, 12000.0, 0.0, 0), SensorVerdict::Queued);         // per sensor
  EXPECT_EQ(core.sensorTiming().time_backwards, 2);
  EXPECT_EQ(core.lastSensorFault().reason, SensorFaultReason::TimeBackwards);
  EXPECT_TRUE(core.alarms().find(AlarmKind::SensorFault, AlarmLevel::Warning)->active());
}

namespace {

/// At rest at 150 m with the configured load, a gap that puts CAGE_POS_Y
/// WARNING on (from the estimate) and CRITICAL off; then 0.1 s of forged IMU
/// samples reading no tilt (the cage would hang straight); then the genuine
/// IMU again.
/// Returns whether CAGE_POS_Y WARNING ever cleared, and the load changes.
struct ForgeResult {
  bool cleared = false;
  bool was_active = false;
  std::int64_t load_changes = 0;
  bool held = false;
};
ForgeResult forgeAtRest(double clear_hold, long forged_ticks = 10) {
  TwinConfig cfg = estimatorConfig();
  cfg.shaft.b = 3.0;  // a static tilt the IMU reads at 12 times its noise
  const Motion rest;  // at rest at 150 m
  double excursion = 0.0;
  {
    TwinCore probe(cfg, ClockMode::Input);
    probe.onInput(winderAt(rest, 0), 0.0);
    excursion = probe.output().clearance.excursion_pos;
  }
  cfg.alarms.gap_pos_y = excursion / 0.6;  // WARNING at 0.5 gap: on; CRITICAL at 0.8 gap: off
  cfg.estimator.clear_hold = clear_hold;
  cfg.alarms.off_delay = 0.0;  // the alarm's own debounce out of the way: the hold alone decides
  const auto z = truthReadings(cfg.shaft, rest, cfg.shaft.Fa, cfg.shaft.b, 1000, 9);
  double tilt = 0.0;  // the genuine f_y at rest
  for (int k = 0; k < 100; ++k) tilt += z[static_cast<std::size_t>(k)].f_y / 100.0;
  TwinCore core(cfg, ClockMode::Input);
  ForgeResult r;
  for (long k = 0; k < 1000; ++k) {
    const WinderSample w = winderAt(rest, k);
    const bool forged = k >= 300 && k < 300 + forged_ticks;  // 10 ticks: 0.1 s
    core.onCageImu(w.utime, forged ? z[k].f_y - tilt : z[k].f_y, z[k].omega, 0.0, 0);
    core.onRopeLoad(w.utime, z[k].rope_load, 0.0, 0);
    core.onInput(w, 0.0);
    const BinaryAlarm* a = core.alarms().find(AlarmKind::CagePosY, AlarmLevel::Warning);
    if (k == 299) r.was_active = a->active();
    if (k >= 300) {
      r.cleared = r.cleared || raised(core.events(), AlarmKind::CagePosY, AlarmEventType::Clear);
      r.held = r.held || core.estimateGate().holding(core.modelTime());
    }
    core.clearEvents();
  }
  r.load_changes = core.estimatorCounters()->load_changes;
  return r;
}

}  // namespace

TEST(SensorTiming, AForgedStepAtRestCannotClearAnActiveAlarm) {
  const ForgeResult r = forgeAtRest(2.0);
  ASSERT_TRUE(r.was_active);
  EXPECT_GE(r.load_changes, 1);  // the forgery was taken for a load change ...
  EXPECT_TRUE(r.held);           // ... and the alarms held their state
  EXPECT_FALSE(r.cleared);
  // Nor 1.5 s of it.  (Without the hold the estimator no longer follows
  // this forgery either -- the sample that reveals a load change is not
  // applied, and a zeroed tilt is a quiet sensor -- so what the hold itself
  // does is shown on the gate alone, below.)
  const ForgeResult longer = forgeAtRest(2.0, 150);
  ASSERT_TRUE(longer.was_active);
  EXPECT_FALSE(longer.cleared);
}

// The gate's rule on its own: after a load change the alarms get the more
// alarming of the new judgement and the one just before, for clear_hold
// seconds, so a new estimate may raise at once but clears only once it held.
TEST(EstimateGate, ALoadChangeClearsOnlyAfterTheHold) {
  AlarmConfig ac;
  auto judge = [&](double excursion) {
    Judgement j;
    j.clearance.excursion_pos = excursion;
    j.clearance.clearance_pos = ac.gap_pos_y - excursion;
    j.lambda0_slack = j.lambda0_overload = 1000.0;
    return j;
  };
  for (const double hold : {0.0, 2.0}) {
    EstimateGate gate(ac, hold);
    const Judgement high = judge(0.2), low = judge(0.01);
    double t = 0.0;
    for (; t < 1.0; t += 0.01) gate.step(t, true, 0, high, low, 0, 1000.0, 500.0);
    // The load changes (count 0 -> 1) and the estimate now says "far from the wall".
    const double change_t = t;
    double cleared_at = -1.0;
    for (; t < 5.0; t += 0.01) {
      const Judgement& j = gate.step(t, true, 0, low, low, 1, 300.0, -50.0);
      if (cleared_at < 0.0 && j.clearance.excursion_pos < 0.1) cleared_at = t;
    }
    ASSERT_GE(cleared_at, 0.0) << "hold " << hold;
    if (hold == 0.0) {
      EXPECT_NEAR(cleared_at, change_t, 1e-9);
    } else {
      EXPECT_GE(cleared_at, change_t + hold - 0.011);
      EXPECT_LE(cleared_at, change_t + hold + 0.011);
    }
    EXPECT_GE(gate.events(), 1);
  }
}

TEST(SensorTiming, AnAbsurdReadingGivesAnEstimateThatIsNotUsed) {
  const TwinConfig cfg = estimatorConfig();
  const Motion rest;
  const auto z = truthReadings(cfg.shaft, rest, cfg.shaft.Fa, cfg.shaft.b, 400, 2);
  TwinCore core(cfg, ClockMode::Input);
  bool fault = false, used_while_absurd = false;
  for (long k = 0; k < 400; ++k) {
    const WinderSample w = winderAt(rest, k);
    const bool absurd = k >= 200;  // f_y = 99 m/s^2 from 2 s on (inside the sample bound of 100)
    core.onCageImu(w.utime, absurd ? 99.0 : z[k].f_y, absurd ? 0.0 : z[k].omega, 0.0, 0);
    core.onInput(w, 0.0);
    if (k >= 260) {
      const LoadEstimate& e = *core.estimate();
      const bool outside = std::abs(e.theta) > 0.1 || std::abs(e.y_c) > 1.0;
      if (outside && core.estimateInUse()) used_while_absurd = true;
      fault = fault || core.alarms().find(AlarmKind::SensorFault, AlarmLevel::Warning)->active();
    }
    if (k == 199) {
      EXPECT_TRUE(core.estimateInUse());
    }
  }
  EXPECT_FALSE(used_while_absurd);
  EXPECT_TRUE(fault);
  EXPECT_FALSE(core.estimateInUse());
  EXPECT_NE(core.estimateGate().notUsed(), 0u);
}
