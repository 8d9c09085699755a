// The load estimator's model check on what real sensors read
// (docs/estimation.md, "The model check"): healthy shafts whose IMU carries
// vibration above the model's band never raise MODEL_MISMATCH, the
// weak-preload shaft does in every seed, and a sensor quieter than its own
// noise (zeroed, stuck) is flagged as such.  Truths: tests/model/sensor_truth.hpp
// (the model at n = 100, static correction, 15-50 Hz vibration on f_y).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "hoist/load_estimator.hpp"
#include "hoist/preload_identification.hpp"
#include "hoist/preload_verdict.hpp"
#include "hoist/trip_pipeline.hpp"
#include "sensor_truth.hpp"

using namespace hoist;
using namespace hoist::test;

namespace {

struct Outcome {
  double first_mismatch = -1.0;  // time MODEL_MISMATCH first rose (-1: never)
  double max_nis_ratio = 0.0, max_drift = 0.0;
  double first_fault = -1.0;     // time any sensor fault first rose
  unsigned faults = 0;           // SensorBits ever faulty
  LoadEstimate last;
};

Outcome run(const ShaftParams& cfg, const std::vector<MeasurementSample>& meas, EstimatorSettings set = {}) {
  Outcome o;
  estimateRecorded(cfg, set, 0.0025, meas, [&](const LoadEstimate& e, const EstimatorCounters&) {
    if (e.mismatch && o.first_mismatch < 0.0) {
      o.first_mismatch = e.t;
      std::printf("  first mismatch at %.2f: nis %d (%.1f of %.1f, dof %d) drift %d (%.2f)\n", e.t, e.nis_exceeded,
                  e.nis_window, e.nis_bound, e.nis_dof, e.drift_exceeded, e.drift);
    }
    if (e.nis_dof > 0) o.max_nis_ratio = std::max(o.max_nis_ratio, e.nis_window / e.nis_dof);
    o.max_drift = std::max(o.max_drift, e.drift);
    if (e.faulty && o.first_fault < 0.0) o.first_fault = e.t;
    o.faults |= e.faulty;
    o.last = e;
  });
  return o;
}

SensorErrors industrial(double vibration) {
  SensorErrors e;
  e.white = SensorNoise{};  // 0.002 m/s^2, 1e-4 rad/s, 20 N
  e.vibration = vibration;
  return e;
}

}  // namespace

// The generator itself: the RMS asked for, and no power below the band
// (0.2-s means, a low-pass at ~2.5 Hz, keep almost nothing of it).
TEST(SensorTruth, BandNoiseHasItsRmsAndStaysInItsBand) {
  const BandNoise n(15.0, 50.0, 0.003, 7);
  double s2 = 0.0, m2 = 0.0;
  const int N = 100000, block = 20;
  double block_sum = 0.0;
  int blocks = 0;
  for (int i = 0; i < N; ++i) {
    const double x = n.at(i * 0.01 + 0.003);
    s2 += x * x;
    block_sum += x;
    if ((i + 1) % block == 0) {
      m2 += std::pow(block_sum / block, 2);
      block_sum = 0.0;
      ++blocks;
    }
  }
  const double rms = std::sqrt(s2 / N), block_rms = std::sqrt(m2 / blocks);
  EXPECT_NEAR(rms, 0.003, 0.0003);
  // White noise of the same RMS would keep 1/sqrt(20) = 22 % in the block means.
  EXPECT_LT(block_rms, 0.05 * 0.003) << "block-mean RMS " << block_rms;
}

