// Static equilibrium: the solver's static start against an exact (n -> inf)
// solution of the continuous problem, docs/model.md's static check, the hoisting
// rope's stretch, and convergence in the number of modes.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "hoist/fast_solver.hpp"
#include "hoist/paper_solver.hpp"
#include "hoist/solver.hpp"
#include "exact_static.hpp"

using namespace hoist;
using hoist::test::ExactStatic;
using hoist::test::exactStatic;

namespace {

CageResponse staticAt(ShaftParams p, double l, Method m = Method::Fast) {
  auto model = std::make_shared<const ShaftModel>(p);
  auto s = makeSolver(m, model);
  s->initialize(0.0, {l, 0.0, 0.0}, InitialState::Static);
  return s->response();
}

TEST(Static, ModelCheckOfModelMd) {
  // docs/model.md: n = 50 baseline, lambda = (-31.25, -31.25, +31.25, +31.25) N
  // = Fa b / (4 h), theta_static about 7-8e-4 rad for l = 50..300 m.
  // The paper's truncation: static correction off (with it theta is exact).
  ShaftParams p;
  p.static_correction = false;
  for (double l : {50.0, 100.0, 150.0, 200.0, 250.0, 300.0}) {
    const CageResponse r = staticAt(p, l);
    const double lam = p.Fa * p.b / (4 * p.h);
    EXPECT_NEAR(r.lambda[1], -lam, 1e-9 * lam) << "l = " << l;
    EXPECT_NEAR(r.lambda[2], -lam, 1e-9 * lam);
    EXPECT_NEAR(r.lambda[3], lam, 1e-9 * lam);
    EXPECT_NEAR(r.lambda[4], lam, 1e-9 * lam);
    // "about 7-8e-4": measured 7.24e-4 (50 m) .. 8.40e-4 (300 m) at n = 50.
    EXPECT_GT(r.theta, 7.0e-4) << "l = " << l;
    EXPECT_LT(r.theta, 8.5e-4) << "l = " << l;
    EXPECT_NEAR(r.lambda[0], p.m * p.g + p.Fa, 1e-8 * p.m * p.g);
  }
  // The reference solution's static facts at l = 50 m (tests/data/c1-paper, README).
  const CageResponse r = staticAt(p, 50.0);
  EXPECT_NEAR(r.y_c, 4.944e-3, 1e-6);
  EXPECT_NEAR(r.theta, 7.2418e-4, 1e-8);
  EXPECT_NEAR(r.x_c, 1.5562e-3, 1e-7);
}

TEST(Static, HoistingRopeStretchUnderEndLoad) {
  // x_c = u(l) = Fa l / EA in the continuum; with n modes the static solution
  // is exactly Fa l/EA * sum_{i<=n} 2/k_i^2 (the mode expansion of a ramp).
  for (int n : {5, 50, 200}) {
    ShaftParams p;
    p.n = n;
    for (double l : {50.0, 300.0}) {
      const CageResponse r = staticAt(p, l);
      double s = 0;
      for (int i = 1; i <= n; ++i) {
        const double k = (2.0 * i - 1) * M_PI / 2;
        s += 2 / (k * k);
      }
      const double exact = p.Fa * l / p.EA;
      EXPECT_NEAR(r.x_c, exact * s, 1e-12 * exact) << "n=" << n << " l=" << l;
      EXPECT_NEAR(r.x_c / exact, 1.0, 1.0 / n) << "truncation ~ 4/(pi^2 n)";
      EXPECT_NEAR(r.lambda[0], p.m * p.g + p.Fa, 1e-8 * r.lambda[0]);
    }
  }
}

TEST(Static, LateralConvergesToExactContinuumSolution) {
  // theta converges slowly (point loads on sine modes); y_c and lambda fast.
  // Without the static correction (with it: static_correction_test).
  ShaftParams base;
  base.static_correction = false;
  const double l = 50.0;
  const ExactStatic ex = exactStatic(base, l);
  // docs/model.md / case README: converged theta at l = 50 m is about 8.05e-4 rad.
  EXPECT_NEAR(ex.theta, 8.05e-4, 0.01e-4);
  std::cout << "exact (continuum) at l = 50 m: theta = " << ex.theta << " rad, y_c = " << ex.y_c << " m\n";
  std::cout << "    n      theta_static   theta/exact     y_c_static   y_c/exact\n";
  double prev = 0;
  for (int n : {20, 50, 100, 200}) {
    ShaftParams p = base;
    p.n = n;
    const CageResponse r = staticAt(p, l);
    std::printf("  %3d   %.6e     %.4f       %.6e   %.5f\n", n, r.theta, r.theta / ex.theta, r.y_c, r.y_c / ex.y_c);
    RecordProperty("theta_static_n" + std::to_string(n), std::to_string(r.theta));
    RecordProperty("y_c_static_n" + std::to_string(n), std::to_string(r.y_c));
    EXPECT_GT(r.theta, prev) << "theta must grow monotonically with n";
    prev = r.theta;
    EXPECT_NEAR(r.y_c / ex.y_c, 1.0, n >= 50 ? 1e-3 : 0.02) << "y_c is converged already at n = " << n;
    if (n == 50) {
      EXPECT_GT(r.theta / ex.theta, 0.87);
      EXPECT_LT(r.theta / ex.theta, 0.93);  // "about 10 % below the converged value"
    }
    if (n == 200) {
      EXPECT_NEAR(r.theta, 7.84e-4, 0.01e-4);  // case README: n = 200 gives 7.84e-4
      EXPECT_GT(r.theta / ex.theta, 0.95);
    }
  }
}

TEST(Static, UnequalPreloadsMatchExactSolutionAndSplitTheForces) {
  ShaftParams p;
  p.Tb1 = 25000;
  p.Tb2 = 35000;
  p.n = 200;
  p.static_correction = false;  // the truncation's error (exact with the correction)
  for (double l : {50.0, 200.0, 380.0}) {
    const ExactStatic ex = exactStatic(p, l);
    const CageResponse r = staticAt(p, l);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(r.lambda[k + 1], ex.lambda[k], 0.03 * std::abs(ex.lambda[k])) << l;
    EXPECT_NEAR(r.y_c, ex.y_c, 0.02 * std::abs(ex.y_c));
    EXPECT_GT(std::abs(r.lambda[1] - r.lambda[2]), 0.05 * std::abs(r.lambda[1])) << "lambda_1 != lambda_2";
    // The stiffer rope (2) takes more of the load.
    EXPECT_GT(std::abs(r.lambda[2]), std::abs(r.lambda[1]));
  }
}

TEST(Static, FastAndPaperPathsAgreeAcrossTheShaft) {
  // Including positions close to both shaft ends, where cond(G0) is large but
  // the paper's method is still usable.
  for (int n : {10, 50}) {
    ShaftParams p;
    p.n = n;
    p.static_correction = false;  // the paper's method has none
    auto model = std::make_shared<const ShaftModel>(p);
    PaperSolver paper(model);
    for (double l : {2.0, 10.0, 50.0, 192.0, 300.0, 370.0, 383.0}) {
      const CageResponse f = staticAt(p, l, Method::Fast);
      const CageResponse q = staticAt(p, l, Method::Paper);
      const double cond = paper.conditionG0(l);
      const double tol = 1e-12 * cond * 100;
      EXPECT_NEAR(q.y_c, f.y_c, tol * std::abs(f.y_c) + 1e-15) << "n=" << n << " l=" << l << " cond=" << cond;
      EXPECT_NEAR(q.theta, f.theta, tol * std::abs(f.theta)) << "n=" << n << " l=" << l;
      EXPECT_NEAR(q.x_c, f.x_c, 1e-10 * std::abs(f.x_c));
      for (int k = 0; k < 5; ++k)
        EXPECT_NEAR(q.lambda[k], f.lambda[k], tol * (1 + std::abs(f.lambda[k]))) << "k=" << k << " l=" << l;
    }
  }
}

TEST(Static, PaperPartitionConditionMatchesModelMd) {
  // docs/model.md: cond(G0) is 78 at l = 50 m, 8 at 192 m, 512 at 370 m, 1.6e4 at 383 m.
  ShaftParams p;
  p.n = 5;
  p.static_correction = false;
  PaperSolver s(std::make_shared<const ShaftModel>(p));
  EXPECT_NEAR(s.conditionG0(50.0), 78, 1.5);
  EXPECT_NEAR(s.conditionG0(192.0), 8, 0.6);
  EXPECT_NEAR(s.conditionG0(370.0), 512, 10);
  EXPECT_NEAR(s.conditionG0(383.0) / 1.6e4, 1.0, 0.05);
}

TEST(Static, FastPathAccurateAtTheShaftEnds) {
  // Where the paper's partition breaks down the fast path still matches the
  // exact continuum solution (at n = 200).
  ShaftParams p;
  p.n = 200;
  for (double l : {0.5, 383.9}) {
    const ExactStatic ex = exactStatic(p, l);
    const CageResponse r = staticAt(p, l);
    EXPECT_NEAR(r.y_c, ex.y_c, 0.02 * std::abs(ex.y_c) + 1e-7) << l;
    EXPECT_NEAR(r.theta, ex.theta, 0.06 * std::abs(ex.theta)) << l;
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(r.lambda[k + 1], ex.lambda[k], 1e-6 * std::abs(ex.lambda[k])) << l;
  }
}

}  // namespace

