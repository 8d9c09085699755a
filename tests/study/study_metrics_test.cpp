// Frequency estimators, peaks/RMS and the sweep parameter keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "hoist/study/metrics.hpp"
#include "hoist/study/sweep.hpp"

using namespace hoist;
using namespace hoist::study;

namespace {

struct Signal {
  std::vector<double> t, y;
};

Signal make(double t0, double t1, double dt, const std::function<double(double)>& f) {
  Signal s;
  const long n = std::lround((t1 - t0) / dt);
  for (long i = 0; i <= n; ++i) {
    const double t = t0 + static_cast<double>(i) * dt;
    s.t.push_back(t);
    s.y.push_back(f(t));
  }
  return s;
}

constexpr double kPi = std::numbers::pi;

}  // namespace

TEST(Frequency, PureSineFFTAndZeroCrossings) {
  for (double f : {0.11, 0.37, 1.3, 2.45, 7.0}) {
    auto s = make(0, 60, 0.01, [&](double t) { return 2e-3 * std::sin(2 * kPi * f * t + 0.3); });
    const double ffft = dominantFrequencyFFT(s.t, s.y, 5, 50);
    const double fzc = zeroCrossingFrequency(s.t, s.y, 5, 50);
    const double fc = spectralCentroid(s.t, s.y, 5, 50);
    EXPECT_NEAR(ffft, f, 0.01 * f + 2e-3) << f;  // resolution 1/45 Hz, refined by interpolation
    EXPECT_NEAR(fzc, f, 0.01 * f + 2e-3) << f;
    EXPECT_NEAR(fc, f, 0.03 * f + 5e-3) << f;
  }
}

TEST(Frequency, IgnoresQuadraticDriftAndFindsTheLargerTone) {
  // A quasi-static drift (like the cage's as l changes) plus two tones.
  auto s = make(0, 60, 0.01, [](double t) {
    return 5e-3 - 2e-4 * t + 1e-6 * t * t + 1e-3 * std::sin(2 * kPi * 0.6 * t) +
           3e-4 * std::sin(2 * kPi * 2.2 * t);
  });
  EXPECT_NEAR(dominantFrequencyFFT(s.t, s.y, 5, 50), 0.6, 0.006);
  EXPECT_NEAR(zeroCrossingFrequency(s.t, s.y, 5, 50), 0.6, 0.006);
  // The centroid lies between the tones, weighted by power.
  const double fc = spectralCentroid(s.t, s.y, 5, 50);
  EXPECT_GT(fc, 0.6);
  EXPECT_LT(fc, 2.2);
}

TEST(Frequency, DampedSineAndShortWindow) {
  auto s = make(0, 60, 0.01, [](double t) { return std::exp(-0.05 * t) * std::cos(2 * kPi * 0.9 * t); });
  EXPECT_NEAR(dominantFrequencyFFT(s.t, s.y, 50, 60), 0.9, 0.02);  // 9 cycles in 10 s
  EXPECT_NEAR(zeroCrossingFrequency(s.t, s.y, 50, 60), 0.9, 0.02);
}

TEST(Frequency, NaNWhenUndeterminable) {
  auto flat = make(0, 60, 0.01, [](double t) { return 3.0 + 0.1 * t; });  // removed by the detrend
  EXPECT_TRUE(std::isnan(dominantFrequencyFFT(flat.t, flat.y, 5, 50)));
  EXPECT_TRUE(std::isnan(zeroCrossingFrequency(flat.t, flat.y, 5, 50)));
  auto slow = make(0, 60, 0.01, [](double t) { return std::sin(2 * kPi * 0.05 * t); });
  // 0.5 cycle in a 10 s window: below min_cycles / T.
  EXPECT_TRUE(std::isnan(dominantFrequencyFFT(slow.t, slow.y, 50, 60)));
  EXPECT_TRUE(std::isnan(dominantFrequencyFFT(slow.t, slow.y, 59.99, 60)));  // too few samples
}

TEST(Metrics, PeakRmsAndDetrend) {
  auto s = make(0, 10, 0.001, [](double t) { return std::sin(2 * kPi * t); });
  EXPECT_NEAR(peakAbs(s.t, s.y, 0, 10), 1.0, 1e-6);
  EXPECT_NEAR(rms(s.t, s.y, 0, 10), std::sqrt(0.5), 1e-4);
  EXPECT_TRUE(std::isnan(peakAbs(s.t, s.y, 20, 30)));
  auto lin = make(0, 10, 0.1, [](double t) { return 2.0 + 3.0 * t; });
  for (double r : detrended(lin.t, lin.y, 0, 10, 1)) EXPECT_NEAR(r, 0.0, 1e-10);
  EXPECT_NEAR(oscillationAmplitude(s.t, s.y, 0, 10, 0), 1.0, 1e-3);
  MetricSet m;
  m.set("a", 1.0);
  m.set("a", 2.0);
  EXPECT_EQ(m.items().size(), 1u);
  EXPECT_EQ(m.get("a"), 2.0);
  EXPECT_THROW(m.get("b"), std::out_of_range);
}

