// MODEL_MISMATCH's trip-end preload test (hoist/preload_verdict.hpp; issue
// 30): the whole trip's identified preload scale against the twin's.  The
// rule itself, then its false alarms on healthy shafts and its detections
// on the weak one over seeded trips, with the offset free (the default) and
// calibrated.  Truths: our own model at n = 100 with the static correction
// (tests/model/sensor_truth.hpp), an industrial IMU (0.002 m/s^2) with 15-50
// Hz vibration of 0.5-1 times its white noise.  The weak shaft's calibrated
// detections are LoadEstimatorCheck.WeakPreloadsWithVibrationRaiseMismatch.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>

#include "hoist/preload_identification.hpp"
#include "hoist/preload_verdict.hpp"
#include "hoist/trip_pipeline.hpp"
#include "sensor_truth.hpp"

using namespace hoist;
using namespace hoist::test;

namespace {

PreloadIdentification identified(double s, double sigma) {
  PreloadIdentification id;
  id.attempted = true;
  id.scale = s;
  id.sigma_scale = sigma;
  id.moment = 900.0;
  id.sigma_moment = 40.0;
  return id;
}

constexpr double kOneMg = 0.0098;  // m/s^2

/// The verdicts of seeds [s0, s0 + n) of `tr` read with `offset`, fitted with
/// the offset prior `prior`, against a twin at s = 1.
int mismatches(const CleanTruth& tr, double prior, double offset, unsigned s0, int n, const char* what,
               double* worst_z = nullptr) {
  EstimatorSettings est;
  PreloadFitOptions opt;
  opt.accel_offset_sigma = prior;
  opt.max_step = 0.0025;
  const double limit = ConditionSettings{}.model_check_sigma;
  int count = 0;
  for (unsigned seed = s0; seed < s0 + static_cast<unsigned>(n); ++seed) {
    SensorErrors e;
    e.vibration = 0.5 + 0.125 * (seed % 5);
    e.accel_offset = offset;
    const PreloadVerdict v = judgeTripPreload(identifyPreload(config(), est, opt, measure(tr, e, seed)).id, 1.0, limit);
    if (v.mismatch) ++count;
    if (worst_z && v.judged && std::abs(v.z) > std::abs(*worst_z)) *worst_z = v.z;
    std::printf("[ %s, prior %.3f, offset %.4f, seed %u ] judged %d, s %.3f +- %.3f, z %+.2f%s\n", what, prior, offset,
                seed, v.judged, v.scale, v.sigma_scale, v.z, v.mismatch ? "  MODEL_MISMATCH" : "");
  }
  return count;
}

}  // namespace

// The rule: two-sided, against the scale the twin runs; a trip that did not
// identify the preload judges nothing.
TEST(PreloadVerdict, TwoSidedAgainstTheScaleTheTwinRuns) {
  const PreloadVerdict weak = judgeTripPreload(identified(0.70, 0.05), 1.0, 4.0);
  EXPECT_TRUE(weak.judged);
  EXPECT_TRUE(weak.mismatch);
  EXPECT_NEAR(weak.z, -6.0, 1e-12);
  // The same trip on a twin that adopted x0.72: consistent.
  const PreloadVerdict adopted = judgeTripPreload(identified(0.70, 0.05), 0.72, 4.0);
  EXPECT_TRUE(adopted.judged);
  EXPECT_FALSE(adopted.mismatch);
  EXPECT_NEAR(adopted.z, -0.4, 1e-12);
  // Stiffer than the twin biases M low: as much a mismatch.
  const PreloadVerdict stiff = judgeTripPreload(identified(1.30, 0.05), 1.0, 4.0);
  EXPECT_TRUE(stiff.mismatch);
  EXPECT_NEAR(stiff.z, 6.0, 1e-12);
  // At the bound: not beyond it.
  EXPECT_FALSE(judgeTripPreload(identified(0.80, 0.05), 1.0, 4.0).mismatch);
  EXPECT_TRUE(judgeTripPreload(identified(0.80, 0.05), 1.0, 3.9).mismatch);
  // Not identified, not attempted, a nonsense scale: nothing judged.
  EXPECT_FALSE(judgeTripPreload(identified(0.5, -1.0), 1.0, 4.0).judged);
  PreloadIdentification none = identified(0.5, 0.01);
  none.attempted = false;
  EXPECT_FALSE(judgeTripPreload(none, 1.0, 4.0).judged);
  EXPECT_FALSE(judgeTripPreload(identified(std::nan(""), 0.01), 1.0, 4.0).judged);
  EXPECT_FALSE(judgeTripPreload(identified(0.5, 0.01), 0.0, 4.0).mismatch);
  // The sentence names the scale, the distance, the bound and what to do.
  char text[320];
  describe(weak, text, sizeof text);
  EXPECT_NE(std::strstr(text, "whole-trip fit: preload x0.70 +- 0.05, 6.0 sigma from the twin's x1 (bound 4)"),
            nullptr) << text;
  EXPECT_NE(std::strstr(text, "shaft softer, moment reads high"), nullptr) << text;
  EXPECT_NE(std::strstr(text, "M = 900 +- 40 N m"), nullptr) << text;
  EXPECT_LE(std::strlen(text), 200u) << "room for alarm_t's prefix and state within its 255 bytes";
  EXPECT_NE(std::strstr(text, "--adopt-preload"), nullptr) << text;
  describe(stiff, text, sizeof text);
  EXPECT_NE(std::strstr(text, "shaft stiffer, moment reads low"), nullptr) << text;
  describe(adopted, text, sizeof text);
  EXPECT_NE(std::strstr(text, "consistent"), nullptr) << text;
  describe(judgeTripPreload(none, 1.0, 4.0), text, sizeof text);
  EXPECT_NE(std::strstr(text, "did not identify"), nullptr) << text;
  // A short buffer is cut, terminated.
  char small[16];
  describe(weak, small, sizeof small);
  EXPECT_EQ(std::strlen(small), sizeof small - 1);
}

