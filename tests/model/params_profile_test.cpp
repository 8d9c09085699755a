// Parameter validation (errors name the TOML key) and hoist profiles.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "hoist/params.hpp"
#include "hoist/profile.hpp"

using namespace hoist;

namespace {

void expectKey(const std::function<void(ShaftParams&)>& mutate, const std::string& key) {
  ShaftParams p;
  mutate(p);
  try {
    p.validate();
    ADD_FAILURE() << "no error for " << key;
  } catch (const ParamError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos);
  }
}

TEST(Params, PaperBaselineIsValid) { EXPECT_NO_THROW(paperBaseline().validate()); }

TEST(Params, InvalidValuesNameTheirKey) {
  expectKey([](auto& p) { p.m = -800; }, "cage.mass");
  expectKey([](auto& p) { p.m = 0; }, "cage.mass");
  expectKey([](auto& p) { p.J = NAN; }, "cage.inertia");
  expectKey([](auto& p) { p.h = 250; }, "cage.half_height");  // cage longer than the guide rope
  expectKey([](auto& p) { p.rho1 = INFINITY; }, "hoisting_rope.mass_per_length");
  expectKey([](auto& p) { p.EA = 0; }, "hoisting_rope.axial_stiffness");
  expectKey([](auto& p) { p.u1 = -1; }, "hoisting_rope.damping");
  expectKey([](auto& p) { p.l0 = 390; }, "hoisting_rope.initial_length");
  expectKey([](auto& p) { p.l0 = 0; }, "hoisting_rope.initial_length");
  expectKey([](auto& p) { p.L = -4; }, "guide_ropes.length");
  expectKey([](auto& p) { p.rho2 = 0; }, "guide_ropes.mass_per_length");
  expectKey([](auto& p) { p.u2 = NAN; }, "guide_ropes.damping");
  expectKey([](auto& p) { p.Tb2 = -5; }, "guide_ropes.preload");
  expectKey([](auto& p) { p.Fa = NAN; }, "load.eccentric_force");
  expectKey([](auto& p) { p.b = INFINITY; }, "load.offset");
  expectKey([](auto& p) { p.n = 0; }, "model.modes");
  expectKey([](auto& p) { p.n = kMaxModes + 1; }, "model.modes");
  expectKey([](auto& p) { p.g = -9.81; }, "model.gravity");
  expectKey([](auto& p) { p.rho_inf = 1.5; }, "model.rho_inf");
}

TEST(Profile, PaperTrapezoidMatchesFig2) {
  const HoistProfile p = HoistProfile::trapezoid();
  EXPECT_DOUBLE_EQ(p.startTime(), 0.0);
  EXPECT_NEAR(p.endTime(), 60.0, 1e-12);
  EXPECT_EQ(p.samples().size(), 6001u);
  auto k = p.at(0.0);
  EXPECT_DOUBLE_EQ(k.l, 50.0);
  EXPECT_DOUBLE_EQ(k.a, 1.0);
  k = p.at(5.0);
  EXPECT_NEAR(k.l, 62.5, 1e-9);
  EXPECT_NEAR(k.v, 5.0, 1e-12);
  EXPECT_DOUBLE_EQ(k.a, 0.0);  // right-continuous, like the reference profile
  k = p.at(50.0);
  EXPECT_NEAR(k.l, 287.5, 1e-9);
  EXPECT_DOUBLE_EQ(k.a, -1.0);
  k = p.at(55.0);
  EXPECT_NEAR(k.l, 300.0, 1e-9);
  EXPECT_NEAR(k.v, 0.0, 1e-12);
  EXPECT_NEAR(p.at(60.0).l, 300.0, 1e-9);
}

TEST(Profile, HermiteInterpolationIsExactForQuadraticMotion) {
  std::vector<ProfileSample> s;
  for (int i = 0; i <= 10; ++i) {
    const double t = i * 0.5;
    s.push_back({t, {10 + 2 * t + 0.3 * t * t, 2 + 0.6 * t, 0.6}});
  }
  const HoistProfile p(s);
  for (double t : {0.1, 1.37, 4.9}) {
    const auto k = p.at(t);
    EXPECT_NEAR(k.l, 10 + 2 * t + 0.3 * t * t, 1e-12);
    EXPECT_NEAR(k.v, 2 + 0.6 * t, 1e-12);
    EXPECT_NEAR(k.a, 0.6, 1e-12);
  }
}

