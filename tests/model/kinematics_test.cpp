// The one kinematics of the project (hoist/profile.hpp): interpolation inside
// a sampling interval, the rope length integrated from v and a (with the
// h^2 (a0 - a1)/12 term), the substep count.  Each against a closed form,
// with a != 0 (the daemon once dropped the acceleration term and
// its test used a = 0, so nothing noticed).
#include <gtest/gtest.h>

#include <cmath>

#include "hoist/plausibility.hpp"
#include "hoist/profile.hpp"

using namespace hoist;

namespace {

/// The plain trapezoid the daemon used before (no acceleration term).
double plainTrapezoid(double l0, double v0, double v1, double h) { return l0 + h * 0.5 * (v0 + v1); }

}  // namespace

TEST(Kinematics, IntegrateLengthIsExactForConstantJerk) {
  // Constant jerk j from rest: v = j t^2/2, a = j t, l = l0 + j t^3/6.
  const double j = 0.5, l0 = 50.0, h = 0.01;
  double l = l0, plain = l0;
  for (int k = 1; k <= 200; ++k) {  // the 2-s jerk phase of the S-curve default
    const double t0 = (k - 1) * h, t1 = k * h;
    l = integrateLength(l, 0.5 * j * t0 * t0, j * t0, 0.5 * j * t1 * t1, j * t1, h);
    plain = plainTrapezoid(plain, 0.5 * j * t0 * t0, 0.5 * j * t1 * t1, h);
  }
  const double exact = l0 + j * 8.0 / 6.0;
  EXPECT_NEAR(l, exact, 1e-11);
  // The term matters: without it the error is j h^2 t / 12 = 8.3e-6 m here.
  EXPECT_NEAR(plain - exact, j * h * h * 2.0 / 12.0, 1e-10);
}

TEST(Kinematics, SCurveTripFromVelocityMatchesItsClosedForm) {
  // HoistProfile::sCurve samples the closed form; rebuilding l from v and a
  // alone (as a winder without encoder does) must give it back.
  const HoistProfile p = HoistProfile::sCurve(50.0, 5.0, 1.0, 0.5, 250.0, 70.0, 0.01);
  std::vector<double> t, v, a;
  for (const auto& s : p.samples()) {
    t.push_back(s.t);
    v.push_back(s.k.v);
    a.push_back(s.k.a);
  }
  const HoistProfile q = HoistProfile::fromVelocity(t, v, a, 50.0);
  double worst = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) worst = std::max(worst, std::fabs(q.samples()[i].k.l - p.samples()[i].k.l));
  EXPECT_LT(worst, 1e-9);
}

TEST(Kinematics, TrapezoidCornerInsideAnIntervalStaysWithinTheDocumentedBound) {
  // 10 Hz samples of a trapezoid whose acceleration ends at t = 5.05 s, in
  // the middle of an interval: the corrected rule errs by at most h^2/12 per
  // unit jump of a (here h^2/24), the plain trapezoid by h^2/8.
  const double h = 0.1;
  const HoistProfile p = HoistProfile::trapezoid(50.0, 5.05, 1.0, 250.0, 60.0, h);
  double l = 50.0, plain = 50.0, worst = 0.0, worst_plain = 0.0;
  const auto& s = p.samples();
  for (std::size_t i = 1; i < s.size(); ++i) {
    l = integrateLength(l, s[i - 1].k.v, s[i - 1].k.a, s[i].k.v, s[i].k.a, h);
    plain = plainTrapezoid(plain, s[i - 1].k.v, s[i].k.v, h);
    if (s[i].t < 6.0) {  // up to just after the first corner (one unit jump)
      worst = std::max(worst, std::fabs(l - s[i].k.l));
      worst_plain = std::max(worst_plain, std::fabs(plain - s[i].k.l));
    }
  }
  EXPECT_LE(worst, h * h / 12.0);
  EXPECT_NEAR(worst, h * h / 24.0, 1e-9);
  EXPECT_NEAR(worst_plain, h * h / 8.0, 1e-9);
}

TEST(Kinematics, InterpolateIsTheProfilesInterpolation) {
  const HoistProfile p = HoistProfile::sCurve(50.0, 5.0, 1.0, 0.5, 250.0, 70.0, 0.1);
  const auto& s = p.samples();
  for (std::size_t i = 1; i < s.size(); i += 37)
    for (double u : {0.1, 0.25, 0.5, 0.9}) {
      const double t = s[i - 1].t + u * (s[i].t - s[i - 1].t);
      const Kinematics a = p.at(t), b = interpolate(s[i - 1].k, s[i].k, s[i].t - s[i - 1].t, u);
      // Same function; t -> u round trip differs in the last bits only.
      EXPECT_NEAR(a.l, b.l, 1e-12 * std::fabs(a.l));
      EXPECT_NEAR(a.v, b.v, 1e-12);
      EXPECT_NEAR(a.a, b.a, 1e-12);
    }
  // Exact for quadratic l (constant a): l = 3 + 2t + 0.5 t^2 on [0, 1].
  const Kinematics k0{3.0, 2.0, 1.0}, k1{5.5, 3.0, 1.0};
  const Kinematics m = interpolate(k0, k1, 1.0, 0.3);
  EXPECT_NEAR(m.l, 3.0 + 0.6 + 0.045, 1e-14);
  EXPECT_NEAR(m.v, 2.3, 1e-14);
}

TEST(Kinematics, SubstepCountNeverClampsInSilence) {
  EXPECT_EQ(substepCount(0.01, 0.0025), 4);
  EXPECT_EQ(substepCount(0.01, 0.003), 4);
  EXPECT_EQ(substepCount(0.01, 0.0), 1);
  EXPECT_EQ(substepCount(0.01, 0.02), 1);
  EXPECT_EQ(substepCount(1.0, 1e-5, 100000), 100000);
  EXPECT_THROW(substepCount(1.0, 1e-9, 100000), std::invalid_argument);
  EXPECT_THROW(substepCount(0.01, -1.0), std::invalid_argument);
  EXPECT_THROW(substepCount(0.01, std::nan("")), std::invalid_argument);
}

TEST(Plausibility, ValidRangeAndBoundsOfThePaperShaft) {
  const ShaftParams p;
  const LengthRange r = validLengthRange(p);
  EXPECT_DOUBLE_EQ(r.lo, 0.05);
  EXPECT_DOUBLE_EQ(r.hi, 384.0 - 0.05);
  EXPECT_FALSE(r.contains(1e-7));
  EXPECT_FALSE(r.contains(384.0 - 1e-6));
  EXPECT_TRUE(r.contains(50.0));
  const PlausibilityBounds b = plausibilityBounds(p, 1.0);
  CageResponse ok;
  ok.y_c = 0.006;
  ok.theta = 7e-4;
  ok.lambda = {8848.0, -31.25, 31.25, -31.25, 31.25};
  double v = 0, lim = 0;
  EXPECT_EQ(implausible(ok, p.h, b, v, lim), nullptr);
  CageResponse bad = ok;
  bad.y_c = -1e159;  // once published with degraded = 0
  ASSERT_NE(implausible(bad, p.h, b, v, lim), nullptr);
  EXPECT_STREQ(implausible(bad, p.h, b, v, lim), "y_c");
  EXPECT_DOUBLE_EQ(lim, 1.0);
  bad = ok;
  bad.lambda[1] = -359e3 * 10;
  EXPECT_STREQ(implausible(bad, p.h, b, v, lim), "lambda_1");
  bad = ok;
  bad.theta = std::nan("");
  EXPECT_STREQ(implausible(bad, p.h, b, v, lim), "y_c");
}