// ShaftModel::staticRopeForce (the reference of ROPE_SLACK / ROPE_OVERLOAD)
// against the solver's static solve: lambda_0 = m g + Fa at every
// length, for both methods and several shafts -- the rope's own weight
// (rho1 g l) does not pass through g0.  Then a rest start settles to it, and
// a constant deceleration shifts it by m a as the cage's equation says.
TEST(Static, RopeForceEqualsTheStaticSolve) {
  std::vector<ShaftParams> shafts(4);
  shafts[1].m = 5000.0;  // a heavy cage, no eccentric load
  shafts[1].Fa = 0.0;
  shafts[2].rho1 = 12.0;  // a heavy rope: its weight must not appear
  shafts[2].g = 9.79;
  shafts[3].Fa = 4000.0;
  shafts[3].n = 12;
  for (std::size_t k = 0; k < shafts.size(); ++k) {
    ShaftParams p = shafts[k];
    auto model = std::make_shared<const ShaftModel>(p);
    const double f = model->staticRopeForce(100.0);
    EXPECT_NEAR(f, p.m * p.g + p.Fa, 1e-12 * f);
    for (double l : {0.5, 50.0, 150.0, 300.0, p.maxRopeLength() - 0.5}) {
      SCOPED_TRACE("shaft " + std::to_string(k) + ", l = " + std::to_string(l));
      EXPECT_EQ(model->staticRopeForce(l), f);
      for (bool corr : {true, false}) {
        p.static_correction = corr;
        EXPECT_NEAR(staticAt(p, l).lambda[0], f, 1e-9 * f) << "fast, static_correction " << corr;
      }
      p.static_correction = false;
      if (l >= 50.0 && l <= 300.0) {  // the paper partition is ill-conditioned near the ends
        EXPECT_NEAR(staticAt(p, l, Method::Paper).lambda[0], f, 1e-8 * f) << "paper";
      }
    }
  }
  // Dynamics agree: from rest (q = 0, the load applied as a step) lambda_0
  // oscillates about the static force and the damped rope settles to it.
  ShaftParams p;
  p.u1 = 3000.0;  // 100x the paper's rope damping: settle within seconds
  auto model = std::make_shared<const ShaftModel>(p);
  auto s = makeSolver(Method::Fast, model);
  const Kinematics rest{150.0, 0.0, 0.0};
  s->initialize(0.0, rest, InitialState::Rest);
  for (int i = 1; i <= 2000; ++i) s->step(i * 0.005, rest);
  const double f = model->staticRopeForce(rest.l);
  EXPECT_NEAR(s->response().lambda[0], f, 1e-4 * f);
  // Constant a (no jerk after the start): lambda_0 -> Fa + m (g - a).
  const double a = -2.0;  // descending and braking
  s->initialize(0.0, {150.0, 3.0, a}, InitialState::Static);
  double l = 150.0, v = 3.0;
  for (int i = 1; i <= 1000; ++i) {
    const double dt = 0.001;
    l += v * dt + 0.5 * a * dt * dt;
    v += a * dt;
    s->step(i * dt, {l, v, a});
  }
  EXPECT_NEAR(s->response().lambda[0], p.Fa + p.m * (p.g - a), 2e-2 * f);
}