TEST(Profile, FromVelocityIntegratesLength) {
  std::vector<double> t, v, a;
  for (int i = 0; i <= 100; ++i) {
    const double ti = i * 0.1;
    t.push_back(ti);
    v.push_back(std::sin(ti));
    a.push_back(std::cos(ti));
  }
  const HoistProfile p = HoistProfile::fromVelocity(t, v, a, 50.0);
  EXPECT_NEAR(p.at(10.0).l, 50.0 + 1 - std::cos(10.0), 1e-6);
}

TEST(Profile, RejectsNonIncreasingTime) {
  EXPECT_THROW(HoistProfile(std::vector<ProfileSample>{{0, {50, 0, 0}}, {0, {50, 0, 0}}}), std::invalid_argument);
  EXPECT_THROW(HoistProfile(std::vector<ProfileSample>{{0, {NAN, 0, 0}}}), std::invalid_argument);
  EXPECT_THROW(HoistProfile(std::vector<ProfileSample>{}), std::invalid_argument);
}

TEST(Profile, SCurveIsJerkLimitedAndReachesTarget) {
  const HoistProfile p = HoistProfile::sCurve(50, 5, 1, 0.5, 250, 70, 0.01);
  double amax = 0, jmax = 0, vmax = 0;
  const auto& s = p.samples();
  for (size_t i = 1; i < s.size(); ++i) {
    amax = std::max(amax, std::abs(s[i].k.a));
    vmax = std::max(vmax, std::abs(s[i].k.v));
    jmax = std::max(jmax, std::abs(s[i].k.a - s[i - 1].k.a) / 0.01);
    // v is the derivative of l
    EXPECT_NEAR((s[i].k.l - s[i - 1].k.l) / 0.01, 0.5 * (s[i].k.v + s[i - 1].k.v), 1e-3);
  }
  EXPECT_LE(amax, 1.0 + 1e-9);
  EXPECT_LE(vmax, 5.0 + 1e-9);
  EXPECT_LE(jmax, 0.5 + 1e-6);
  EXPECT_NEAR(s.back().k.l, 300.0, 1e-6);
  EXPECT_NEAR(s.back().k.v, 0.0, 1e-9);
}

TEST(Profile, EmergencyStop) {
  const HoistProfile p = HoistProfile::emergencyStop(50, 5, 10, 2.5, 20, 0.01);
  EXPECT_NEAR(p.at(5).v, 5, 1e-12);
  EXPECT_NEAR(p.at(11).a, -2.5, 1e-12);
  EXPECT_NEAR(p.at(15).v, 0, 1e-12);
  // cruise 10 s at 5 m/s, then stop in 2 s over 5 m
  EXPECT_NEAR(p.at(20).l, 50 + 50 + 5.0 * 5.0 / (2 * 2.5), 1e-9);
}

}  // namespace

#include "hoist/simulator.hpp"

namespace {

TEST(Simulate, SubstepsSplitTheOutputStep) {
  SimulationOptions o;
  o.dt = 0.01;
  o.max_step = 0.0025;
  EXPECT_EQ(substepsFor(o), 4);
  o.max_step = 0.003;
  EXPECT_EQ(substepsFor(o), 4);
  o.max_step = 0.0;
  EXPECT_EQ(substepsFor(o), 1);
  o.max_step = 0.02;
  EXPECT_EQ(substepsFor(o), 1);
  o.max_step = -1;
  EXPECT_THROW(substepsFor(o), std::invalid_argument);
}

TEST(Simulate, OutputsEveryDtAndEndsAtProfileEnd) {
  auto model = std::make_shared<const ShaftModel>(ShaftParams{});
  auto s = makeSolver(Method::Fast, model);
  SimulationOptions o;
  o.dt = 0.05;
  o.max_step = 0.01;
  std::vector<double> t;
  simulate(*s, HoistProfile::trapezoid(), o, [&](const CageResponse& r) { t.push_back(r.t); });
  ASSERT_EQ(t.size(), 1201u);
  EXPECT_NEAR(t[1], 0.05, 1e-12);
  EXPECT_NEAR(t.back(), 60.0, 1e-9);
}

}  // namespace
