// Assumed modes (Eq. 13) and the constant matrices of Eq. (17):
// closed forms (used by the model) against composite Gauss-Legendre
// quadrature of the defining integrals, plus two analytic checks of the
// guide-rope discretization (taut-string frequencies, point-load deflection).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "hoist/shaft_model.hpp"
#include "test_util.hpp"

using namespace hoist;
using hoist::test::integrate;
constexpr double kPi = std::numbers::pi;

namespace {

double U0(int i, double xi) { return std::sqrt(2.0) * std::sin((2.0 * i - 1) * kPi / 2 * xi); }
double dU0(int i, double xi) {
  const double k = (2.0 * i - 1) * kPi / 2;
  return std::sqrt(2.0) * k * std::cos(k * xi);
}

class HoistingRopeIntegrals : public ::testing::TestWithParam<int> {};

TEST_P(HoistingRopeIntegrals, ClosedFormsMatchQuadrature) {
  ShaftParams p;
  p.n = GetParam();
  const ShaftModel model(p);
  const auto& H = model.hoistingRope();
  const int panels = 2 * p.n + 4;
  double worst = 0;
  for (int i = 1; i <= p.n; ++i) {
    EXPECT_NEAR(H.intU(i - 1), integrate([&](double x) { return U0(i, x); }, 0, 1, panels), 1e-12);
    EXPECT_NEAR(H.U1(i - 1), U0(i, 1.0), 1e-12);
    for (int j = 1; j <= p.n; ++j) {
      const double scale = ((2.0 * i - 1) * (2.0 * j - 1) + 1.0) * 3;  // integrals grow like k_i k_j
      auto q = [&](auto f) { return integrate(f, 0.0, 1.0, panels); };
      const double acc = q([&](double x) { return (1 - x) * U0(i, x) * dU0(j, x); });
      const double gyro = q([&](double x) { return (1 - x) * (U0(i, x) * dU0(j, x) - dU0(i, x) * U0(j, x)); });
      const double vel = q([&](double x) { return x * U0(i, x) * dU0(j, x); });
      const double cent = q([&](double x) { return (1 - x) * (1 - x) * dU0(i, x) * dU0(j, x); });
      const double pr = q([&](double x) { return x * dU0(i, x) * U0(j, x); });
      const double mass = q([&](double x) { return U0(i, x) * U0(j, x); });
      const double stiff = q([&](double x) { return dU0(i, x) * dU0(j, x); });
      worst = std::max({worst, std::abs(H.A_acc(i - 1, j - 1) - acc) / scale,
                        std::abs(H.A_gyro(i - 1, j - 1) - gyro) / scale, std::abs(H.A_vel(i - 1, j - 1) - vel) / scale,
                        std::abs(H.A_cent(i - 1, j - 1) - cent) / scale,
                        std::abs(H.B_printed(i - 1, j - 1) - pr) / scale});
      // docs/model.md closed forms: Int U_i U_j = delta_ij, Int U_i' U_j' = k_i^2 delta_ij.
      EXPECT_NEAR(mass, i == j ? 1.0 : 0.0, 1e-11);
      const double k = (2.0 * i - 1) * kPi / 2;
      EXPECT_NEAR(stiff, i == j ? k * k : 0.0, 1e-9 * k * k);
    }
  }
  EXPECT_LT(worst, 1e-11);
  // The gyroscopic matrix is skew-symmetric.
  EXPECT_LT((H.A_gyro + H.A_gyro.transpose()).cwiseAbs().maxCoeff(), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Modes, HoistingRopeIntegrals, ::testing::Values(3, 10, 50));

class GuideRopeStiffness : public ::testing::TestWithParam<int> {};

TEST_P(GuideRopeStiffness, ClosedFormMatchesQuadratureOfTensionWeightedIntegral) {
  ShaftParams p;
  p.n = GetParam();
  p.Tb1 = 27000;
  p.Tb2 = 33000;
  const ShaftModel model(p);
  const int panels = 2 * p.n + 4;
  for (int r = 1; r <= 2; ++r) {
    const double Tb = r == 1 ? p.Tb1 : p.Tb2;
    const auto& K = model.guideStiffness(r);
    for (int i = 1; i <= p.n; i += (p.n > 10 ? 7 : 1)) {
      for (int j = 1; j <= p.n; ++j) {
        const double q = integrate(
            [&](double eta) {
              const double T = Tb + p.rho2 * p.g * p.L * (1 - eta);
              return T * 2 * i * j * kPi * kPi * std::cos(i * kPi * eta) * std::cos(j * kPi * eta);
            },
            0, 1, panels) / p.L;
        EXPECT_NEAR(K(i - 1, j - 1), q, 1e-10 * K(i - 1, i - 1)) << "rope " << r << " i=" << i << " j=" << j;
      }
    }
    // Modal decomposition reproduces K.
    const auto& V = model.guideModalVectors(r);
    const MatrixXd Kr = V * model.guideModalStiffness(r).asDiagonal() * V.transpose();
    EXPECT_LT((Kr - K).cwiseAbs().maxCoeff(), 1e-9 * K.cwiseAbs().maxCoeff());
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, GuideRopeStiffness, ::testing::Values(2, 10, 50));

TEST(GuideRope, TautStringNaturalFrequencies) {
  // rho2 g -> 0: uniform tension T = Tb, f_k = k/(2L) sqrt(T/rho2).
  for (double g : {0.0, 1e-7}) {
    ShaftParams p;
    p.n = 30;
    p.g = g;
    const ShaftModel model(p);
    VectorXd kappa = model.guideModalStiffness(1);
    std::sort(kappa.data(), kappa.data() + kappa.size());
    for (int k = 1; k <= p.n; ++k) {
      const double f = std::sqrt(kappa(k - 1) / (p.rho2 * p.L)) / (2 * kPi);
      const double f_exact = k / (2 * p.L) * std::sqrt(p.Tb1 / p.rho2);
      EXPECT_NEAR(f / f_exact, 1.0, g == 0 ? 1e-12 : 1e-6) << "mode " << k;
    }
  }
}

TEST(GuideRope, WeightRaisesFrequenciesTowardsMeanTension) {
  // With gravity the tension grows upward; the fundamental must lie between the
  // taut-string values for the bottom and top tensions.
  ShaftParams p;
  p.n = 40;
  const ShaftModel model(p);
  const double kmin = model.guideModalStiffness(1).minCoeff();
  const double f1 = std::sqrt(kmin / (p.rho2 * p.L)) / (2 * kPi);
  const double fb = 1 / (2 * p.L) * std::sqrt(p.Tb1 / p.rho2);
  const double ft = 1 / (2 * p.L) * std::sqrt((p.Tb1 + p.rho2 * p.g * p.L) / p.rho2);
  EXPECT_GT(f1, fb);
  EXPECT_LT(f1, ft);
}

TEST(GuideRope, StaticPointLoadDeflectionConvergesInModes) {
  // Taut string (g = 0), unit point load F at depth a: y(a) = F a (L - a) / (T L).
  const double F = 100.0, a = 123.0;
  double prev_err = 1e300;
  for (int n : {10, 50, 200}) {
    ShaftParams p;
    p.n = n;
    p.g = 0.0;
    const ShaftModel model(p);
    VectorXd U(n);
    model.guideModes(a / p.L, U);
    const VectorXd q = model.guideStiffness(1).ldlt().solve(U * F);
    const double y = U.dot(q);
    const double exact = F * a * (p.L - a) / (p.Tb1 * p.L);
    const double err = std::abs(y - exact) / exact;
    RecordProperty("point_load_rel_err_n" + std::to_string(n), std::to_string(err));
    EXPECT_LT(err, prev_err) << "n = " << n;
    prev_err = err;
  }
  EXPECT_LT(prev_err, 5e-3);  // ~ 1/n: 2.4e-3 at n = 200
}

TEST(GuideRope, ModeRecurrenceMatchesDirectSines) {
  ShaftParams p;
  p.n = 1000;
  const ShaftModel model(p);
  VectorXd U(p.n);
  for (double eta : {1e-6, 0.125, 0.5, 0.96, 1.0 - 1e-6}) {
    model.guideModes(eta, U);
    for (int i = 1; i <= p.n; ++i)
      ASSERT_NEAR(U(i - 1), std::sqrt(2.0) * std::sin(i * kPi * eta), 1e-11) << eta << " " << i;
  }
}

TEST(HoistingRope, PrintedBlockDiffersFromCorrectedOnlyInTransposedAndSpuriousTerms) {
  ShaftParams p;
  p.n = 20;
  const ShaftModel model(p);
  HoistingRopeMatrices c, pr;
  model.hoistingRopeMatrices(120.0, 5.0, 0.7, c, false);
  model.hoistingRopeMatrices(120.0, 5.0, 0.7, pr, true);
  EXPECT_EQ((c.M - pr.M).norm(), 0.0);
  EXPECT_LT((c.F - pr.F).norm(), 1e-12);
  // C-bar printed is the transpose of the corrected C.
  EXPECT_LT((c.C - pr.C.transpose()).cwiseAbs().maxCoeff(), 1e-9);
  // K differs by the transposition and the deleted rho1 v^2/l Int xi U_i' U_j term.
  const auto& H = model.hoistingRope();
  const MatrixXd spurious = (p.rho1 * 25.0 / 120.0) * H.B_printed;
  EXPECT_LT((pr.K.transpose() - spurious.transpose() - c.K).cwiseAbs().maxCoeff(), 1e-6);
  // ... and the difference is tiny against the elastic stiffness (docs/model.md).
  EXPECT_LT((pr.K - c.K).norm() / c.K.norm(), 1e-4);
  EXPECT_GT((pr.K - c.K).norm(), 0.0);
}

}  // namespace
