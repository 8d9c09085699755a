// The static correction (residual flexibility of the guide ropes at the
// sleeves, docs/model.md): statics exact for every n against the exact
// continuum solution, the corrected shapes and envelope consistent with the
// sleeves, the residual flexibility positive and vanishing as n grows, and
// the paper path refusing the option.
#include <gtest/gtest.h>

#include <cmath>
#include <array>
#include <cstdio>

#include "exact_static.hpp"
#include "hoist/fast_solver.hpp"
#include "hoist/paper_solver.hpp"
#include "hoist/simulator.hpp"
#include "hoist/solver.hpp"
#include "test_util.hpp"

using namespace hoist;
using hoist::test::ExactStatic;
using hoist::test::exactStatic;
using hoist::test::nrms;
using hoist::test::readCsv;
using hoist::test::Table;

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

// ---- dynamics ---------------------------------------------------------------

HoistProfile caseProfile(const std::string& cs) {
  const Table t = readCsv(hoist::test::dataDir() + "/" + cs + "/profile.csv");
  std::vector<ProfileSample> s;
  for (const auto& r : t.rows) s.push_back({r[0], {r[1], r[2], r[3]}});
  return HoistProfile(std::move(s));
}

/// hoist-sim's defaults: output every 10 ms, 2.5 ms integration substeps.
std::vector<CageResponse> runCase(const std::string& cs, InitialState init, int n, bool corr, double t_end = -1) {
  ShaftParams p;  // the cases are the paper baseline
  p.n = n;
  p.static_correction = corr;
  auto s = std::make_unique<FastSolver>(std::make_shared<const ShaftModel>(p));
  SimulationOptions o;
  o.dt = 0.01;
  o.max_step = 0.0025;
  o.initial = init;
  o.t_end = t_end;
  std::vector<CageResponse> out;
  simulate(*s, caseProfile(cs), o, [&](const CageResponse& r) { out.push_back(r); });
  return out;
}

const char* kLat[6] = {"y_c", "theta", "lambda_1", "lambda_2", "lambda_3", "lambda_4"};
double latValue(const CageResponse& r, int c) { return c == 0 ? r.y_c : c == 1 ? r.theta : r.lambda[c - 1]; }

/// nRMS of each lateral column of `run` against the reference table rows
/// (matched by time; the table may be sparser than the run).
std::array<double, 6> errorsAgainst(const std::vector<CageResponse>& run, const Table& ref, double t_max = 1e9) {
  std::array<double, 6> e{};
  for (int c = 0; c < 6; ++c) {
    std::vector<double> a, b;
    for (const auto& row : ref.rows) {
      if (row[0] > t_max + 1e-9) break;
      const auto k = static_cast<std::size_t>(std::lround(row[0] / 0.01));
      if (k >= run.size()) break;
      EXPECT_NEAR(run[k].t, row[0], 1e-9);
      a.push_back(latValue(run[k], c));
      b.push_back(row[ref.col(kLat[c])]);
    }
    e[c] = nrms(a, b);
  }
  return e;
}

void printErrors(const char* what, const std::array<double, 6>& e) {
  std::printf("  %-34s", what);
  for (double v : e) std::printf(" %8.2e", v);
  std::printf("\n");
}

// The converged reference WITHOUT the correction: Richardson extrapolation of
// n = 200 and n = 400 (tests/data/c1-converged, generate.sh: a 60-s trip at
// n = 400 takes ~15 s of CPU, too slow to regenerate in every CTest run).
struct Tol {
  double y_c, theta, lambda;
};
std::array<double, 6> checkAgainstConverged(const std::string& cs, const std::string& file, InitialState init,
                                            int n, Tol tol) {
  const Table ref = readCsv(hoist::test::dataDir() + "/c1-converged/" + file);
  EXPECT_GT(ref.rows.size(), 2900u);
  std::printf("%s vs converged (nRMS)       y_c      theta    lambda_1 lambda_2 lambda_3 lambda_4\n", cs.c_str());
  const auto on = errorsAgainst(runCase(cs, init, n, true), ref);
  const std::string label = "n = " + std::to_string(n) + ", static correction on";
  printErrors(label.c_str(), on);
  const auto off = errorsAgainst(runCase(cs, init, n, false), ref);
  printErrors(("n = " + std::to_string(n) + ", off").c_str(), off);
  for (int c = 0; c < 6; ++c) {
    ::testing::Test::RecordProperty(cs + "_n" + std::to_string(n) + "_nrms_" + kLat[c], std::to_string(on[c]));
    EXPECT_LE(on[c], c == 0 ? tol.y_c : c == 1 ? tol.theta : tol.lambda) << cs << " n=" << n << " " << kLat[c];
  }
  return off;
}

