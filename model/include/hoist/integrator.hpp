// hoist/integrator.hpp -- generalized-alpha coefficients (Chung & Hulbert 1993,
// in the form of Arnold & Bruls 2007 used for constrained systems).
//
// With step h, true accelerations qdd and pseudo-accelerations a:
//   (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) qdd_{n+1} + alpha_f qdd_n
//   q_{n+1}  = q_n + h qd_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}
//   qd_{n+1} = qd_n + h (1 - gamma) a_n + h gamma a_{n+1}
// and the equations of motion (and constraints) hold exactly at t_{n+1}.
// rho_inf = 1 gives alpha_m = alpha_f = 1/2, beta = 1/4, gamma = 1/2: the
// trapezoidal rule (Newmark average acceleration), second order, no numerical
// damping; rho_inf < 1 damps the highest frequencies (still second order).
#pragma once

namespace hoist {

struct GeneralizedAlpha {
  double alpha_m, alpha_f, beta, gamma;
  /// a_{n+1} = ca * qdd_{n+1} + abar, with abar = (alpha_f qdd_n - alpha_m a_n)/(1 - alpha_m).
  double ca;

  explicit GeneralizedAlpha(double rho_inf) {
    alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
    alpha_f = rho_inf / (rho_inf + 1.0);
    gamma = 0.5 - alpha_m + alpha_f;
    const double t = 1.0 - alpha_m + alpha_f;
    beta = 0.25 * t * t;
    ca = (1.0 - alpha_f) / (1.0 - alpha_m);
  }
};

}  // namespace hoist
