// The shaft's condition over many trips (issue 32): sequences of trips
// alternating down and up with a different load at each station (b on both
// sides, some near zero), at rest between trips, made by our own model at
// n = 100 with the static correction and seeded industrial-IMU noise, run
// through the whole offline pipeline (recordTrips: the estimator, the trip
// records, the identification) at the twin's n = 25, then the trend
// (PreloadTrend) and the fingerprint (ShaftFingerprint).
//
// Cost: the truths are superpositions of a few runs per preload scale and
// direction (trip_truth.hpp), shared between the tests.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "hoist/preload_trend.hpp"
#include "hoist/preload_verdict.hpp"
#include "hoist/shaft_fingerprint.hpp"
#include "hoist/trip_pipeline.hpp"
#include "trip_truth.hpp"

using namespace hoist;
using namespace hoist::test;

namespace {

constexpr int kTruthN = 100;
constexpr double kTop = 50.0, kTravel = 280.0, kSegment = 49.0;
constexpr double kDistFrom = 150.0, kDistMoment = 300.0;  // the local push: 300 N m over l in [150, 160) m

ShaftParams twin() {
  ShaftParams p;
  p.n = 25;
  p.static_correction = true;
  return p;
}

const std::vector<ProfileSample>& kin(bool down) {
  static const auto d = tripKinematics(kTop, kTravel, 3.0, kSegment);
  static const auto u = tripKinematics(kTop + kTravel, -kTravel, 3.0, kSegment);
  return down ? d : u;
}

const UnitRuns& truth(double s, bool down, bool disturbed) {
  static std::map<std::tuple<double, bool, bool>, UnitRuns> cache;
  const auto key = std::make_tuple(s, down, disturbed);
  auto it = cache.find(key);
  if (it == cache.end()) {
    ShaftParams p = twin();
    p.n = kTruthN;
    it = cache.emplace(key, truthRuns(p, s, kin(down), disturbed ? kDistMoment : 0.0, kDistFrom)).first;
  }
  return it->second;
}

struct Load {
  double Fa, b;
};
// Loads at the stations: both sides of the axis, and some near it.
const Load kLoads[] = {{1600, 0.7}, {900, -0.8}, {2000, 0.02}, {1200, 0.9}, {500, -0.6},
                       {1800, -0.75}, {700, 0.01}, {1400, 0.6}, {1000, -0.9}, {2200, 0.5}};

/// Trips i0 .. i0 + s.size() - 1 (even: down), preload scale s[k], through recordTrips.
std::vector<TripRecord> runSequence(const std::vector<double>& scales, int i0, unsigned seed, bool disturbed = false,
                                    double accel = 0.002, double offset_prior = 0.0) {
  SensorNoise noise;
  noise.imu_accel = accel;
  std::vector<MeasurementSample> all;
  for (std::size_t k = 0; k < scales.size(); ++k) {
    const int i = i0 + static_cast<int>(k);
    const bool down = i % 2 == 0;
    const Load L = kLoads[i % 10];
    const auto seg = tripSamples(truth(scales[k], down, disturbed), kin(down), k * (kSegment + 0.01), L.Fa, L.b,
                                 noise, seed + 7919u * i);
    all.insert(all.end(), seg.begin(), seg.end());
  }
  EstimatorSettings est;
  est.noise = noise;
  ConditionSettings cond;
  cond.accel_offset_sigma = offset_prior;  // [sensors] imu_accel_offset_sigma (0: calibrated)
  auto recs = recordTrips(twin(), est, cond, 0.0025, all);
  for (std::size_t k = 0; k < recs.size(); ++k) recs[k].trip = i0 + static_cast<long>(k) + 1;
  return recs;
}

const std::vector<TripRecord>& nominal20() {
  static const auto r = runSequence(std::vector<double>(20, 1.0), 0, 100);
  return r;
}

void print(const TripRecord& r, double s_true, double M_true) {
  std::printf("  trip %2lld %-4s s_true %.2f  s = %6.3f +- %.3f  (%+5.2f sigma)  M = %7.1f +- %.1f (true %7.1f)  %s  cpu %.2f s\n",
              static_cast<long long>(r.trip), r.direction == TripDirection::Down ? "down" : "up", s_true, r.id.scale,
              r.id.sigma_scale, (r.id.scale - s_true) / r.id.sigma_scale, r.id.moment, r.id.sigma_moment, M_true,
              r.id.informative ? "informative" : "NOT informative", r.id.cpu_seconds);
}

}  // namespace

