// The condition decisions on hand-made records (no physics): the trend's
// filter against its closed form, what it ignores, the alarm levels and
// texts; the fingerprint's baseline, its z and its 2-of-3 rule; the
// [condition] settings' validation naming the key.
#include <gtest/gtest.h>

#include <cmath>

#include "hoist/preload_trend.hpp"
#include "hoist/shaft_fingerprint.hpp"

using namespace hoist;

namespace {

TripRecord trip(std::int64_t n, double s, double sigma, bool informative = true) {
  TripRecord r;
  r.trip = n;
  r.id.attempted = true;
  r.id.scale = s;
  r.id.sigma_scale = sigma;
  r.id.informative = informative;
  return r;
}

TripRecord binned(std::int64_t n, TripDirection d, double resid_at_100, double other = 0.0) {
  TripRecord r;
  r.trip = n;
  r.direction = d;
  for (int k = 0; k < 5; ++k) {
    DepthBinStats b;
    b.depth_lo = 60.0 + 10.0 * k;
    b.samples = 100;
    b.resid_mean = b.depth_lo == 100.0 ? resid_at_100 : other;
    b.resid_rms = 1e-3;  // standard error 1e-4
    r.bins.push_back(b);
  }
  return r;
}

}  // namespace

TEST(PreloadTrend, KalmanFilterWithARandomWalkByTripNumber) {
  ConditionSettings c;  // trend_walk 0.05
  PreloadTrend t(c);
  EXPECT_FALSE(t.decision().valid);
  EXPECT_FALSE(t.add(trip(1, 0.5, 0.5, false)));  // not informative: ignored
  EXPECT_FALSE(t.valid());
  EXPECT_TRUE(t.add(trip(2, 1.0, 0.1)));
  EXPECT_DOUBLE_EQ(t.scale(), 1.0);
  EXPECT_DOUBLE_EQ(t.sigma(), 0.1);
  // Trip 5: three trips of walk since trip 2.
  EXPECT_TRUE(t.add(trip(5, 0.8, 0.1)));
  const double P = 0.01 + 3 * 0.0025, K = P / (P + 0.01);
  EXPECT_NEAR(t.scale(), 1.0 + K * (0.8 - 1.0), 1e-12);
  EXPECT_NEAR(t.sigma(), std::sqrt(P * (1 - K)), 1e-12);
  ASSERT_EQ(t.weights().size(), 2u);
  EXPECT_NEAR(t.weights()[0].second + t.weights()[1].second, 1.0, 1e-12);
  EXPECT_NEAR(t.weights()[1].second, K, 1e-12);
}

TEST(PreloadTrend, LevelsAtTheOneSided95PercentBound) {
  ConditionSettings c;
  {
    PreloadTrend t(c);
    t.add(trip(1, 0.80, 0.03));  // upper 0.849: WARNING
    const PreloadDecision d = t.decision();
    EXPECT_EQ(d.level, ConditionLevel::Warning);
    EXPECT_NE(d.text.find("0.800 +- 0.030"), std::string::npos) << d.text;
    EXPECT_NE(d.text.find("trips 1"), std::string::npos) << d.text;
    EXPECT_NE(d.text.find("tensioning weights"), std::string::npos);
  }
  {
    PreloadTrend t(c);
    t.add(trip(1, 0.80, 0.04));  // upper 0.866: not yet
    EXPECT_EQ(t.decision().level, ConditionLevel::None);
  }
  {
    PreloadTrend t(c);
    t.add(trip(1, 0.60, 0.05));  // upper 0.682: CRITICAL
    EXPECT_EQ(t.decision().level, ConditionLevel::Critical);
  }
}

TEST(ShaftFingerprint, TwoOfTheLastThreeInOneDirection) {
  ConditionSettings c;
  c.baseline_trips = 4;
  ShaftFingerprint f(c);
  // Baseline: residual at 100 m of 1e-3 +- about 2e-4, elsewhere 0.
  const double base[] = {0.8e-3, 1.2e-3, 1.0e-3, 1.0e-3};
  for (int k = 0; k < 4; ++k) EXPECT_FALSE(f.add(binned(k + 1, TripDirection::Down, base[k])));
  EXPECT_TRUE(f.baselineComplete(TripDirection::Down));
  EXPECT_FALSE(f.baselineComplete(TripDirection::Up));
  // sd at 100 m: sqrt(var 0.0267e-6 + se 1e-8) = 1.93e-4: 2e-3 is z = 5.2.
  EXPECT_TRUE(f.add(binned(5, TripDirection::Down, 2.0e-3)));
  EXPECT_NEAR(f.lastZ(TripDirection::Down).at(10), 1e-3 / std::sqrt(0.08e-6 / 3.0 + 1e-8), 1e-9);
  EXPECT_FALSE(f.decision().active);  // once is not enough
  f.add(binned(6, TripDirection::Up, 5e-3));  // another direction: its baseline is being built
  EXPECT_FALSE(f.decision().active);
  f.add(binned(7, TripDirection::Down, 1.0e-3));
  EXPECT_FALSE(f.decision().active);
  f.add(binned(8, TripDirection::Down, 2.0e-3));  // 2 of the last 3
  const FingerprintDecision d = f.decision();
  ASSERT_TRUE(d.active);
  ASSERT_EQ(d.hits.size(), 1u);
  EXPECT_DOUBLE_EQ(d.hits[0].depth_lo, 100.0);
  EXPECT_NE(d.text.find("depth 100-110 m"), std::string::npos) << d.text;
  f.add(binned(9, TripDirection::Down, 1.0e-3));
  f.add(binned(10, TripDirection::Down, 1.0e-3));  // the last 3: one over
  EXPECT_FALSE(f.decision().active);
}

TEST(ConditionSettings, ValidateNamesTheKey) {
  auto expectKey = [](ConditionSettings c, const char* key) {
    try {
      c.validate();
      FAIL() << key;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  ConditionSettings c;
  EXPECT_NO_THROW(c.validate());
  c.max_sigma = 0.0;
  expectKey(c, "condition.max_sigma");
  c = {};
  c.preload_critical = 0.9;
  expectKey(c, "condition.preload_critical");
  c = {};
  c.baseline_trips = 1;
  expectKey(c, "condition.baseline_trips");
  c = {};
  c.trend_walk = -1.0;
  expectKey(c, "condition.trend_walk");
  c = {};
  c.band_hz = std::nan("");
  expectKey(c, "condition.band_hz");
}