// 20 seeded healthy trips, down and up, loads on both sides of the axis,
// vibration 0.5 to 1 times the white noise: MODEL_MISMATCH never rises, no
// sensor is judged faulty, and the truth stays inside the 3-sigma bands.
TEST(LoadEstimatorCheck, HealthyTripsWithVibrationNeverRaiseMismatch) {
  struct Case {
    const char* what;
    HoistProfile prof;
    Load load;
  };
  const Case cases[] = {
      {"down, Fa 1500 b 0.6", HoistProfile::trapezoid(), {1500.0, 0.6}},
      {"down, Fa 800 b -0.5", HoistProfile::trapezoid(), {800.0, -0.5}},
      {"up, Fa 600 b -0.8", HoistProfile::trapezoid(250.0, 5.0, 1.0, -200.0, 55.0), {600.0, -0.8}},
      {"up, Fa 1800 b 0.4", HoistProfile::trapezoid(300.0, 5.0, 1.0, -250.0, 60.0), {1800.0, 0.4}},
  };
  int trips = 0, alarms = 0;
  unsigned seed = 100;
  for (const Case& c : cases) {
    const CleanTruth tr = simulate(config(), c.prof, c.load, 100);
    for (int k = 0; k < 5; ++k, ++seed) {
      const double vib = 0.5 + 0.125 * k;
      const Outcome o = run(config(), measure(tr, industrial(vib), seed));
      ++trips;
      if (o.first_mismatch >= 0.0) ++alarms;
      std::printf("[ %s, vibration %.3f, seed %u ] mismatch %s, NIS/dof max %.2f, drift max %.2f, Fa %.1f +- %.1f, "
                  "M %.1f +- %.1f (true %.1f), f_y noise learned %.4f\n",
                  c.what, vib, seed, o.first_mismatch >= 0.0 ? "ROSE" : "never", o.max_nis_ratio, o.max_drift,
                  o.last.Fa, o.last.sigma_Fa, o.last.moment, o.last.sigma_moment, tr.M.back(),
                  o.last.noise_imu_accel);
      EXPECT_LT(o.first_mismatch, 0.0) << c.what << " seed " << seed << ": MODEL_MISMATCH at t = " << o.first_mismatch;
      EXPECT_EQ(o.faults, 0u) << c.what << " seed " << seed << ": a sensor judged faulty at t = " << o.first_fault;
      EXPECT_LT(std::abs(o.last.Fa - tr.Fa.back()), 3.0 * o.last.sigma_Fa) << c.what << " seed " << seed;
      EXPECT_LT(std::abs(o.last.moment - tr.M.back()), 3.0 * o.last.sigma_moment) << c.what << " seed " << seed;
      // The learned noise sees the vibration (sqrt(1 + vib^2) times the white
      // noise, less the monitor's 3-sd discount: 1.14 at vib = 0.75).
      if (vib >= 0.75) { EXPECT_GT(o.last.noise_imu_accel, 0.002 * 1.05) << c.what << " seed " << seed; }
    }
  }
  EXPECT_EQ(trips, 20);
  std::printf("[ healthy ] MODEL_MISMATCH on %d of %d trips\n", alarms, trips);
}

// Both guide-rope preloads 30 % low, an industrial IMU with vibration of half
// and of once its white noise: MODEL_MISMATCH rises in every seed at either
// level -- during the trip by the estimator's constancy test in at least 8
// of 10 (its misses are its power at this white noise, see
// docs/estimation.md's table; the vibration changes nothing), and at the
// trip's end by the trip-end preload test (hoist/preload_verdict.hpp, as
// hoist-twind's trip room runs it) in 9 of 10 (measured: |z| 5.9-11.2 but
// seed 201's 3.0-3.4, which the constancy test sees at 50.7 s); together,
// every seed (seeds 205 and 209, which the constancy test misses or sees
// only at the arrival, have |z| 9.0-10.4 and 6.3-7.3).
TEST(LoadEstimatorCheck, WeakPreloadsWithVibrationRaiseMismatch) {
  ShaftParams shaft = config();
  shaft.Tb1 = shaft.Tb2 = 0.7 * 30000.0;
  const CleanTruth tr = simulate(shaft, HoistProfile::trapezoid(), {1500.0, 0.6}, 100);
  // A calibrated IMU (imu_accel_offset_sigma = 0, or an offset learned by a
  // calibration): with the offset free the constancy test's short memory
  // cannot tell M's depth shape from the offset (measured: 0 of 10 seeds;
  // the trip-end test then sees 7 of 10: PreloadVerdict.*).
  EstimatorSettings set;
  set.accel_offset_sigma = 0.0;
  PreloadFitOptions fit;
  fit.accel_offset_sigma = 0.0;
  fit.max_step = 0.0025;
  const double limit = ConditionSettings{}.model_check_sigma;
  for (double vib : {0.5, 1.0}) {
    int in_trip = 0, raised = 0, n = 0;
    for (unsigned seed = 200; seed < 210; ++seed) {
      const auto meas = measure(tr, industrial(vib), seed);
      const Outcome o = run(config(), meas, set);
      const PreloadVerdict v = judgeTripPreload(identifyPreload(config(), set, fit, meas).id, 1.0, limit);
      ++n;
      const bool during = o.first_mismatch >= 0.0 && o.first_mismatch < 55.0;
      if (during) ++in_trip;
      if (during || v.mismatch) ++raised;
      std::printf("[ weak preloads, vibration %.1f, seed %u ] MODEL_MISMATCH at %.2f s, drift max %.2f, NIS/dof max "
                  "%.2f; trip end: s %.3f +- %.3f, z %+.2f%s\n",
                  vib, seed, o.first_mismatch, o.max_drift, o.max_nis_ratio, v.scale, v.sigma_scale, v.z,
                  v.mismatch ? " MODEL_MISMATCH" : "");
    }
    std::printf("[ weak preloads, vibration %.1f ] during the trip in %d of %d seeds, by the trip's end in %d\n", vib,
                in_trip, n, raised);
    EXPECT_GE(in_trip, 8) << "vibration " << vib;
    EXPECT_EQ(raised, n) << "vibration " << vib << ": MODEL_MISMATCH in every seed";
  }
}

