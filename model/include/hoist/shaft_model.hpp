// hoist/shaft_model.hpp -- the immutable, precomputed shaft model.
//
// Wang et al. (2016), Eqs. (12)-(17) with the corrections of docs/model.md.
// Assumed modes (Eq. 13), xi = x/l(t), eta = x/L:
//   U0_i(xi)  = sqrt(2) sin(k_i xi),  k_i = (2i-1) pi/2      (hoisting rope)
//   U1_i(eta) = U2_i(eta) = sqrt(2) sin(i pi eta)              (guide ropes)
// The model splits into two subsystems that share only l(t), v, a:
//   longitudinal: q0 (n hoisting-rope modes) + x_c, constraint g0 = u(l) - x_c
//   lateral/torsional: q1, q2 (n modes of each guide rope) + y_c + theta,
//                      constraints g1..g4 (Eq. 8).
// Everything that does not depend on time is computed once here: the mode
// integral matrices (closed form, checked against Gauss-Legendre in tests),
// the guide-rope stiffness (Eq. 17, K block) and its modal decomposition.
#pragma once

#include <Eigen/Dense>
#include <memory>

#include "hoist/params.hpp"

namespace hoist {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// Hoisting-rope mode integrals over xi in [0, 1] (i = row = equation, j = column).
struct HoistingRopeIntegrals {
  VectorXd k;      ///< k_i = (2i-1) pi / 2
  VectorXd U1;     ///< U0_i(1) = sqrt(2) (-1)^(i+1)
  VectorXd intU;   ///< Int U0_i = sqrt(2)/k_i
  MatrixXd A_gyro; ///< Int (1-xi) [U_i U_j' - U_i' U_j]
  MatrixXd A_acc;  ///< Int (1-xi) U_i U_j'
  MatrixXd A_vel;  ///< Int xi U_i U_j'
  MatrixXd A_cent; ///< Int (1-xi)^2 U_i' U_j'
  MatrixXd B_printed; ///< Int xi U_i' U_j (the term of the printed Eq. 17 that docs/model.md deletes)
};

/// The paper's system matrices for one subsystem at one instant (docs/model.md, Eq. 17).
struct HoistingRopeMatrices {
  MatrixXd M, C, K;
  VectorXd F;
};

class ShaftModel {
 public:
  /// Validates `p` (throws ParamError) and precomputes everything.
  explicit ShaftModel(const ShaftParams& p);

  const ShaftParams& params() const { return p_; }
  int n() const { return p_.n; }

  // ---- assumed modes (Eq. 13) ------------------------------------------
  /// U_i(eta) for the guide ropes, i = 1..n, into `out` (size n).
  void guideModes(double eta, Eigen::Ref<VectorXd> out) const;
  /// dU_i/deta.
  void guideModeSlopes(double eta, Eigen::Ref<VectorXd> out) const;
  /// d2U_i/deta2.
  void guideModeCurvatures(double eta, Eigen::Ref<VectorXd> out) const;

  // ---- constant matrices -------------------------------------------------
  const HoistingRopeIntegrals& hoistingRope() const { return hr_; }
  /// Guide rope r (1 or 2) stiffness K_ij = (1/L) Int T_r(eta) U_i' U_j' deta.
  const MatrixXd& guideStiffness(int r) const { return r == 1 ? K1_ : K2_; }
  /// Modal decomposition of each guide rope: K_r = V_r diag(kappa_r) V_r^T, V orthogonal.
  const MatrixXd& guideModalVectors(int r) const { return r == 1 ? V1_ : V2_; }
  const VectorXd& guideModalStiffness(int r) const { return r == 1 ? kappa1_ : kappa2_; }

  /// Hoisting-rope block of Eq. (17) at (l, v, a) as corrected in docs/model.md
  /// (`printed = true`: the printed, transposed form with its spurious term,
  /// kept only to measure the difference).  F includes the cage-free rope
  /// terms: F_i = -rho1 l a sqrt(2)/k_i - sqrt(2) (-1)^(i+1) m g (+ excitation terms: none).
  void hoistingRopeMatrices(double l, double v, double a, HoistingRopeMatrices& out,
                            bool printed = false) const;

  /// Static tension of guide rope r at depth x: T_br + rho2 g (L - x).
  double guideTension(int r, double x) const;

  /// Static hoisting-rope force lambda_0 at rope length l [N]: the value of
  /// lambda_0 (the force of the cage on the rope at g0 = u(l) - x_c, +x
  /// down) in static equilibrium (v = a = 0), the reference of the
  /// ROPE_SLACK / ROPE_OVERLOAD alarms.
  ///
  /// Derivation (MODEL.md, Eq. 15): the cage's longitudinal equation is
  /// m x_c'' = Fa + m (g - a) - lambda_0 (the cage feels -lambda_0; the
  /// eccentric load Fa acts on x_c as a weight).  At rest x_c'' = a = 0, so
  /// lambda_0 = m g + Fa, whatever the rope's modes do (they only set x_c).
  /// The rope's own weight rho1 g l does not pass through g0: u is measured
  /// about the gravity-loaded state, and the rope above the cage carries its
  /// weight itself (the sheave sees m g + Fa + rho1 g l; lambda_0 is the
  /// force at the cage end).  So in this model the static force does not
  /// depend on l; the argument keeps the API right for models where it does
  /// (a tail rope, a cage-mounted rope weight).  Checked against the solver's
  /// static start for both methods, every l and several shafts
  /// (tests/model/static_test.cpp, Static.RopeForceEqualsTheStaticSolve).
  double staticRopeForce(double l) const;

  // ---- exact statics of a guide rope (static correction) ------------------
  /// S_r(x) = Int_0^x ds / T_r(s) = ln(T_r(0)/T_r(x)) / (rho2 g)  (x / T_br if g = 0).
  double guideFlexibilityIntegral(int r, double x) const;
  /// Exact static Green's function of guide rope r, the lateral deflection at x
  /// under a unit point load at s of  -(T_r y')' = delta(x - s), y(0) = y(L) = 0:
  ///   G_r(x, s) = S_r(min) (S_r(L) - S_r(max)) / S_r(L)   [m/N].
  double guideGreen(int r, double x, double s) const;
  /// S_r(L), precomputed.
  double guideFlexibilityTotal(int r) const { return r == 1 ? SL1_ : SL2_; }

 private:
  ShaftParams p_;
  HoistingRopeIntegrals hr_;
  MatrixXd K1_, K2_, V1_, V2_;
  VectorXd kappa1_, kappa2_;
  double SL1_ = 0.0, SL2_ = 0.0;
};

}  // namespace hoist
