// The static correction (residual flexibility of the guide ropes at the
// sleeves, docs/model.md): statics exact for every n against the exact
// continuum solution, the corrected shapes and envelope consistent with the
// sleeves, the residual flexibility positive and vanishing as n grows, and
// the paper path refusing the option.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "exact_static.hpp"
#include "hoist/fast_solver.hpp"
#include "hoist/paper_solver.hpp"
#include "hoist/solver.hpp"

using namespace hoist;
using hoist::test::ExactStatic;
using hoist::test::exactStatic;

namespace {

std::unique_ptr<FastSolver> staticSolver(const ShaftParams& p, double l) {
  auto s = std::make_unique<FastSolver>(std::make_shared<const ShaftModel>(p));
  s->initialize(0.0, {l, 0.0, 0.0}, InitialState::Static);
  return s;
}

TEST(StaticCorrection, IsTheDefault) {
  EXPECT_TRUE(ShaftParams{}.static_correction);
  EXPECT_TRUE(paperBaseline().static_correction);
}

TEST(StaticCorrection, StaticsMatchTheExactContinuumSolutionForEveryN) {
  // y_c, theta, lambda_1..4 within 0.5 % of the exact solution (issue 13);
  // the correction makes the discrete statics exact, so the tolerance is met
  // with orders of magnitude to spare.  Without it, n = 5 is 60 % off in theta.
  std::printf("   n      l   dTb   theta/exact  y_c/exact   max|lam/exact-1|   (uncorrected theta/exact)\n");
  for (double dT : {0.0, 10000.0}) {
    for (int n : {5, 10, 20, 50}) {
      for (double l : {2.0, 50.0, 300.0, 380.0}) {
        ShaftParams p;
        p.n = n;
        p.Tb1 = 30000.0;
        p.Tb2 = 30000.0 + dT;
        const ExactStatic ex = exactStatic(p, l);
        const CageResponse r = staticSolver(p, l)->response();
        const double tol = 0.005;
        EXPECT_NEAR(r.theta / ex.theta, 1.0, tol) << "n=" << n << " l=" << l << " dT=" << dT;
        EXPECT_NEAR(r.y_c / ex.y_c, 1.0, tol) << "n=" << n << " l=" << l << " dT=" << dT;
        double worst = 0;
        for (int k = 0; k < 4; ++k) {
          EXPECT_NEAR(r.lambda[k + 1] / ex.lambda[k], 1.0, tol) << "k=" << k << " n=" << n << " l=" << l;
          worst = std::max(worst, std::abs(r.lambda[k + 1] / ex.lambda[k] - 1.0));
        }
        ShaftParams off = p;
        off.static_correction = false;
        const CageResponse u = staticSolver(off, l)->response();
        std::printf("  %3d  %5.0f  %5.0f   %.6f    %.6f    %.1e            %.4f\n", n, l, dT, r.theta / ex.theta,
                    r.y_c / ex.y_c, worst, u.theta / ex.theta);
        // Round-off only: the discrete static problem IS the continuum one.
        EXPECT_NEAR(r.theta / ex.theta, 1.0, 1e-6);
      }
    }
  }
}

TEST(StaticCorrection, ConvergenceTableAtFiftyMetres) {
  // The README's convergence table (l = 50 m, paper baseline): theta / exact
  // without and with the correction.
  const ShaftParams base;
  const ExactStatic ex = exactStatic(base, 50.0);
  std::printf("    n   theta/exact (off)   theta/exact (on)\n");
  for (int n : {5, 10, 20, 50, 100, 200}) {
    ShaftParams p = base;
    p.n = n;
    const double on = staticSolver(p, 50.0)->response().theta / ex.theta;
    p.static_correction = false;
    const double off = staticSolver(p, 50.0)->response().theta / ex.theta;
    std::printf("  %3d      %.4f             %.4f\n", n, off, on);
    EXPECT_NEAR(on, 1.0, 1e-6) << n;
    EXPECT_LT(off, 0.99) << "the truncation alone is visibly off at n = " << n;
  }
}

TEST(StaticCorrection, ResidualFlexibilityIsPositiveAndVanishesWithN) {
  // R = G - Phi K^-1 Phi^T is the compliance of the modes above n: positive
  // definite per rope, decreasing with n roughly as 1/n.
  double prev = 1e300;
  for (int n : {5, 20, 80, 320}) {
    ShaftParams p;
    p.n = n;
    auto s = staticSolver(p, 120.0);
    const Eigen::Matrix4d& R = s->residualFlexibility();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(R);
    EXPECT_GT(es.eigenvalues().minCoeff(), 0.0) << n;
    EXPECT_LT(R(0, 0), prev) << n;
    if (n > 5) {
      EXPECT_NEAR(R(0, 0) * n / (prev * n / 4), 1.0, 0.25) << "R ~ 1/n at n = " << n;
    }
    prev = R(0, 0);
    // Ropes do not couple.
    EXPECT_EQ(R(0, 1), 0.0);
    EXPECT_EQ(R(0, 2), 0.0);
    EXPECT_EQ(R(3, 1), 0.0);
  }
  ShaftParams off;
  off.static_correction = false;
  EXPECT_EQ(staticSolver(off, 120.0)->residualFlexibility().norm(), 0.0);
}

TEST(StaticCorrection, ShapesAndEnvelopeAreExactStaticShapes) {
  // The corrected static shape is sum_k G(x, a_k) lambda_k exactly; at the
  // sleeves it equals the cage position y_c -/+ h theta.
  ShaftParams p;
  p.n = 10;
  p.Tb2 = 40000.0;
  const double l = 150.0;
  auto s = staticSolver(p, l);
  const ShaftModel& m = s->model();
  const CageResponse& r = s->response();
  VectorXd x = VectorXd::LinSpaced(81, 0.0, p.L);
  x(1) = l;
  x(2) = l + 2 * p.h;
  VectorXd y1, y2;
  s->guideRopeShapes(x, y1, y2);
  double ymax = 0;
  for (int i = 0; i < x.size(); ++i) {
    const double e1 = m.guideGreen(1, x(i), l) * r.lambda[1] + m.guideGreen(1, x(i), l + 2 * p.h) * r.lambda[4];
    const double e2 = m.guideGreen(2, x(i), l) * r.lambda[2] + m.guideGreen(2, x(i), l + 2 * p.h) * r.lambda[3];
    EXPECT_NEAR(y1(i), e1, 1e-9 * std::abs(r.y_c)) << x(i);
    EXPECT_NEAR(y2(i), e2, 1e-9 * std::abs(r.y_c)) << x(i);
    ymax = std::max({ymax, std::abs(e1), std::abs(e2)});
  }
  EXPECT_NEAR(y1(1), r.y_c - p.h * r.theta, 1e-9 * std::abs(r.y_c));
  EXPECT_NEAR(y2(1), r.y_c - p.h * r.theta, 1e-9 * std::abs(r.y_c));
  EXPECT_NEAR(y1(2), r.y_c + p.h * r.theta, 1e-9 * std::abs(r.y_c));
  EXPECT_NEAR(y2(2), r.y_c + p.h * r.theta, 1e-9 * std::abs(r.y_c));
  // The real-time envelope agrees with the shapes on its grid (401 points,
  // 1 m spacing: the kink at the sleeve is at most 1 grid cell from a sample).
  GuideRopeEnvelope env(m, 401);
  const double e = env.evaluate(*s);
  s->guideRopeShapes(env.depths(), y1, y2);
  for (int i = 0; i < env.depths().size(); ++i) {
    EXPECT_NEAR(env.y1()(i), y1(i), 1e-12);
    EXPECT_NEAR(env.y2()(i), y2(i), 1e-12);
  }
  EXPECT_NEAR(e, std::max(y1.cwiseAbs().maxCoeff(), y2.cwiseAbs().maxCoeff()), 1e-15);
  EXPECT_NEAR(e, ymax, 0.01 * ymax);
}

TEST(StaticCorrection, ShapesStayConsistentWithTheSleevesInMotion) {
  // During a trip the corrected shape at the sleeves is the cage position
  // (G q + R lambda = 0 holds at every step).
  ShaftParams p;
  p.n = 12;
  auto s = std::make_unique<FastSolver>(std::make_shared<const ShaftModel>(p));
  const HoistProfile prof = HoistProfile::trapezoid();
  s->initialize(0.0, prof.at(0.0), InitialState::Rest);
  VectorXd x(2), y1, y2;
  for (int k = 1; k <= 1500; ++k) {
    const double t = 0.01 * k;
    s->step(t, prof.at(t));
    if (k % 100) continue;
    const CageResponse& r = s->response();
    x << r.kin.l, r.kin.l + 2 * p.h;
    s->guideRopeShapes(x, y1, y2);
    const double sc = std::abs(r.y_c) + p.h * std::abs(r.theta);
    EXPECT_NEAR(y1(0), r.y_c - p.h * r.theta, 1e-9 * sc) << t;
    EXPECT_NEAR(y2(0), r.y_c - p.h * r.theta, 1e-9 * sc) << t;
    EXPECT_NEAR(y2(1), r.y_c + p.h * r.theta, 1e-9 * sc) << t;
    EXPECT_NEAR(y1(1), r.y_c + p.h * r.theta, 1e-9 * sc) << t;
  }
}

TEST(StaticCorrection, PaperMethodRefusesIt) {
  ShaftParams p;
  p.n = 10;
  EXPECT_THROW(PaperSolver(std::make_shared<const ShaftModel>(p)), std::invalid_argument);
  p.static_correction = false;
  EXPECT_NO_THROW(PaperSolver(std::make_shared<const ShaftModel>(p)));
}

}  // namespace