TEST(StaticCorrection, PaperStaticStartAtTwentyModesMatchesTheConvergedModel) {
  // Issue 13's tolerances: 1 % on y_c and theta, 2 % on lambda_1..4 (measured
  // 6e-4, 7e-4, 2e-4; without the correction theta is 33 % off).
  const auto off = checkAgainstConverged("c1-paper", "static.csv", InitialState::Static, 20, {0.01, 0.01, 0.02});
  EXPECT_GT(off[1], 0.2) << "the uncorrected n = 20 tilt is far off";
}

TEST(StaticCorrection, PaperRestStartMatchesTheConvergedModel) {
  // The rest start launches sharp waves along the guide ropes (the step load);
  // their reflections from the rope ends (the top at 2 x 50 m / 130 m/s =
  // 0.77 s, ...) reach the sleeves as short force pulses that 20 or 50 sine
  // modes cannot represent, with or without the correction: lambda_1..4 stay
  // ~5 % off in nRMS at n = 20 and n = 50 (issue 13 asked for 2 %: not met,
  // see docs/model.md).  The tilt is where the correction matters: 33 % ->
  // 1.9 % at n = 20 (issue: 1 %), 0.5 % at n = 50.
  const auto off20 = checkAgainstConverged("c1-paper-rest", "rest.csv", InitialState::Rest, 20, {0.01, 0.025, 0.065});
  EXPECT_GT(off20[1], 0.2);
  checkAgainstConverged("c1-paper-rest", "rest.csv", InitialState::Rest, 50, {0.01, 0.01, 0.06});
}

TEST(StaticCorrection, ConvergedReferenceIsReproducibleInTest) {
  // A cheaper in-test check of the committed reference: Richardson
  // extrapolation of n = 50 and n = 100 over the first 15 s of the rest start
  // agrees with it (the committed file is what its generator says it is).
  const double T = 15.0;
  const auto a = runCase("c1-paper-rest", InitialState::Rest, 50, false, T);
  const auto b = runCase("c1-paper-rest", InitialState::Rest, 100, false, T);
  std::vector<CageResponse> x = b;
  for (std::size_t k = 0; k < x.size(); ++k) {
    x[k].y_c = 2 * b[k].y_c - a[k].y_c;
    x[k].theta = 2 * b[k].theta - a[k].theta;
    for (int j = 1; j <= 4; ++j) x[k].lambda[j] = 2 * b[k].lambda[j] - a[k].lambda[j];
  }
  const Table ref = readCsv(hoist::test::dataDir() + "/c1-converged/rest.csv");
  const auto e = errorsAgainst(x, ref, T);
  const auto e100 = errorsAgainst(b, ref, T);
  printErrors("Richardson(50, 100) vs committed", e);
  printErrors("n = 100 alone vs committed", e100);
  // Measured: y_c 4.9e-3, theta 1.3e-2 (n = 100 alone: 5.3e-2); the rest of
  // the difference is the next order in 1/n that (200, 400) removes better.
  EXPECT_LT(e[0], 0.01);
  EXPECT_LT(e[1], 0.02);
  EXPECT_LT(e[1], 0.5 * e100[1]) << "the extrapolation must improve on n = 100 alone";
}

