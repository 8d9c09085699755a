// hoist/solver.hpp -- time stepping of the constrained system, Eq. (15):
//
//   M q'' + C q' + K q = F + G(l)^T lambda,     G(l) q = 0.
//
// Two interchangeable methods (same inputs, same outputs):
//   * FastSolver  (the production path, fast_solver.hpp): both subsystems solved
//     in multiplier (KKT) form with the position-level constraints enforced at
//     every step -- accurate over the whole shaft 0 < l < L - 2h.
//   * PaperSolver (the verification path, paper_solver.hpp): the paper's literal
//     coordinate partition G = (G0 G1), q = Phi q1 (Eqs. 18-24), reduced ODE
//     Eq. (22), lambda recovered from Eq. (15).  Ill-conditioned near the shaft
//     ends (docs/model.md) and O(n^3) per step: for checking, not for production.
// Both use the same implicit, fixed-step generalized-alpha integrator with the
// equations of motion enforced at t_{n+1}; its high-frequency damping is
// ShaftParams::rho_inf ([model] rho_inf, default 0.9; rho_inf = 1 would be the
// undamped trapezoidal rule / Newmark average acceleration, which lets the
// sleeve forces of the moving index-3 constraints grow without bound).
//
// Frame (the one every part of the project uses; docs/model.md "Frame"):
//   x      depth, origin at the top of the shaft (head sheave / derrick, where
//          both guide ropes are fixed), positive DOWNWARD.  The hoisting rope
//          occupies [0, l]; the cage's top sleeves are at x = l, its bottom
//          sleeves at x = l + 2h; the guide ropes span [0, L].  v = dl/dt > 0
//          when the cage descends, a = dv/dt.  x_c: cage displacement along
//          +x about the static (gravity-loaded) state.
//   y      the one lateral direction of the model (paper Fig. 1b).  Guide
//          rope 1 stands on one side of the cage and rope 2 on the other, and
//          y_1, y_2 and y_c are all measured along the SAME +y: each sleeve
//          makes its rope move with the cage there (g1..g4 below), so the
//          linear model does not depend on which side a rope stands.
//   theta  cage rotation in the x-y plane, positive when it turns the cage's
//          downward axis toward +y: the bottom sleeves move by +h theta, the
//          top sleeves by -h theta.  The eccentric load's moment +Fa b drives
//          +theta (b > 0 tilts the cage bottom toward +y).
// Constraints (Eqs. 6, 8, linearized; lambda_k goes with g_k):
//   g0 = u(l) - x_c                 hoisting rope / cage
//   g1 = y1(l)    + h theta - y_c   top sleeve, rope 1
//   g2 = y2(l)    + h theta - y_c   top sleeve, rope 2
//   g3 = y2(l+2h) - h theta - y_c   bottom sleeve, rope 2
//   g4 = y1(l+2h) - h theta - y_c   bottom sleeve, rope 1
// lambda_k is the force the cage exerts on the rope at constraint g_k,
// positive in +y (+x for lambda_0); the cage feels -lambda_k.  Cage lateral
// displacement at the top sleeves is y_c - h theta, at the bottom sleeves
// y_c + h theta.
// The largest guide-rope deflection over the shaft, from any solver's state:
// hoist/guide_rope_envelope.hpp.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "hoist/profile.hpp"
#include "hoist/shaft_model.hpp"

namespace hoist {

/// What both solvers report after every step.
struct CageResponse {
  double t = 0.0;
  Kinematics kin;        ///< l, v, a the step ended at
  double x_c = 0.0;      ///< cage longitudinal displacement (+ down) [m]
  double y_c = 0.0;      ///< cage lateral displacement [m]
  double theta = 0.0;    ///< cage rotation [rad]
  std::array<double, 5> lambda{};  ///< lambda_0 (hoisting rope) .. lambda_4 (sleeves) [N]
  // Rates of the cage coordinates at t (what a cage IMU sees; hoist/load_estimator.hpp).
  // Filled by FastSolver; the paper path leaves them 0.
  double x_c_ddot = 0.0;    ///< cage longitudinal acceleration about the static state [m/s^2]
  double y_c_ddot = 0.0;    ///< cage lateral acceleration [m/s^2]
  double theta_dot = 0.0;   ///< tilt rate [rad/s]
};

/// Point loads whose exact static deflection (the Green's function of each
/// guide rope, ShaftModel::guideGreen) is part of the guide-rope shape: with
/// the static correction the shape is
///   y_r(x) = U(x/L) . q_r + sum_{k: rope_k = r} G_r(x, x_k) f_k
/// (q_r from guideRopeCoordinates); without it there are none (count = 0).
struct SleeveLoads {
  int count = 0;
  std::array<int, 4> rope{};    ///< 1 or 2
  std::array<double, 4> x{};    ///< depth of the load [m]
  std::array<double, 4> f{};    ///< force on the rope, +y [N]
};

enum class Method { Fast, Paper };
const char* toString(Method m);

class Solver {
 public:
  virtual ~Solver() = default;

  /// Set the state at t0 (static equilibrium or rest, see InitialState) and
  /// compute consistent accelerations and multipliers for kinematics k0.
  virtual void initialize(double t0, const Kinematics& k0, InitialState init) = 0;
  void initialize(double t0, const Kinematics& k0) { initialize(t0, k0, model().params().initial); }

  /// Advance to t1 > t, where the prescribed motion is k1.  The fast path does
  /// not allocate.  Throws std::domain_error if k1.l leaves (0, L - 2h).
  virtual void step(double t1, const Kinematics& k1) = 0;

  virtual const CageResponse& response() const = 0;

  /// Lateral displacement of both guide ropes at depths x (same size outputs):
  /// the modal part (guideRopeCoordinates) plus the exact static deflection
  /// under residualSleeveLoads, as SleeveLoads states.  One implementation
  /// for every solver.
  void guideRopeShapes(const VectorXd& x, VectorXd& y1, VectorXd& y2) const;

  /// Guide-rope modal coordinates in the sine basis of Eq. (13) (q_1,i and q_2,i):
  /// the modal part of the shape (see SleeveLoads for the rest).
  virtual void guideRopeCoordinates(VectorXd& q1, VectorXd& q2) const = 0;

  /// The point loads that complete the shape (static correction); none by default.
  virtual void residualSleeveLoads(SleeveLoads& out) const { out.count = 0; }

  /// All state values finite.
  virtual bool finite() const = 0;

  virtual Method method() const = 0;
  const ShaftModel& model() const { return *model_; }
  const std::shared_ptr<const ShaftModel>& modelPtr() const { return model_; }

 protected:
  explicit Solver(std::shared_ptr<const ShaftModel> model) : model_(std::move(model)) {}
  std::shared_ptr<const ShaftModel> model_;
};

/// Factory: the solver for `method` on `model`.
std::unique_ptr<Solver> makeSolver(Method method, std::shared_ptr<const ShaftModel> model);

}  // namespace hoist