// The same weak shaft after an operator adopted the identified preload into
// the twin (hoist-alarm-ack --adopt-preload 0.7; a twin that adopted it runs
// as a twin configured with it: TwinModel.* in tests/service): the model and
// the shaft agree again, so MODEL_MISMATCH stays down and the moment is
// right, where the twin at the configured preload reads a wrong moment
// (theta = M / k: a softer shaft looks like a larger moment).  Industrial
// IMU with vibration, calibrated and not.
TEST(LoadEstimatorCheck, AfterAdoptingTheIdentifiedPreloadTheWeakShaftReadsHealthy) {
  ShaftParams weak = config();
  weak.Tb1 = weak.Tb2 = 0.7 * 30000.0;
  const CleanTruth tr = simulate(weak, HoistProfile::trapezoid(), {1500.0, 0.6}, 100);
  for (const double offset_sigma : {0.0, 0.005}) {
    EstimatorSettings set;
    set.accel_offset_sigma = offset_sigma;
    int nominal_wrong = 0;
    for (unsigned seed = 300; seed < 305; ++seed) {
      const auto meas = measure(tr, industrial(0.75), seed);
      const Outcome adopted = run(weak, meas, set);
      const Outcome nominal = run(config(), meas, set);
      const double M = tr.M.back();
      std::printf("[ weak shaft, offset sigma %.3f, seed %u ] adopted: mismatch %s, M %.1f +- %.1f; nominal: "
                  "M %.1f +- %.1f, mismatch at %.2f s (true M %.1f)\n",
                  offset_sigma, seed, adopted.first_mismatch >= 0.0 ? "ROSE" : "never", adopted.last.moment,
                  adopted.last.sigma_moment, nominal.last.moment, nominal.last.sigma_moment, nominal.first_mismatch, M);
      EXPECT_LT(adopted.first_mismatch, 0.0) << "seed " << seed;
      EXPECT_LT(std::abs(adopted.last.moment - M), 3.0 * adopted.last.sigma_moment) << "seed " << seed;
      if (std::abs(nominal.last.moment - M) > 3.0 * nominal.last.sigma_moment || nominal.first_mismatch >= 0.0)
        ++nominal_wrong;
    }
    // The comparison can fail: the twin at the configured preload is wrong
    // (its moment outside its band, or MODEL_MISMATCH) in most seeds.
    EXPECT_GE(nominal_wrong, 3) << "offset sigma " << offset_sigma;
  }
}

// What a 0.01 m/s^2 IMU can see of the same weak shaft (reported, not
// required: a 30 % preload loss is then about 1.6 sigma over the trip).
TEST(LoadEstimatorCheck, WeakPreloadsWithACheapImuAreReported) {
  ShaftParams shaft = config();
  shaft.Tb1 = shaft.Tb2 = 0.7 * 30000.0;
  const CleanTruth tr = simulate(shaft, HoistProfile::trapezoid(), {1500.0, 0.6}, 100);
  EstimatorSettings set;
  set.noise.imu_accel = 0.01;
  int detected = 0;
  for (unsigned seed = 300; seed < 305; ++seed) {
    SensorErrors e = industrial(0.75);
    e.white.imu_accel = 0.01;
    const Outcome o = run(config(), measure(tr, e, seed), set);
    if (o.first_mismatch >= 0.0) ++detected;
    EXPECT_EQ(o.faults, 0u);
  }
  std::printf("[ weak preloads, IMU 0.01 m/s^2 ] detected in %d of 5 seeds\n", detected);
}

