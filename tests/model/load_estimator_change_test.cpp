// Load changes at rest as one event (hoist/load_estimator.hpp, "Load
// changes"): the station sequence of a hoist's day -- a light load goes
// down, at rest the conveyance is loaded, 5 s later it goes up.  Truth:
// tests/model/sensor_truth.hpp (n = 100, the change an exact step response).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "hoist/load_estimator.hpp"
#include "sensor_truth.hpp"

using namespace hoist;
using namespace hoist::test;

namespace {

// stationSequence(10): down 2 -> 57 s, rest, up from 67 s.  The load changes at 62 s.
constexpr double kChange = 62.0, kUp = 67.0;

void station(double imu_noise, unsigned seed, bool require_no_mismatch) {
  const Load before{300.0, 0.2}, after{1800.0, -0.7};
  const double dFa = after.Fa - before.Fa, dM = after.Fa * after.b - before.Fa * before.b;
  static const CleanTruth tr = simulate(config(), stationSequence(10.0), before, 100, kChange, {dFa, dM / dFa});
  SensorErrors err;
  err.white.imu_accel = imu_noise;
  err.vibration = 0.75;
  EstimatorSettings set;
  set.noise.imu_accel = imu_noise;
  // A calibrated IMU (the truth has no offset).  With the offset free
  // (imu_accel_offset_sigma = 0.005) M is not settled 5 s after the change:
  // at rest M and the offset are one number (measured: 40-130 N m off,
  // 1-3x its 3-sigma band; docs/estimation.md, "The accelerometer's offset").
  set.accel_offset_sigma = 0.0;
  bool checked = false, mismatch_up = false, nis_up = false;
  double change_t = -1.0;
  LoadEstimate at_move;
  estimateRecorded(config(), set, 0.0025, measure(tr, err, seed), [&](const LoadEstimate& e,
                                                                      const EstimatorCounters&) {
    if (e.change_t > kChange - 1.0 && change_t < 0.0) change_t = e.change_t;
    if (!checked && e.t >= kUp - 0.01 - 1e-9) {
      checked = true;
      at_move = e;
    }
    if (e.t >= kUp && e.nis_exceeded) nis_up = true;
    if (e.t >= kUp && e.mismatch && !mismatch_up) {
      mismatch_up = true;
      std::printf("  MODEL_MISMATCH at %.2f: nis %d (%.1f of %.1f) drift %d (%.2f), M %.1f +- %.1f\n", e.t,
                  e.nis_exceeded, e.nis_window, e.nis_bound, e.drift_exceeded, e.drift, e.moment, e.sigma_moment);
    }
  });
  const double Fa = after.Fa, M = after.Fa * after.b;
  std::printf("[ station, IMU %.3f, seed %u ] change found at %.2f s (true %.1f); at %.2f s: Fa %.1f +- %.1f (true %.0f), "
              "M %.1f +- %.1f (true %.0f), size %.0f N, %.0f N m; MODEL_MISMATCH on the trip up: %s (NIS %s)\n",
              imu_noise, seed, change_t, kChange, at_move.t, at_move.Fa, at_move.sigma_Fa, Fa, at_move.moment,
              at_move.sigma_moment, M, at_move.change_Fa, at_move.change_moment, mismatch_up ? "yes" : "no",
              nis_up ? "yes" : "no");
  ASSERT_TRUE(checked);
  EXPECT_GE(change_t, kChange);
  EXPECT_LT(change_t, kChange + 2.0) << "the change is found within 2 s";
  EXPECT_LT(std::abs(at_move.Fa - Fa), 3.0 * at_move.sigma_Fa) << "Fa not settled before the cage moves";
  EXPECT_LT(std::abs(at_move.moment - M), 3.0 * at_move.sigma_moment) << "M not settled before the cage moves";
  EXPECT_LT(at_move.sigma_moment, 0.05 * std::abs(M)) << "M settled, but too uncertain to be of use";
  EXPECT_NEAR(at_move.change_Fa, dFa, 0.02 * dFa) << "one change, its full size";
  EXPECT_NEAR(at_move.change_moment, dM, 0.1 * std::abs(dM));
  if (require_no_mismatch) {
    EXPECT_FALSE(mismatch_up) << "MODEL_MISMATCH on the trip up";
    EXPECT_FALSE(nis_up) << "the NIS test fired on the trip up";
  }
}

}  // namespace

// The change is found within 0.1 s, as one event of the right size, and
// both loads are inside their 3-sigma bands of the new truth before the cage
// moves, with the industrial and with a 0.01 m/s^2 IMU.
TEST(LoadEstimatorChange, StationSequenceIndustrialImu) {
  for (unsigned seed : {1u, 2u, 3u}) station(0.002, seed, false);
}

TEST(LoadEstimatorChange, StationSequenceCheapImu) {
  for (unsigned seed : {4u, 5u, 6u}) station(0.01, seed, false);
}

// DISABLED (issue 30, not done): on the trip that follows, MODEL_MISMATCH
// still rises -- the drift test in the trip's first second (M moves ~2 sigma
// as the moving data arrive: the rest estimate's sigma under-states the
// error the step's not fully modelled transient leaves), and in some seeds
// the NIS test.  docs/estimation.md, "Load changes".
TEST(LoadEstimatorChange, DISABLED_StationSequenceNoMismatchOnTheTripUp) {
  for (unsigned seed : {1u, 2u, 3u}) station(0.002, seed, true);
  for (unsigned seed : {4u, 5u, 6u}) station(0.01, seed, true);
}

// The CUSUM's false changes at rest: a long rest with no change, with
// vibration, never re-opens the load.
TEST(LoadEstimatorChange, NoFalseChangeOverALongRest) {
  std::vector<ProfileSample> rest;
  for (int k = 0; k <= 12000; ++k) rest.push_back({k * 0.01, {150.0, 0.0, 0.0}});
  const CleanTruth tr = simulate(config(), HoistProfile(rest), {1200.0, 0.5}, 50);
  SensorErrors err;
  err.vibration = 1.0;
  EstimatorCounters counts;
  estimateRecorded(config(), {}, 0.0025, measure(tr, err, 9),
                   [&](const LoadEstimate&, const EstimatorCounters& c) { counts = c; });
  EXPECT_EQ(counts.load_changes, 0) << "false load changes over 120 s at rest";
}
