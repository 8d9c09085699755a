// The static correction (residual flexibility of the guide ropes at the
// sleeves, docs/model.md): statics exact for every n against the exact
// continuum solution, the corrected shapes and envelope consistent with the
// sleeves, the residual flexibility positive and vanishing as n grows, and
// the paper path refusing the option.
#include <gtest/gtest.h>

#include <cmath>
#include <array>
#include <cstdio>
#include <map>
#include <numbers>

#include "exact_static.hpp"
#include "hoist/fast_solver.hpp"
#include "hoist/guide_rope_envelope.hpp"
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
  // y_c, theta, lambda_1..4 within 0.5 % of the exact solution (the accuracy target);
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
  // The convergence table (docs/verification.md, docs/model.md; l = 50 m,
  // paper baseline): theta / exact without and with the correction, as
  // printed there (3 decimals).
  const ShaftParams base;
  const ExactStatic ex = exactStatic(base, 50.0);
  std::printf("    n   theta/exact (off)   theta/exact (on)\n");
  const std::map<int, double> documented{{5, 0.146}, {10, 0.372}, {20, 0.672}, {50, 0.899}, {100, 0.948}, {200, 0.974}};
  for (auto [n, doc] : documented) {
    ShaftParams p = base;
    p.n = n;
    const double on = staticSolver(p, 50.0)->response().theta / ex.theta;
    p.static_correction = false;
    const double off = staticSolver(p, 50.0)->response().theta / ex.theta;
    std::printf("  %3d      %.4f             %.4f\n", n, off, on);
    EXPECT_NEAR(on, 1.0, 1e-6) << n;
    EXPECT_LT(off, 0.99) << "the truncation alone is visibly off at n = " << n;
    EXPECT_NEAR(off, doc, 5.5e-4) << "the documented table at n = " << n;
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
/// zscale multiplies the sleeves' dashpot (FastSolver::setResidualDampingScale).
std::vector<CageResponse> runCase(const std::string& cs, InitialState init, int n, bool corr, double t_end = -1,
                                  double zscale = 1.0, double max_step = 0.0025) {
  ShaftParams p;  // the cases are the paper baseline
  p.n = n;
  p.static_correction = corr;
  auto s = std::make_unique<FastSolver>(std::make_shared<const ShaftModel>(p));
  s->setResidualDampingScale(zscale);
  SimulationOptions o;
  o.dt = 0.01;
  o.max_step = max_step;
  o.initial = init;
  o.t_end = t_end;
  std::vector<CageResponse> out;
  simulate(*s, caseProfile(cs), o, [&](const CageResponse& r) { out.push_back(r); });
  return out;
}

const char* kLat[6] = {"y_c", "theta", "lambda_1", "lambda_2", "lambda_3", "lambda_4"};
double latValue(const CageResponse& r, int c) { return c == 0 ? r.y_c : c == 1 ? r.theta : r.lambda[c - 1]; }

/// The run's and the reference's column c at the reference's times (the
/// table may be sparser than the run), up to t_max.
void columns(const std::vector<CageResponse>& run, const Table& ref, int c, std::vector<double>& a,
             std::vector<double>& b, double t_max = 1e9) {
  a.clear();
  b.clear();
  for (const auto& row : ref.rows) {
    if (row[0] > t_max + 1e-9) break;
    const auto k = static_cast<std::size_t>(std::lround(row[0] / 0.01));
    if (k >= run.size()) break;
    EXPECT_NEAR(run[k].t, row[0], 1e-9);
    a.push_back(latValue(run[k], c));
    b.push_back(row[ref.col(kLat[c])]);
  }
}

/// nRMS of each lateral column of `run` against the reference table.
std::array<double, 6> errorsAgainst(const std::vector<CageResponse>& run, const Table& ref, double t_max = 1e9) {
  std::array<double, 6> e{};
  std::vector<double> a, b;
  for (int c = 0; c < 6; ++c) {
    columns(run, ref, c, a, b, t_max);
    e[c] = nrms(a, b);
  }
  return e;
}

/// Zero-phase low-pass: a 2nd-order Butterworth (bilinear transform,
/// prewarped) run forwards and backwards, |H| = 1 / (1 + (f/fc)^4).  The
/// signal is zero before its first sample (a rest start) and held after its last.
std::vector<double> lowPass(const std::vector<double>& x, double fc, double dt) {
  const double K = std::tan(std::numbers::pi * fc * dt), q = std::sqrt(2.0), nrm = 1.0 / (1.0 + q * K + K * K);
  const double b0 = K * K * nrm, b1 = 2 * b0, b2 = b0, a1 = 2 * (K * K - 1) * nrm, a2 = (1 - q * K + K * K) * nrm;
  const std::size_t pad = static_cast<std::size_t>(std::ceil(10.0 / (fc * dt)));  // 10 periods of fc
  std::vector<double> y(pad, 0.0);
  y.insert(y.end(), x.begin(), x.end());
  y.insert(y.end(), pad, x.back());
  auto pass = [&](auto first, auto last) {
    double x1 = *first, x2 = *first, y1 = *first, y2 = *first;
    for (auto it = first; it != last; ++it) {
      const double v = *it, o = b0 * v + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
      x2 = x1;
      x1 = v;
      y2 = y1;
      y1 = o;
      *it = o;
    }
  };
  pass(y.begin(), y.end());
  pass(y.rbegin(), y.rend());
  return {y.begin() + static_cast<std::ptrdiff_t>(pad), y.begin() + static_cast<std::ptrdiff_t>(pad + x.size())};
}

/// The band a rope of n sine modes represents: the n-th natural frequency of
/// the continuum guide rope (rope 1), f_n = n / (2 Int_0^L dx / c),
/// c = sqrt(T / rho2), T = Tb + rho2 g (L - x) (WKB; the formula of
/// docs/figures/convergence/convergence.py, so the table there matches).
double topModeFrequency(int n) {
  const ShaftParams p;
  const double T0 = p.Tb1 + p.rho2 * p.g * p.L, T1 = p.Tb1;
  const double travel = 2.0 * std::sqrt(p.rho2) * (std::sqrt(T0) - std::sqrt(T1)) / (p.rho2 * p.g);
  return n / (2.0 * travel);
}

TEST(StaticCorrection, LowPassIsTheFilterItSays) {
  // The band-limited comparisons rest on lowPass: zero phase, |H| =
  // 1 / (1 + (f / fc)^4) (a sine keeps its phase; half amplitude at fc).
  const double fc = 3.0, dt = 0.01;
  for (double f : {0.3, 1.5, 3.0, 6.0, 15.0}) {
    std::vector<double> x(6000);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(2 * std::numbers::pi * f * dt * static_cast<double>(i) + 0.3);
    const auto y = lowPass(x, fc, dt);
    // Away from the ends: y = H x with the prewarped (bilinear) response.
    const double wd = std::tan(std::numbers::pi * f * dt) / std::tan(std::numbers::pi * fc * dt);
    const double H = 1.0 / (1.0 + std::pow(wd, 4));
    double worst = 0;
    for (std::size_t i = 2000; i < 4000; ++i) worst = std::max(worst, std::abs(y[i] - H * x[i]));
    EXPECT_LT(worst, 1e-6) << f << " Hz";
    if (f == fc) {
      EXPECT_NEAR(H, 0.5, 1e-12);
    }
  }
}

struct BandErrors {
  std::array<double, 6> raw{}, band{}, above{};  // nRMS; low-passed both; the reference's content above fc
};
BandErrors bandErrorsAgainst(const std::vector<CageResponse>& run, const Table& ref, double fc) {
  BandErrors e;
  std::vector<double> a, b;
  for (int c = 0; c < 6; ++c) {
    columns(run, ref, c, a, b);
    const double dt = ref.rows[1][0] - ref.rows[0][0];
    const auto la = lowPass(a, fc, dt), lb = lowPass(b, fc, dt);
    e.raw[c] = nrms(a, b);
    e.band[c] = nrms(la, lb);
    // RMS(ref - lowpass(ref)) / RMS(ref)
    double se = 0, sr = 0;
    for (std::size_t i = 0; i < b.size(); ++i) {
      se += (b[i] - lb[i]) * (b[i] - lb[i]);
      sr += b[i] * b[i];
    }
    e.above[c] = std::sqrt(se / sr);
  }
  return e;
}

void printErrors(const char* what, const std::array<double, 6>& e) {
  std::printf("  %-44s", what);
  for (double v : e) std::printf(" %8.2e", v);
  std::printf("\n");
}

const Table& restReference() {
  static const Table t = readCsv(hoist::test::dataDir() + "/c1-converged/rest.csv");
  return t;
}
const Table& staticReference() {
  static const Table t = readCsv(hoist::test::dataDir() + "/c1-converged/static.csv");
  return t;
}

// The converged references (tests/data/c1-converged, generate.sh; too slow to
// regenerate in every CTest run): static.csv WITHOUT the correction,
// Richardson extrapolation of n = 200 and 400 (the static start's error is
// the static truncation, which falls as 1/n); rest.csv the corrected model at
// n = 400 with 0.625 ms steps (from rest the uncorrected sleeve forces do not
// converge as 1/n: RichardsonDoesNotConvergeTheRestStartsSleeveForces).
struct Tol {
  double y_c, theta, lambda;
};
std::array<double, 6> checkAgainstConverged(const std::string& cs, const Table& ref, InitialState init, int n,
                                            Tol tol) {
  EXPECT_GT(ref.rows.size(), 2900u);
  std::printf("%s vs converged (nRMS)                     y_c      theta    lambda_1 lambda_2 lambda_3 lambda_4\n",
              cs.c_str());
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
  // The accuracy targets: 1 % on y_c and theta, 2 % on lambda_1..4 (measured
  // 6e-4, 7e-4, 2e-4; without the correction theta is 33 % off).
  const auto off = checkAgainstConverged("c1-paper", staticReference(), InitialState::Static, 20, {0.01, 0.01, 0.02});
  EXPECT_GT(off[1], 0.2) << "the uncorrected n = 20 tilt is far off";
}

TEST(StaticCorrection, PeakExcursionIsConvergedAtTwentyModes) {
  // The preload advisor's measure (hoist-study advise, docs/studies.md): the
  // peak cage excursion max |y_c -+ h theta| over the paper's trip from the
  // static start.  Mostly tilt, so the truncation understates it (n = 50 off:
  // 6.5 % low here at 30 kN, measured; in the advisor's 8 mm example 8.0 vs
  // 8.4 mm); with the correction n = 20 has the converged peak (2e-5).
  const Table& ref = staticReference();
  const double h = ShaftParams{}.h;
  auto peak = [&](const std::vector<CageResponse>* run) {
    double m = 0;
    for (const auto& row : ref.rows) {
      double y = row[ref.col("y_c")], th = row[ref.col("theta")];
      if (run) {
        const auto& r = (*run)[static_cast<std::size_t>(std::lround(row[0] / 0.01))];
        y = r.y_c;
        th = r.theta;
      }
      m = std::max({m, std::abs(y - h * th), std::abs(y + h * th)});
    }
    return m;
  };
  const double conv = peak(nullptr);
  const auto on20 = runCase("c1-paper", InitialState::Static, 20, true);
  const auto off50 = runCase("c1-paper", InitialState::Static, 50, false);
  const double p20 = peak(&on20), p50 = peak(&off50);
  std::printf("  peak excursion: converged %.4f mm, n = 20 on %.4f mm, n = 50 off %.4f mm\n", 1e3 * conv, 1e3 * p20,
              1e3 * p50);
  EXPECT_NEAR(p20 / conv, 1.0, 0.002);
  EXPECT_LT(p50 / conv, 0.95) << "the truncation understates the excursion";
}

TEST(StaticCorrection, PaperRestStartMatchesTheConvergedModelInTheModelsBand) {
  // From rest the eccentric load is a step: the cage twists against the
  // ropes' wave impedance in J / (4 h^2 Z) = 6 ms and launches sharp waves;
  // the 16-m rope segments between the sleeves ring (first mode c / 4h =
  // 3.9 Hz) and the rope ends reflect the waves back.  The converged response
  // carries 1.2 % (theta) and 3.2 % (lambda) of its nRMS above the top mode
  // of a 20-mode rope (f_20 = 3.1 Hz), a band no 20-mode model has modes for:
  // the targets' 1 % (theta) / 2 % (lambda) over the whole signal are not
  // attainable at n = 20 (docs/model.md, docs/figures/convergence).  Below
  // f_20 the corrected n = 20 model meets them (measured 0.86 % theta, 0.96 %
  // lambda, 0.14 % y_c); over the whole signal it is held at its measured level (theta
  // 1.8 %, lambda 3.7 %) plus a margin.
  const Table& ref = restReference();
  const double f20 = topModeFrequency(20);
  const BandErrors e = bandErrorsAgainst(runCase("c1-paper-rest", InitialState::Rest, 20, true), ref, f20);
  const BandErrors u = bandErrorsAgainst(runCase("c1-paper-rest", InitialState::Rest, 20, false), ref, f20);
  std::printf("c1-paper-rest vs converged (nRMS), f_20 = %.2f Hz         y_c      theta    lambda_1 lambda_2 lambda_3 lambda_4\n", f20);
  printErrors("n = 20, on: whole signal", e.raw);
  printErrors("n = 20, on: both low-passed at f_20", e.band);
  printErrors("n = 20, off: whole signal", u.raw);
  printErrors("n = 20, off: both low-passed at f_20", u.band);
  printErrors("converged: its content above f_20", e.above);
  EXPECT_GT(f20, 2.5);
  EXPECT_LT(f20, 3.5);
  for (int c = 0; c < 6; ++c) {
    ::testing::Test::RecordProperty(std::string("rest_n20_nrms_") + kLat[c], std::to_string(e.raw[c]));
    ::testing::Test::RecordProperty(std::string("rest_n20_band_nrms_") + kLat[c], std::to_string(e.band[c]));
    // In the model's band: the accuracy targets.
    EXPECT_LE(e.band[c], c < 2 ? 0.01 : 0.02) << kLat[c];
    // Whole signal: the measured level plus a margin.
    EXPECT_LE(e.raw[c], c == 0 ? 0.005 : c == 1 ? 0.022 : 0.042) << kLat[c];
  }
  // What no 20-mode model can reproduce exceeds the accuracy targets ...
  EXPECT_GT(e.above[1], 0.01);
  for (int c = 2; c < 6; ++c) EXPECT_GT(e.above[c], 0.025) << kLat[c];
  // ... and the correction is what brings the tilt into line.
  EXPECT_GT(u.raw[1], 0.2);
  EXPECT_GT(u.band[1], 0.2);
}

TEST(StaticCorrection, PaperRestStartAtFiftyModes) {
  // n = 50 (f_50 = 7.8 Hz) resolves the segments' first mode: theta within
  // 0.4 %; the sleeve forces' content above 8 Hz keeps them 2.8 % off.
  const auto off = checkAgainstConverged("c1-paper-rest", restReference(), InitialState::Rest, 50, {0.005, 0.006, 0.035});
  EXPECT_GT(off[1], 0.05);
}

TEST(StaticCorrection, ConvergedSetting) {
  // docs/model.md "converged setting": the smallest n with theta within 1 %
  // (nRMS over the paper's trip) of the converged model, with the correction,
  // in both of the paper's cases.  From the static start (the daemon's
  // operating state) every n >= 5 is; from rest (a load step) n = 25 is the
  // first (measured 0.97 %; 1.05 % at 24, 0.67 % at 30): the highest mode's
  // half wave L / n reaches the segment between the sleeves, 2h = 16 m.
  const Table& st = staticReference();
  for (int n : {5, 10, 20, 25}) {
    const auto e = errorsAgainst(runCase("c1-paper", InitialState::Static, n, true), st);
    std::printf("  static start, n = %2d: theta %.2e  y_c %.2e  lambda_1 %.2e\n", n, e[1], e[0], e[2]);
    EXPECT_LE(e[1], 0.01) << n;
    EXPECT_LE(e[0], 0.01) << n;
  }
  const Table& rr = restReference();
  std::array<double, 4> th{};
  const std::array<int, 4> ns{20, 24, 25, 30};
  for (std::size_t i = 0; i < ns.size(); ++i) {
    th[i] = errorsAgainst(runCase("c1-paper-rest", InitialState::Rest, ns[i], true), rr)[1];
    std::printf("  rest start,   n = %2d: theta %.2e\n", ns[i], th[i]);
  }
  EXPECT_GT(th[0], 0.01) << "n = 20 from rest (measured 1.84 %)";
  EXPECT_GT(th[1], 0.01) << "n = 24 from rest (measured 1.05 %)";
  EXPECT_LE(th[2], 0.01) << "n = 25 from rest (measured 0.97 %)";
  EXPECT_LE(th[3], 0.008) << "n = 30 from rest (measured 0.67 %)";
}

TEST(StaticCorrection, RichardsonDoesNotConvergeTheRestStartsSleeveForces) {
  // Why rest.csv is not Richardson-extrapolated: from rest the uncorrected
  // model's sleeve forces do not converge as 1/n (the modal rope presents an
  // effective mass of about 2 rho2 L / n at a sleeve instead of the
  // continuum's wave impedance, which the 6-ms twist of the cage feels), so
  // 2 y(2n) - y(n) is worse than y(2n) alone; the tilt's static truncation
  // error does fall as 1/n and the extrapolation helps there.
  const Table& ref = restReference();
  const auto a = runCase("c1-paper-rest", InitialState::Rest, 50, false);
  const auto b = runCase("c1-paper-rest", InitialState::Rest, 100, false);
  std::vector<CageResponse> x = b;
  for (std::size_t k = 0; k < x.size(); ++k) {
    x[k].y_c = 2 * b[k].y_c - a[k].y_c;
    x[k].theta = 2 * b[k].theta - a[k].theta;
    for (int j = 1; j <= 4; ++j) x[k].lambda[j] = 2 * b[k].lambda[j] - a[k].lambda[j];
  }
  const auto e = errorsAgainst(x, ref), e100 = errorsAgainst(b, ref);
  printErrors("off, Richardson(50, 100) vs converged", e);
  printErrors("off, n = 100 alone vs converged", e100);
  EXPECT_LT(e[1], 0.5 * e100[1]) << "theta: the extrapolation removes the 1/n static error";
  for (int c = 2; c < 6; ++c) EXPECT_GT(e[c], 1.3 * e100[c]) << kLat[c] << ": the extrapolation makes lambda worse";
}

TEST(StaticCorrection, RestReferenceIsWhatItsGeneratorSays) {
  // The first 0.3 s of tests/data/c1-converged/rest.csv recomputed with its
  // generator's settings (corrected, n = 400, 0.625 ms steps) agree to
  // round-off: the committed file is this code's converged run.
  const Table& ref = restReference();
  const double T = 0.3;
  const auto run = runCase("c1-paper-rest", InitialState::Rest, 400, true, T, 1.0, 0.000625);
  std::vector<double> a, b;
  for (int c = 0; c < 6; ++c) {
    columns(run, ref, c, a, b, T);
    ASSERT_GE(a.size(), 30u);
    double scale = 0, worst = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      scale = std::max(scale, std::abs(b[i]));
      worst = std::max(worst, std::abs(a[i] - b[i]));
    }
    EXPECT_GT(scale, 0.0) << kLat[c];
    EXPECT_LT(worst, 1e-6 * scale) << kLat[c];
  }
}