// 20 healthy trips (down and up, loads on both sides), each fitted with the
// offset calibrated and with the offset free on an IMU 1 mg off: the
// trip-end test never fires (measured: |z| at most 3.4 over both).
TEST(PreloadVerdict, HealthyTripsNeverRaiseIt) {
  struct Case {
    const char* what;
    HoistProfile prof;
    Load load;
  };
  const Case cases[] = {
      {"healthy down, Fa 1500 b 0.6", HoistProfile::trapezoid(), {1500.0, 0.6}},
      {"healthy down, Fa 800 b -0.5", HoistProfile::trapezoid(), {800.0, -0.5}},
      {"healthy up, Fa 600 b -0.8", HoistProfile::trapezoid(250.0, 5.0, 1.0, -200.0, 55.0), {600.0, -0.8}},
      {"healthy up, Fa 1800 b 0.4", HoistProfile::trapezoid(300.0, 5.0, 1.0, -250.0, 60.0), {1800.0, 0.4}},
  };
  int fired = 0, trips = 0;
  double worst = 0.0;
  unsigned seed = 100;
  for (const Case& c : cases) {
    const CleanTruth tr = simulate(config(), c.prof, c.load, 100);
    fired += mismatches(tr, 0.0, 0.0, seed, 5, c.what, &worst);
    fired += mismatches(tr, EstimatorSettings{}.accel_offset_sigma, kOneMg, seed, 5, c.what, &worst);
    trips += 10;
    seed += 5;
  }
  std::printf("[ healthy ] the trip-end preload test fired on %d of %d trips; largest |z| %.2f\n", fired, trips,
              std::abs(worst));
  EXPECT_EQ(fired, 0);
}

// The weak shaft (both preloads x0.7) on an IMU 1 mg off whose offset is
// free: what one trip can tell (a 30 % loss is 2-8 sigma of s here, the
// offset absorbing part of the depth shape; docs/estimation.md's table).
// Measured (seeds 200-209): 7 of 10 down trips (|z| 4.3-6.9; the others
// 1.8-3.3) and 1 of 10 up trips (three not identifiable: s is then a ratio
// of a small M; the others |z| 0.9-2.7).  Required: 6 of the 10 down trips.
// What one trip cannot tell is the detectability that estimate_t states per
// trip, and the trend over trips (GUIDE_PRELOAD_LOW) adds it up.
TEST(PreloadVerdict, WeakShaftWithTheOffsetFreeIsSeenWhereTheTripCanTell) {
  ShaftParams weak = config();
  weak.Tb1 = weak.Tb2 = 0.7 * 30000.0;
  const double prior = EstimatorSettings{}.accel_offset_sigma;
  const CleanTruth down = simulate(weak, HoistProfile::trapezoid(), {1500.0, 0.6}, 100);
  const CleanTruth up = simulate(weak, HoistProfile::trapezoid(300.0, 5.0, 1.0, -250.0, 60.0), {1800.0, 0.4}, 100);
  const int d = mismatches(down, prior, kOneMg, 200, 10, "weak x0.7 down, Fa 1500 b 0.6");
  const int u = mismatches(up, prior, kOneMg, 200, 10, "weak x0.7 up, Fa 1800 b 0.4");
  std::printf("[ weak, offset free ] the trip-end preload test fired on %d of 10 down and %d of 10 up trips\n", d, u);
  EXPECT_GE(d, 6);
}
