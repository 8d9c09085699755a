// bench/longitudinal_reference.hpp -- FastSolver's longitudinal step
// (hoisting rope + cage, docs/model.md) on its own, with the step matrix
//   E = hg rho1 v A_gyro + hb Ek(l, v, a)
// built in either of two forms:
//   Fused     E in one pass from the four constant matrices, Ek never
//             formed -- what FastSolver::step does;
//   Previous  Ek built, applied to yhat, scaled and added to: the form
//             FastSolver had before, kept here (not in the model) so that
//             the benchmark can set the two side by side and a test can show
//             that they agree (bench/longitudinal_reference_test.cpp).
// It starts from a FastSolver's saved state (FastSolverState) and steps the
// longitudinal subsystem only (Forcing::Full), with FastSolver's
// fixed-point solve and dense-LU fallback.  No allocation in step().
#pragma once

#include <memory>

#include "hoist/fast_solver.hpp"

namespace hoist::bench {

enum class StepMatrix { Fused, Previous };

class LongitudinalStep {
 public:
  LongitudinalStep(std::shared_ptr<const ShaftModel> model, StepMatrix form);
  /// Continue from `s` (its t, kinematics and hoisting-rope coordinates).
  void start(const FastSolverState& s);
  void step(double t1, const Kinematics& k1);
  double t() const { return t_; }
  double x_c() const { return u_.dot(y_); }          ///< cage longitudinal displacement [m]
  double lambda0() const { return lambda0_; }        ///< hoisting-rope force on the cage [N]
  int lastIterations() const { return last_iters_; }

 private:
  void loads(const Kinematics& k);  // F0_ at k

  std::shared_ptr<const ShaftModel> model_;
  StepMatrix form_;
  GeneralizedAlpha ga_;
  double t_ = 0.0;
  VectorXd u_, k2_;                   // U0_i(1), k_i^2
  VectorXd y_, yd_, ydd_, ya_;        // q0: state, rate, acceleration, pseudo-acceleration
  VectorXd yhat_, yvhat_, r0_, F0_, Pd_, w_, res_, dy_;
  MatrixXd S0_, Ek_;
  Eigen::PartialPivLU<MatrixXd> lu_;
  double lambda0_ = 0.0;
  int last_iters_ = 0;
};

}  // namespace hoist::bench