TEST(ConditionSequence, NominalPreloadNeverLow) {
  const auto& recs = nominal20();
  ASSERT_EQ(recs.size(), 20u);
  PreloadTrend trend{ConditionSettings{}};
  int informative = 0;
  for (std::size_t k = 0; k < recs.size(); ++k) {
    const TripRecord& r = recs[k];
    const Load L = kLoads[k % 10];
    print(r, 1.0, L.Fa * L.b);
    EXPECT_EQ(r.direction, k % 2 == 0 ? TripDirection::Down : TripDirection::Up);
    if (r.id.sigma_scale > 0.0) {
      EXPECT_LT(std::abs(r.id.scale - 1.0), 3.0 * r.id.sigma_scale) << "trip " << r.trip;
    }
    if (std::abs(L.b) < 0.05) { EXPECT_FALSE(r.id.informative) << "a load near the axis tells nothing: trip " << r.trip; }
    informative += r.id.informative;
    trend.add(r);
    const PreloadDecision d = trend.decision();
    EXPECT_EQ(d.level, ConditionLevel::None) << d.text;
    // MODEL_MISMATCH's trip-end preload test, the trip's and the trend's: quiet.
    EXPECT_FALSE(judgeTripPreload(r.id, 1.0, 4.0).mismatch) << "trip " << r.trip;
    EXPECT_FALSE(judgeTrendPreload(d, 1.0, 4.0).mismatch) << d.text;
  }
  EXPECT_GE(informative, 12);
  std::printf("  trend: %s\n", trend.decision().text.c_str());
  EXPECT_NEAR(trend.scale(), 1.0, 3.0 * trend.sigma());
}

TEST(ConditionSequence, PreloadFallingByStepsRaisesTheAlarmWithinTwoTrips) {
  // 1.0 x 4, 0.9 x 3, then 0.75 (the truth crosses 0.85 at trip 8), then 0.6 (below 0.70 at trip 11).
  const std::vector<double> s = {1.0, 1.0, 1.0, 1.0, 0.9, 0.9, 0.9, 0.75, 0.75, 0.75, 0.6, 0.6, 0.6};
  const auto recs = runSequence(s, 0, 200);
  ASSERT_EQ(recs.size(), s.size());
  PreloadTrend trend{ConditionSettings{}};
  int first_warning = -1, first_critical = -1;
  for (std::size_t k = 0; k < recs.size(); ++k) {
    const Load L = kLoads[k % 10];
    print(recs[k], s[k], L.Fa * L.b);
    if (recs[k].id.sigma_scale > 0.0) {
      EXPECT_LT(std::abs(recs[k].id.scale - s[k]), 3.0 * recs[k].id.sigma_scale) << "trip " << recs[k].trip;
    }
    trend.add(recs[k]);
    const PreloadDecision d = trend.decision();
    std::printf("    trend %.3f +- %.3f (upper %.3f) level %d\n", d.scale, d.sigma, d.upper95, int(d.level));
    if (d.level >= ConditionLevel::Warning && first_warning < 0) {
      first_warning = static_cast<int>(k) + 1;
      std::printf("    WARNING: %s\n", d.text.c_str());
    }
    if (d.level == ConditionLevel::Critical && first_critical < 0) {
      first_critical = static_cast<int>(k) + 1;
      std::printf("    CRITICAL: %s\n", d.text.c_str());
      EXPECT_FALSE(d.trips.empty());
    }
  }
  EXPECT_GE(first_warning, 8) << "no warning before the truth crosses 0.85";
  EXPECT_LE(first_warning, 9) << "warning within 2 trips of the crossing (trip 8)";
  EXPECT_GE(first_critical, 11);
  EXPECT_LE(first_critical, 12) << "critical within 2 trips of the truth going below 0.70 (trip 11)";
}