TEST(StaticCorrection, DashpotValueAndStepBarelyMatter) {
  // The sleeves' dashpot Z = 2 sqrt(T rho2) (the rope's wave impedance) is
  // an addition to the paper's model: the rest start's errors change by less
  // than 0.2 % of the signal over 0.25 Z .. 2 Z, and halving the step
  // (the dashpot's first-order difference) changes nothing visible.  Without
  // it (Z = 0) the cage rings on the residual springs (docs/model.md).
  const Table& ref = restReference();
  const auto base = errorsAgainst(runCase("c1-paper-rest", InitialState::Rest, 20, true), ref);
  printErrors("n = 20, Z", base);
  for (double z : {0.25, 0.5, 2.0}) {
    const auto e = errorsAgainst(runCase("c1-paper-rest", InitialState::Rest, 20, true, -1, z), ref);
    char label[64];
    std::snprintf(label, sizeof label, "n = 20, %.2f Z", z);
    printErrors(label, e);
    for (int c = 0; c < 6; ++c) EXPECT_NEAR(e[c], base[c], 0.002) << kLat[c] << " at " << z << " Z";
  }
  const auto fine = errorsAgainst(runCase("c1-paper-rest", InitialState::Rest, 20, true, -1, 1.0, 0.00125), ref);
  printErrors("n = 20, Z, 1.25 ms steps", fine);
  for (int c = 0; c < 6; ++c) EXPECT_NEAR(fine[c], base[c], 0.001) << kLat[c];
  const auto none = errorsAgainst(runCase("c1-paper-rest", InitialState::Rest, 20, true, -1, 0.0), ref);
  printErrors("n = 20, no dashpot", none);
  for (int c = 2; c < 6; ++c) EXPECT_GT(none[c], 0.2) << kLat[c] << ": the undamped residual mode";
}