TEST(Parameters, KeysApplyAndRoundTrip) {
  ShaftParams p;
  applyParameter(p, "guide_ropes.preload", 5e4);
  EXPECT_DOUBLE_EQ(p.Tb1, 2.5e4);
  EXPECT_DOUBLE_EQ(p.Tb2, 2.5e4);
  applyParameter(p, "guide_ropes.preload_difference", 1e4);
  EXPECT_DOUBLE_EQ(p.Tb1, 2e4);
  EXPECT_DOUBLE_EQ(p.Tb2, 3e4);
  EXPECT_DOUBLE_EQ(parameterValue(p, "guide_ropes.preload_difference"), 1e4);
  applyParameter(p, "guide_ropes.preload_split", 0.4);
  EXPECT_DOUBLE_EQ(p.Tb1, 2e4);
  applyParameter(p, "cage.mass_and_inertia", 1600);
  EXPECT_DOUBLE_EQ(p.m, 1600);
  EXPECT_DOUBLE_EQ(p.J, 1740);
  applyParameter(p, "model.modes", 20);
  EXPECT_EQ(p.n, 20);
  applyParameter(p, "model.static_correction", 0);
  EXPECT_FALSE(p.static_correction);
  EXPECT_EQ(parameterValue(p, "model.static_correction"), 0.0);
  applyParameter(p, "model.static_correction", 1);
  EXPECT_TRUE(p.static_correction);
  for (const auto& k : sweepableKeys()) {
    ShaftParams q;
    const double v = parameterValue(q, k);
    if (k == "guide_ropes.preload_difference") continue;  // 0 at the baseline
    EXPECT_NO_THROW(applyParameter(q, k, v)) << k;
    EXPECT_NEAR(parameterValue(q, k), v, 1e-9 * std::abs(v)) << k;
  }
}

TEST(Parameters, ErrorsNameTheKey) {
  ShaftParams p;
  try {
    applyParameter(p, "cage.colour", 1.0);
    FAIL();
  } catch (const ParamError& e) {
    EXPECT_EQ(e.key(), "cage.colour");
    EXPECT_NE(std::string(e.what()).find("cage.mass"), std::string::npos);  // lists valid keys
  }
  EXPECT_THROW(applyParameter(p, "model.modes", 2.5), ParamError);
  EXPECT_THROW(applyParameter(p, "model.static_correction", 0.5), ParamError);
  try {
    sweepStudy("cage.mass", {800, -5}, p);
    FAIL();
  } catch (const ParamError& e) {
    EXPECT_EQ(e.key(), "cage.mass");
    EXPECT_NE(std::string(e.what()).find("-5"), std::string::npos);
  }
}

TEST(Studies, PaperStudiesAreThePapersCases) {
  ShaftParams b;
  auto pre = paperStudy("preload", b);
  ASSERT_TRUE(pre);
  ASSERT_EQ(pre->runs.size(), 3u);
  EXPECT_DOUBLE_EQ(pre->runs[0].params.Tb1 + pre->runs[0].params.Tb2, 4.8e4);
  auto td = paperStudy("tension-difference", b);
  ASSERT_TRUE(td);
  EXPECT_DOUBLE_EQ(td->runs[2].params.Tb1, 2.5e4);
  EXPECT_DOUBLE_EQ(td->runs[2].params.Tb2, 3.5e4);
  auto ms = paperStudy("mass", b);
  ASSERT_TRUE(ms);
  EXPECT_DOUBLE_EQ(ms->runs[1].params.J, 1305);
  EXPECT_FALSE(paperStudy("nonsense", b));
  auto w = stageWindows(HoistProfile::trapezoid());
  ASSERT_EQ(w.size(), 3u);
  EXPECT_NEAR(w[1].t0, 5.0, 1e-9);
  EXPECT_NEAR(w[1].t1, 50.0, 1e-9);
  EXPECT_NEAR(w[2].t1, 60.0, 1e-9);
}

TEST(Parallel, ParallelForRunsAllAndRethrows) {
  std::vector<int> hit(50, 0);
  parallelFor(50, 4, [&](int i) { hit[static_cast<std::size_t>(i)] += 1; });
  for (int h : hit) EXPECT_EQ(h, 1);
  EXPECT_THROW(parallelFor(10, 3, [](int i) { if (i == 7) throw std::runtime_error("x"); }),
               std::runtime_error);
}

TEST(Parameters, EverySweepableTableFieldIsAParam) {
  // hoist-study --param follows hoist::kParamFields: each sweepable field is
  // a key that sets exactly that member; the others are refused by name.
  for (const auto& f : kParamFields) {
    ShaftParams p;
    const std::string key = f.element();
    if (!f.sweepable) {
      EXPECT_THROW(applyParameter(p, key, f.get(p)), ParamError) << key;
      continue;
    }
    EXPECT_NE(std::find(sweepableKeys().begin(), sweepableKeys().end(), key), sweepableKeys().end()) << key;
    EXPECT_NE(parameterHelp().find(key), std::string::npos) << key;
    const double v = f.type == ParamType::Boolean ? 1.0 - f.get(p)
                     : f.type == ParamType::Integer ? 17.0
                                                    : f.get(p) * 1.25;
    applyParameter(p, key, v);
    EXPECT_EQ(f.get(p), v) << key;
    EXPECT_EQ(parameterValue(p, key), v) << key;
    ShaftParams q = p;
    f.set(q, f.get(ShaftParams{}));
    EXPECT_TRUE(q == ShaftParams{}) << key << ": set more than its own member";
  }
}