/// Lateral energy with compliant sleeves: kinetic + modal strain energy +
/// the residual springs' 1/2 lamS^T R lamS - work of the eccentric load.
double energyWithResidual(const FastSolver& s) {
  const auto& m = s.model();
  const auto& p = m.params();
  VectorXd q, qd;
  s.lateralState(q, qd);
  const int n = p.n;
  double E = 0;
  for (int r = 1; r <= 2; ++r) {
    const auto qr = q.segment((r - 1) * n, n), qdr = qd.segment((r - 1) * n, n);
    E += 0.5 * p.rho2 * p.L * qdr.squaredNorm() + 0.5 * qr.dot(m.guideStiffness(r) * qr);
  }
  E += 0.5 * p.m * qd(2 * n) * qd(2 * n) + 0.5 * p.J * qd(2 * n + 1) * qd(2 * n + 1);
  E -= p.Fa * p.b * q(2 * n + 1);
  const Eigen::Vector4d& ls = s.residualSpringForces();
  E += 0.5 * ls.dot(s.residualFlexibility() * ls);
  return E;
}

TEST(StaticCorrection, EnergyIncludingTheResidualSpringsNeverGrows) {
  // u1 = u2 = 0, v = 0, trapezoidal rule (energy-conserving on its own): the
  // residual spring stores 1/2 lamS^T R lamS and the high modes' dashpot may
  // only remove energy, so the total never exceeds its initial value.
  ShaftParams p;
  p.n = 15;
  p.u1 = p.u2 = 0.0;
  p.rho_inf = 1.0;
  FastSolver s(std::make_shared<const ShaftModel>(p));
  const Kinematics k{120.0, 0.0, 0.0};
  s.initialize(0.0, k, InitialState::Rest);
  const double E0 = energyWithResidual(s);
  double Emax = E0, Emin = E0, thmax = 0, spring = 0;
  for (int i = 1; i <= 2000; ++i) {
    s.step(i * 0.005, k);
    const double E = energyWithResidual(s);
    Emax = std::max(Emax, E);
    Emin = std::min(Emin, E);
    thmax = std::max(thmax, std::abs(s.response().theta));
    const Eigen::Vector4d& ls = s.residualSpringForces();
    spring = std::max(spring, 0.5 * ls.dot(s.residualFlexibility() * ls));
  }
  const double scale = p.Fa * p.b * thmax;
  EXPECT_GT(spring, 1e-3 * scale) << "the residual springs must carry visible energy";
  EXPECT_LT((Emax - E0) / scale, 1e-6) << "energy must not be created";
  EXPECT_GT((E0 - Emin) / scale, 0.01) << "the step load does work (E falls)";
}

TEST(StaticCorrection, PaperMethodRefusesIt) {
  ShaftParams p;
  p.n = 10;
  EXPECT_THROW(PaperSolver(std::make_shared<const ShaftModel>(p)), std::invalid_argument);
  p.static_correction = false;
  EXPECT_NO_THROW(PaperSolver(std::make_shared<const ShaftModel>(p)));
}

}  // namespace

namespace {

TEST(FastLongitudinal, FusedStepMatrixMatchesThePreviousForm) {
  // The cost lever: E built in one pass from the constant matrices, Ek never
  // formed.  Same equations, different rounding: x_c and lambda_0 agree to
  // round-off over the paper's trip (the hoisting rope's kHz modes included).
  for (int n : {10, 50}) {
    ShaftParams p;
    p.n = n;
    auto model = std::make_shared<const ShaftModel>(p);
    FastSolver a(model), b(model);
    b.setFusedLongitudinal(false);
    const HoistProfile prof = HoistProfile::trapezoid();
    a.initialize(0.0, prof.at(0.0));
    b.initialize(0.0, prof.at(0.0));
    double worst = 0, scale = 0;
    for (int k = 1; k <= 6000; ++k) {
      const double t = 0.01 * k;
      a.step(t, prof.at(t));
      b.step(t, prof.at(t));
      worst = std::max({worst, std::abs(a.response().x_c - b.response().x_c) / 1e-3,
                        std::abs(a.response().lambda[0] - b.response().lambda[0]) / 1e4});
      scale = std::max(scale, std::abs(b.response().x_c));
    }
    EXPECT_LT(worst, 1e-9) << "n = " << n;
    EXPECT_GT(scale, 1e-4);
  }
}

}  // namespace
