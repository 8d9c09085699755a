// The exact (n -> inf) static solution of the continuous lateral problem, the
// reference of the static and dynamic tests.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "hoist/params.hpp"

namespace hoist::test {

/// Exact static solution of the continuous model (strings with tension
/// T_r(x) = Tb_r + rho2 g (L - x), rigid cage on four sleeves).  Green's
/// function of -(T y')' = delta(x - s), y(0) = y(L) = 0:
///   y(x) = phi(min) (phi(L) - phi(max)) / phi(L),  phi(x) = Int_0^x ds / T(s).
struct ExactStatic {
  double y_c, theta;
  double lambda[4];
};

inline ExactStatic exactStatic(const ShaftParams& p, double l) {
  auto phi = [&](double Tb, double x) {
    if (p.g == 0.0) return x / Tb;
    const double rg = p.rho2 * p.g;
    return std::log((Tb + rg * p.L) / (Tb + rg * (p.L - x))) / rg;
  };
  auto green = [&](double Tb, double x, double s) {
    const double lo = std::min(x, s), hi = std::max(x, s);
    return phi(Tb, lo) * (phi(Tb, p.L) - phi(Tb, hi)) / phi(Tb, p.L);
  };
  const double xt = l, xb = l + 2 * p.h;
  // unknowns: lambda1..4, y_c, theta
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  // g1: y1(l) + h th - y_c = 0, rope 1 carries lambda1 at l, lambda4 at l+2h.
  A(0, 0) = green(p.Tb1, xt, xt);
  A(0, 3) = green(p.Tb1, xt, xb);
  A(0, 4) = -1;
  A(0, 5) = p.h;
  // g2: y2(l) + h th - y_c, rope 2 carries lambda2 at l, lambda3 at l+2h.
  A(1, 1) = green(p.Tb2, xt, xt);
  A(1, 2) = green(p.Tb2, xt, xb);
  A(1, 4) = -1;
  A(1, 5) = p.h;
  // g3: y2(l+2h) - h th - y_c
  A(2, 1) = green(p.Tb2, xb, xt);
  A(2, 2) = green(p.Tb2, xb, xb);
  A(2, 4) = -1;
  A(2, 5) = -p.h;
  // g4: y1(l+2h) - h th - y_c
  A(3, 0) = green(p.Tb1, xb, xt);
  A(3, 3) = green(p.Tb1, xb, xb);
  A(3, 4) = -1;
  A(3, 5) = -p.h;
  // cage: sum lambda = 0 (no lateral load); Fa b + h(l1 + l2) - h(l3 + l4) = 0
  A(4, 0) = A(4, 1) = A(4, 2) = A(4, 3) = 1;
  A(5, 0) = A(5, 1) = p.h;
  A(5, 2) = A(5, 3) = -p.h;
  rhs(5) = -p.Fa * p.b;
  const Eigen::Matrix<double, 6, 1> s = A.fullPivLu().solve(rhs);
  return {s(4), s(5), {s(0), s(1), s(2), s(3)}};
}

}  // namespace hoist::test