TEST(ConditionSequence, FingerprintQuietOnHealthyAndFindsALocalPush) {
  ConditionSettings cond;
  cond.baseline_trips = 6;  // 6 per direction (the default 10 would double the run time of the test)
  ShaftFingerprint healthy(cond), sick(cond);
  for (const TripRecord& r : nominal20()) {
    healthy.add(r);
    sick.add(r);
    const FingerprintDecision d = healthy.decision();
    EXPECT_FALSE(d.active) << "trip " << r.trip << ": " << d.text;
  }
  // Four more trips with a local push at 150-160 m (a station inset's air flow).
  const auto dis = runSequence({1.0, 1.0, 1.0, 1.0}, 20, 300, true);
  ASSERT_EQ(dis.size(), 4u);
  int first = -1;
  for (std::size_t k = 0; k < dis.size(); ++k) {
    sick.add(dis[k]);
    const FingerprintDecision d = sick.decision();
    std::printf("  trip %lld: z at 150 m = %.1f  %s\n", static_cast<long long>(dis[k].trip),
                sick.lastZ(dis[k].direction).count(15) ? sick.lastZ(dis[k].direction).at(15) : 0.0, d.text.c_str());
    for (const auto& [bin, z] : sick.lastZ(dis[k].direction))
      if (std::abs(z) > 3.0) std::printf("    |z| > 3 at %ld m: %.1f\n", bin * 10, z);
    if (d.active && first < 0) {
      first = static_cast<int>(k) + 1;
      // The strongest hit is the push's depth, and the text names it first; weaker
      // hits are the oscillation the push excites, seen after it.
      ASSERT_FALSE(d.hits.empty());
      EXPECT_DOUBLE_EQ(d.hits.front().depth_lo, kDistFrom);
      EXPECT_EQ(d.text.find("150-160 m"), d.text.find("depth ") + 6) << d.text;
    }
  }
  {
    const FingerprintDecision d = sick.decision();
    for (TripDirection dd : {TripDirection::Down, TripDirection::Up}) {
      bool at = false;
      for (const FingerprintHit& h : d.hits) at = at || (h.direction == dd && h.depth_lo == kDistFrom);
      EXPECT_TRUE(at) << "both directions see the push at 150 m after 2 trips each";
    }
  }
  EXPECT_GE(first, 2);
  EXPECT_LE(first, 3) << "2 of the last 3 trips in one direction";
}

// The same 20-trip sequence of stations on a shaft whose guide ropes are at
// x0.7, and on the healthy one, fitted with the accelerometer's offset free
// ([sensors] imu_accel_offset_sigma = 0.005, the default; the truth has no
// offset): one trip is often not enough to tell (the trip's own test), the
// shaft's trend adds the trips up.  MODEL_MISMATCH's trip-end test (either
// fires) then rises within a few trips on the weak shaft and never on the
// healthy one.
TEST(ConditionSequence, OffsetFreeTheTrendRaisesModelMismatchOnTheWeakShaftWithinAFewTrips) {
  const double prior = EstimatorSettings{}.accel_offset_sigma;
  for (const double s_true : {1.0, 0.7}) {
    const auto recs = runSequence(std::vector<double>(s_true < 1.0 ? 8 : 20, s_true), 0, 300, false, 0.002, prior);
    PreloadTrend trend{ConditionSettings{}};
    int first = -1, trip_fired = 0, trend_fired = 0;
    double worst = 0.0;
    for (std::size_t k = 0; k < recs.size(); ++k) {
      const Load L = kLoads[k % 10];
      print(recs[k], s_true, L.Fa * L.b);
      trend.add(recs[k]);
      const PreloadVerdict a = judgeTripPreload(recs[k].id, 1.0, 4.0);
      const PreloadVerdict b = judgeTrendPreload(trend.decision(), 1.0, 4.0);
      trip_fired += a.mismatch;
      trend_fired += b.mismatch;
      worst = std::max({worst, a.judged ? std::abs(a.z) : 0.0, b.judged ? std::abs(b.z) : 0.0});
      char text[320];
      describe(b, text, sizeof text);
      std::printf("    trip z %+.2f%s, %s\n", a.z, a.mismatch ? " FIRES" : "", text);
      if ((a.mismatch || b.mismatch) && first < 0) first = static_cast<int>(k) + 1;
    }
    std::printf("  [ s %.1f, offset free ] MODEL_MISMATCH first after trip %d; the trip's test fired on %d, the "
                "trend's on %d of %zu trips; largest |z| %.2f\n",
                s_true, first, trip_fired, trend_fired, recs.size(), worst);
    if (s_true == 1.0) {
      EXPECT_EQ(first, -1) << "a healthy shaft never raises it";
    } else {
      EXPECT_GE(first, 1);
      EXPECT_LE(first, 4) << "the weak shaft within four trips";
      // Measured: the trips' own test fired on 3 of 8 (the others |z| 0-2.9,
      // or not identified: loads near the axis); the trend on all 8.
      EXPECT_GE(trend_fired, static_cast<int>(recs.size()) - 2) << "the trend holds what single trips cannot tell";
      EXPECT_LT(trip_fired, trend_fired);
    }
  }
}