// The lower side: a sensor far quieter than its own noise is wrong.  A zeroed
// IMU (a dead gateway or a forger) from the start, a rope load stuck at its
// last value from t = 20 s: each flagged (imu_quiet / rope_quiet, the reason
// in the fault bits) within 3 s; the healthy channels stay clean.
TEST(LoadEstimatorCheck, QuietAndStuckSensorsAreFlaggedWithinSeconds) {
  const CleanTruth tr = simulate(config(), HoistProfile::trapezoid(), {1500.0, 0.6}, 50);
  std::vector<MeasurementSample> m = measure(tr, industrial(0.5), 400);
  double stuck_value = 0.0;
  for (auto& s : m) {
    s.z.f_y = 0.0;
    s.z.omega = 0.0;
    if (s.t < 20.0) stuck_value = s.z.rope_load;
    else s.z.rope_load = stuck_value;
  }
  double imu_at = -1.0, rope_at = -1.0;
  bool rope_early = false;
  unsigned imu_bits = 0, rope_bits = 0;
  estimateRecorded(config(), {}, 0.0025, m, [&](const LoadEstimate& e, const EstimatorCounters&) {
    if (e.imu_quiet && imu_at < 0.0) imu_at = e.t;
    if (e.rope_quiet && rope_at < 0.0) rope_at = e.t;
    if (e.rope_quiet && e.t < 20.0) rope_early = true;
    imu_bits |= e.fault_imu_accel;
    rope_bits |= e.fault_rope_load;
  });
  std::printf("[ zero IMU ] flagged at t = %.2f s (%s); [ rope stuck at 20 s ] flagged at t = %.2f s (%s)\n", imu_at,
              sensorFaultReason(imu_bits), rope_at, sensorFaultReason(rope_bits));
  ASSERT_GE(imu_at, 0.0);
  EXPECT_LE(imu_at, 3.0);
  ASSERT_GE(rope_at, 20.0);
  EXPECT_LE(rope_at, 23.0);
  EXPECT_FALSE(rope_early);
  EXPECT_NE(rope_bits & kFaultStuck, 0u);
  EXPECT_NE(imu_bits & (kFaultQuiet | kFaultStuck), 0u);
}

// A channel flat while the winder accelerates, but not bit-identical (a held
// value with a little dither far below the datasheet noise): quiet, not stuck.
TEST(LoadEstimatorCheck, AFlatButDitheredChannelIsQuiet) {
  SensorMonitor mon;
  SensorMonitorSettings s;
  s.sigma = 20.0;
  mon.reset(s);
  double at = -1.0;
  for (int k = 0; k < 1000; ++k) {
    const double t = k * 0.01;
    mon.sample(t, 8800.0 + ((k % 3) - 1) * 0.5);
    if ((mon.faults() & kFaultQuiet) && at < 0.0) at = t;
  }
  EXPECT_NE(mon.faults() & kFaultQuiet, 0u);
  EXPECT_EQ(mon.faults() & kFaultStuck, 0u);
  EXPECT_GT(at, 1.0);
  EXPECT_LT(at, 3.5);
  EXPECT_STREQ(sensorFaultReason(mon.faults()), "quiet");
}

