// hoist/paper_solver.hpp -- the paper's method, literally (verification path).
//
// Wang et al. (2016), Section 2.2, with docs/model.md's corrected hoisting-rope
// block of Eq. (17):
//   * generalized coordinates in the paper's order (Eq. 15)
//       q = (q0_1, q1_1, q1_2, q2_1, q2_2, q0_2, q0_3, q1_3, q2_3, ...,
//            q0_n, q1_n, q2_n, x_c, y_c, theta)
//     obtained from the block order p = (q0, q1, q2, x_c, y_c, theta) by the
//     permutation T_r of Eq. (16);
//   * the constraint Jacobian G(l) (Eqs. 6, 8), partitioned G = (G0 G1) with
//     q0 = the first five coordinates (Eq. 19);
//   * Phi = [-G0^-1 G1; I] (Eq. 20), Phi-dot = v Phi', Phi-ddot = a Phi' + v^2 Phi''
//     with Phi' = [-G0^-1 G' Phi; 0], Phi'' = [-G0^-1 (G'' Phi + 2 G' Phi'); 0]
//     (' = d/dl, docs/model.md);
//   * the reduced ODE  M_G q1'' + C_G q1' + K_G q1 = F_G  (Eqs. 22-23),
//     integrated with the same generalized-alpha scheme as the fast path;
//   * q assembled by Eq. (24) and lambda recovered from Eq. (15):
//       lambda = G0^-T [M q'' + C q' + K q - F]_{first five rows}.
// O(n^3) per step and ill-conditioned near both shaft ends (cond G0 grows as
// sin(pi l/L) or sin(pi (l+2h)/L) -> 0): for checking the fast path only.
#pragma once

#include <Eigen/Dense>

#include "hoist/integrator.hpp"
#include "hoist/solver.hpp"

namespace hoist {

/// The paper's matrices at one instant, in the paper's coordinate order.
struct PaperSystem {
  MatrixXd M, C, K;  ///< (3n+3) x (3n+3), Eq. (17) permuted by T_r
  VectorXd F;        ///< Eq. (17): F = T_r F-bar
  MatrixXd G, Gl, Gll;  ///< 5 x (3n+3) Jacobian (Eqs. 6, 8) and its l-derivatives
  MatrixXd Phi, Phil, Phill;  ///< Eq. (20) and its l-derivatives
  MatrixXd MG, CG, KG;  ///< Eq. (23)
  VectorXd FG;
  Eigen::Matrix<double, 5, 5> G0;  ///< Eq. (19)
};

class PaperSolver final : public Solver {
 public:
  /// Requires n >= 2 (G0 takes modes 1 and 2 of each guide rope).
  explicit PaperSolver(std::shared_ptr<const ShaftModel> model);

  void initialize(double t0, const Kinematics& k0, InitialState init) override;
  using Solver::initialize;
  void step(double t1, const Kinematics& k1) override;
  const CageResponse& response() const override { return resp_; }
  void guideRopeCoordinates(VectorXd& q1, VectorXd& q2) const override;
  bool finite() const override;
  Method method() const override { return Method::Paper; }

  /// Eqs. (15)-(23) at kinematics k: every matrix of the paper's method.
  void assemble(const Kinematics& k, PaperSystem& s) const;
  /// Index in the paper's q of block coordinate p (Eq. 16: q = T_r p).
  int qIndexOfP(int p) const { return q_of_p_[p]; }
  /// Full q (paper order) of the current state.
  const VectorXd& q() const { return q_; }
  /// Condition number (2-norm) of G0 at rope length l.
  double conditionG0(double l) const;

 private:
  void recover(const Kinematics& k);  // q, q', q'', lambda from q1 state
  GeneralizedAlpha ga_;
  int n_ = 0, nq_ = 0, n1_ = 0;  // modes, 3n+3, 3n-2
  std::vector<int> q_of_p_;
  double t_ = 0.0;
  PaperSystem sys_;
  VectorXd z_, zd_, zdd_, za_;  // q1 and its rate, acceleration, pseudo-acceleration
  VectorXd q_, qd_, qdd_;
  Eigen::Matrix<double, 5, 1> lam_;
  CageResponse resp_;
};

}  // namespace hoist