TEST(StaticCorrection, OffHasNoResidualSpringOrDashpot) {
  // --static-correction off is the paper's truncation: R = 0 and Z = 0 at
  // every step, and the dashpot scale has no effect (bit-identical).
  ShaftParams p;
  p.n = 12;
  p.static_correction = false;
  auto model = std::make_shared<const ShaftModel>(p);
  FastSolver a(model), b(model);
  b.setResidualDampingScale(3.0);
  const HoistProfile prof = HoistProfile::trapezoid();
  a.initialize(0.0, prof.at(0.0), InitialState::Rest);
  b.initialize(0.0, prof.at(0.0), InitialState::Rest);
  for (int k = 1; k <= 2000; ++k) {
    const double t = 0.005 * k;
    a.step(t, prof.at(t));
    b.step(t, prof.at(t));
    ASSERT_EQ(a.residualFlexibility().norm(), 0.0);
    ASSERT_EQ(a.residualDamping().norm(), 0.0);
    ASSERT_EQ(b.residualDamping().norm(), 0.0);
    ASSERT_EQ(a.response().theta, b.response().theta) << t;
    for (int j = 1; j <= 4; ++j) ASSERT_EQ(a.response().lambda[j], b.response().lambda[j]) << t;
  }
  EXPECT_THROW(a.setResidualDampingScale(-1.0), std::invalid_argument);
  EXPECT_THROW(a.setResidualDampingScale(std::nan("")), std::invalid_argument);
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
