// The weak-preload shaft on ONE trip of an uncalibrated accelerometer
// (issue 30; docs/estimation.md, "The accelerometer's offset").  With the
// offset free, MODEL_MISMATCH's constancy test no longer sees both guide
// ropes 30 % low (0 of 10 seeds, LoadEstimatorCheck's shaft and trip): its
// 10-s memory cannot tell M's depth shape from the offset.  The whole trip
// can: the trip record's preload identification (hoist/preload_identification.hpp)
// fits s jointly with M and the offset over the whole depth range, where the
// offset is one constant and a weak preload bends the tilt's depth shape.
// Same truths as LoadEstimatorCheck.WeakPreloadsWithVibrationRaiseMismatch:
// our own model at n = 100 (static correction), Fa 1500 N at 0.6 m, the
// trapezoid trip, an industrial IMU (0.002 m/s^2) with 15-50 Hz vibration of
// half its white noise, and a 1 mg offset the fit is not told.
#include <gtest/gtest.h>

#include <cstdio>

#include "hoist/preload_identification.hpp"
#include "sensor_truth.hpp"

using namespace hoist;
using namespace hoist::test;

namespace {

constexpr double kOneMg = 0.0098;  // m/s^2

struct Tally {
  int below = 0;     // s below 1 by more than 3 sigma: a weak preload seen
  int inside = 0;    // the truth inside s's 3-sigma band (identifiable trips)
  int identified = 0;
};

/// identifyPreload (the trip record's fit) on seeds 200-209 of `tr`, read
/// with a 1 mg offset; `prior`: [sensors] imu_accel_offset_sigma.
Tally fitTrips(const CleanTruth& tr, double s_true, double prior, const char* what) {
  EstimatorSettings est;  // the industrial IMU's noise
  PreloadFitOptions opt;
  opt.accel_offset_sigma = prior;
  opt.max_step = 0.0025;
  Tally t;
  for (unsigned seed = 200; seed < 210; ++seed) {
    SensorErrors e;
    e.vibration = 0.5;
    e.accel_offset = kOneMg;
    const PreloadIdentification id = identifyPreload(config(), est, opt, measure(tr, e, seed)).id;
    const bool ident = id.sigma_scale > 0.0;
    if (ident) {
      ++t.identified;
      if ((1.0 - id.scale) / id.sigma_scale > 3.0) ++t.below;
      if (std::abs(id.scale - s_true) < 3.0 * id.sigma_scale) ++t.inside;
    }
    std::printf("[ %s, prior %.3f, seed %u ] s = %.3f +- %.3f, M = %.0f +- %.0f, chi2/dof %.3f\n", what, prior, seed,
                id.scale, id.sigma_scale, id.moment, id.sigma_moment, id.dof > 0 ? id.chi2 / id.dof : 0.0);
  }
  std::printf("[ %s, prior %.3f ] identified %d of 10, s > 3 sigma below 1 in %d, truth inside 3 sigma in %d\n", what,
              prior, t.identified, t.below, t.inside);
  return t;
}

}  // namespace

// With the offset's prior (the default 0.005) the whole-trip fit finds the
// weak shaft on one uncalibrated trip and leaves the healthy one alone.
TEST(PreloadUncalibrated, TheWholeTripFitSeesTheWeakShaftWithTheOffsetFree) {
  ShaftParams weak = config();
  weak.Tb1 = weak.Tb2 = 0.7 * 30000.0;
  const CleanTruth trw = simulate(weak, HoistProfile::trapezoid(), {1500.0, 0.6}, 100);
  const CleanTruth trh = simulate(config(), HoistProfile::trapezoid(), {1500.0, 0.6}, 100);
  const double prior = EstimatorSettings{}.accel_offset_sigma;
  const Tally w = fitTrips(trw, 0.7, prior, "weak preloads (s 0.7)");
  EXPECT_GE(w.below, 8) << "the weak shaft seen on one uncalibrated trip";
  EXPECT_GE(w.inside, w.identified - 1) << "an honest band (at most one of 10 outside 3 sigma)";
  const Tally h = fitTrips(trh, 1.0, prior, "healthy (s 1)");
  EXPECT_EQ(h.below, 0) << "no false weak preload on the healthy shaft";
  EXPECT_GE(h.inside, h.identified - 1);
}

// The same data fitted as if the accelerometer were calibrated (prior 0,
// what a trip pipeline that is not handed [sensors] imu_accel_offset_sigma
// does): the 1 mg offset is read as tilt.  Measured: on every seed s runs to
// the grid's end (1.6, reported not identifiable) with M about 2030 N m for a
// true 900, where the fit that carries the offset identifies 7 of 10 with
// the truth inside the band in 6.  The reason the prior must reach the fit.
TEST(PreloadUncalibrated, FittedAsCalibratedTheOffsetSpoilsTheHealthyShaftsFit) {
  const CleanTruth trh = simulate(config(), HoistProfile::trapezoid(), {1500.0, 0.6}, 100);
  const Tally h = fitTrips(trh, 1.0, 0.0, "healthy (s 1), offset not fitted");
  const Tally f = fitTrips(trh, 1.0, EstimatorSettings{}.accel_offset_sigma, "healthy (s 1), offset fitted");
  EXPECT_GE(f.inside, f.identified - 1);
  EXPECT_LT(h.inside, f.inside) << "not fitting a real offset must cost the band its honesty";
}
