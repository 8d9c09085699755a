#include "hoist/shaft_model.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "modes_detail.hpp"

namespace hoist {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kSqrt2 = std::numbers::sqrt2;
}  // namespace

ShaftModel::ShaftModel(const ShaftParams& p) : p_(p) {
  p_.validate();
  const int n = p_.n;

  // ---- hoisting rope (xi in [0,1]) -------------------------------------
  hr_.k.resize(n);
  hr_.U1.resize(n);
  hr_.intU.resize(n);
  for (int i = 0; i < n; ++i) {
    hr_.k(i) = (2.0 * (i + 1) - 1.0) * kPi / 2.0;
    hr_.U1(i) = (i % 2 == 0) ? kSqrt2 : -kSqrt2;  // sqrt(2) (-1)^(i+1), i 1-based
    hr_.intU(i) = kSqrt2 / hr_.k(i);               // sqrt(2)(1 - cos k_i)/k_i, cos k_i = 0
  }
  const double w1mx[3] = {1.0, -1.0, 0.0};   // (1 - xi)
  const double wx[3] = {0.0, 1.0, 0.0};      // xi
  const double w1mx2[3] = {1.0, -2.0, 1.0};  // (1 - xi)^2
  hr_.A_gyro.resize(n, n);
  hr_.A_acc.resize(n, n);
  hr_.A_vel.resize(n, n);
  hr_.A_cent.resize(n, n);
  hr_.B_printed.resize(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double ki = hr_.k(i), kj = hr_.k(j);
      // Each integrand is written out as 2 sin(a) cos(b) etc.; the factor 2
      // of sqrt(2)^2 is absorbed by the product-to-sum identities.
      hr_.A_acc(i, j) = detail::intUdU(w1mx, ki, kj);
      hr_.A_gyro(i, j) = detail::intUdU(w1mx, ki, kj) - detail::intdUU(w1mx, ki, kj);
      hr_.A_vel(i, j) = detail::intUdU(wx, ki, kj);
      hr_.A_cent(i, j) = detail::intdUdU(w1mx2, ki, kj);
      hr_.B_printed(i, j) = detail::intdUU(wx, ki, kj);
    }
  }

  // ---- guide ropes: K_ij = (1/L) Int T(eta) U_i' U_j' deta, closed form ----
  auto guideK = [&](double Tb) {
    MatrixXd K = MatrixXd::Zero(n, n);
    const double rg = p_.rho2 * p_.g;
    for (int a = 1; a <= n; ++a) {
      for (int b = 1; b <= n; ++b) {
        if (a == b) {
          K(a - 1, b - 1) = a * a * kPi * kPi * (Tb + rg * p_.L / 2.0) / p_.L;
        } else if ((a + b) % 2 == 1) {
          const double d = a - b, s = a + b;
          K(a - 1, b - 1) = 2.0 * rg * a * b * (1.0 / (d * d) + 1.0 / (s * s));
        }
      }
    }
    return K;
  };
  K1_ = guideK(p_.Tb1);
  K2_ = guideK(p_.Tb2);
  auto decompose = [n](const MatrixXd& K, MatrixXd& V, VectorXd& kappa) {
    Eigen::SelfAdjointEigenSolver<MatrixXd> es(K);
    if (es.info() != Eigen::Success) throw std::runtime_error("guide-rope stiffness eigen-decomposition failed");
    V = es.eigenvectors();
    kappa = es.eigenvalues();
    if (kappa.minCoeff() <= 0.0) throw std::runtime_error("guide-rope stiffness is not positive definite");
    (void)n;
  };
  decompose(K1_, V1_, kappa1_);
  decompose(K2_, V2_, kappa2_);
  SL1_ = guideFlexibilityIntegral(1, p_.L);
  SL2_ = guideFlexibilityIntegral(2, p_.L);
}

double ShaftModel::guideFlexibilityIntegral(int r, double x) const {
  const double Tb = r == 1 ? p_.Tb1 : p_.Tb2;
  const double rg = p_.rho2 * p_.g;
  if (rg == 0.0) return x / Tb;
  // ln(T(0)/T(x)) with T(0)/T(x) = 1 + rg x / T(x): log1p keeps full accuracy near x = 0.
  return std::log1p(rg * x / (Tb + rg * (p_.L - x))) / rg;
}

double ShaftModel::guideGreen(int r, double x, double s) const {
  const double lo = std::min(x, s), hi = std::max(x, s);
  const double SL = r == 1 ? SL1_ : SL2_;
  return guideFlexibilityIntegral(r, lo) * (SL - guideFlexibilityIntegral(r, hi)) / SL;
}

void ShaftModel::guideModes(double eta, Eigen::Ref<VectorXd> out) const {
  // Rotation recurrence: (cos i t, sin i t) -> (cos (i+1) t, sin (i+1) t); error O(n eps).
  const double t = kPi * eta, c = std::cos(t), s = std::sin(t);
  double ci = c, si = s;
  for (int i = 0; i < p_.n; ++i) {
    out(i) = kSqrt2 * si;
    const double cn = ci * c - si * s;
    si = si * c + ci * s;
    ci = cn;
  }
}

void ShaftModel::guideModeSlopes(double eta, Eigen::Ref<VectorXd> out) const {
  for (int i = 0; i < p_.n; ++i) {
    const double w = (i + 1) * kPi;
    out(i) = kSqrt2 * w * std::cos(w * eta);
  }
}

void ShaftModel::guideModeCurvatures(double eta, Eigen::Ref<VectorXd> out) const {
  for (int i = 0; i < p_.n; ++i) {
    const double w = (i + 1) * kPi;
    out(i) = -kSqrt2 * w * w * std::sin(w * eta);
  }
}

double ShaftModel::staticRopeForce(double l) const {
  (void)l;  // independent of l in this model: see shaft_model.hpp
  return p_.m * p_.g + p_.Fa;
}

double ShaftModel::guideTension(int r, double x) const {
  return (r == 1 ? p_.Tb1 : p_.Tb2) + p_.rho2 * p_.g * (p_.L - x);
}

void ShaftModel::hoistingRopeMatrices(double l, double v, double a, HoistingRopeMatrices& out,
                                      bool printed) const {
  const int n = p_.n;
  const auto& H = hr_;
  const double rho1 = p_.rho1;
  out.M = MatrixXd::Identity(n, n) * (rho1 * l);
  out.C = MatrixXd::Identity(n, n) * (rho1 * v + p_.u1 * l);
  out.K = ((p_.EA / l) * H.k.array().square()).matrix().asDiagonal();
  if (!printed) {
    // docs/model.md (corrected): i = equation row, j = coordinate column.
    out.C += rho1 * v * H.A_gyro;
    out.K += rho1 * a * H.A_acc - p_.u1 * v * H.A_vel - (rho1 * v * v / l) * H.A_cent;
  } else {
    // As printed in Eq. (17): transposed, plus the spurious + rho1 v^2/l Int xi U_i' U_j.
    out.C -= rho1 * v * H.A_gyro;  // Int (1-xi)[U_i' U_j - U_i U_j'] = -A_gyro
    out.K += rho1 * a * H.A_acc.transpose() - p_.u1 * v * H.A_vel.transpose() +
             (rho1 * v * v / l) * (H.B_printed - H.A_cent);
  }
  // F_i = -rho1 l a Int U_i - m g U_i(1) (the rope-weight and v^2 terms cancel).
  out.F = -rho1 * l * a * H.intU - p_.m * p_.g * H.U1;
}

}  // namespace hoist