// Physical bounds at the model level: forged-looking inputs inside the
// sample bounds.  Each is caught within 5 s: either the estimate is not
// plausible (with the reason) or the gate rejects the stream and its channel
// is flagged "rejected" -- and a payload significantly below zero (3 sigma)
// is never reported as plausible.
TEST(LoadEstimatorCheck, ForgedInputsAreNotPlausible) {
  const CleanTruth tr = simulate(config(), HoistProfile::trapezoid(), {1500.0, 0.6}, 50);
  const std::vector<MeasurementSample> genuine = measure(tr, industrial(0.5), 500);
  struct Forgery {
    const char* what;
    void (*apply)(MeasurementSample&, const CleanTruth&, std::size_t);
  };
  const Forgery forgeries[] = {
      {"f_y = 99 m/s^2", [](MeasurementSample& m, const CleanTruth&, std::size_t) { m.z.f_y = 99.0; }},
      {"rope load 1e7 N", [](MeasurementSample& m, const CleanTruth&, std::size_t) { m.z.rope_load = 1e7; }},
      {"rope load 0.3 x static",
       [](MeasurementSample& m, const CleanTruth& t, std::size_t i) { m.z.rope_load = 0.3 * t.z[i].rope_load; }},
  };
  for (const Forgery& f : forgeries) {
    std::vector<MeasurementSample> m = genuine;
    for (std::size_t i = 0; i < m.size(); ++i)
      if (m[i].t >= 10.0) f.apply(m[i], tr, i);
    bool negative_plausible = false, implausible_late = true;
    const char* reason = "";
    estimateRecorded(config(), {}, 0.0025, m, [&](const LoadEstimate& e, const EstimatorCounters&) {
      if (e.fa_observed && e.Fa + 3.0 * e.sigma_Fa < 0.0 && e.plausible) negative_plausible = true;
      const bool caught = !e.plausible || e.faulty;
      if (e.t >= 15.0 && !caught) implausible_late = false;
      if (!e.plausible) reason = e.implausible;
      else if (e.faulty) reason = sensorFaultReason(e.fault_imu_accel | e.fault_rope_load);
    });
    std::printf("[ forged: %s ] caught from 15 s on: %s (%s)\n", f.what, implausible_late ? "yes" : "NO", reason);
    EXPECT_TRUE(implausible_late) << f.what;
    EXPECT_FALSE(negative_plausible) << f.what;
  }
  // The genuine stream stays plausible throughout.
  bool all = true;
  estimateRecorded(config(), {}, 0.0025, genuine,
                   [&](const LoadEstimate& e, const EstimatorCounters&) { all = all && e.plausible; });
  EXPECT_TRUE(all);
}

// Cheap sensors and dropouts keep working: 0.04 m/s^2, 4e-3 rad/s, 60 N,
// vibration 0.75 x, 5 % of the samples missing at random and the IMU silent
// for 2 s mid-trip: the loads inside their 3-sigma bands, no MODEL_MISMATCH,
// no sensor fault, plausible throughout.
TEST(LoadEstimatorCheck, CheapSensorsAndDropoutsKeepWorking) {
  const CleanTruth tr = simulate(config(), HoistProfile::trapezoid(), {1500.0, 0.6}, 100);
  SensorErrors err;
  err.white = {0.04, 4e-3, 60.0};
  err.vibration = 0.75;
  EstimatorSettings set;
  set.noise = err.white;
  for (unsigned seed : {600u, 601u}) {
    std::vector<MeasurementSample> m = measure(tr, err, seed);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (auto& s : m) {
      if (u(rng) < 0.05) s.present &= ~(kSensorImuAccel | kSensorImuRate);
      if (u(rng) < 0.05) s.present &= ~kSensorRopeLoad;
      if (s.t > 30.0 && s.t < 32.0) s.present &= ~(kSensorImuAccel | kSensorImuRate);
    }
    const Outcome o = run(config(), m, set);
    bool plausible = true;
    estimateRecorded(config(), set, 0.0025, m,
                     [&](const LoadEstimate& e, const EstimatorCounters&) { plausible = plausible && e.plausible; });
    std::printf("[ cheap sensors, seed %u ] Fa %.1f +- %.1f, M %.1f +- %.1f (true 900), mismatch %s, faults %u\n", seed,
                o.last.Fa, o.last.sigma_Fa, o.last.moment, o.last.sigma_moment,
                o.first_mismatch >= 0.0 ? "ROSE" : "never", o.faults);
    EXPECT_LT(o.first_mismatch, 0.0) << "seed " << seed;
    EXPECT_EQ(o.faults, 0u) << "seed " << seed;
    EXPECT_TRUE(plausible) << "seed " << seed;
    EXPECT_LT(std::abs(o.last.Fa - 1500.0), 3.0 * o.last.sigma_Fa) << "seed " << seed;
    EXPECT_LT(std::abs(o.last.moment - 900.0), 3.0 * o.last.sigma_moment) << "seed " << seed;
  }
}
