// hoist/fast_solver.hpp -- the production path ("fast").
//
// Solves Eq. (15) in multiplier form, exploiting the structure of docs/model.md:
//
// Longitudinal (hoisting rope q0 + x_c, constraint g0 = U0(1).q0 - x_c = 0):
//   the constraint row is constant, so x_c = u.q0 (u = U0(1)) is eliminated
//   exactly with the constant, perfectly conditioned basis [I; u^T]:
//     (rho1 l I + m u u^T) q0'' + C(l,v) q0' + K(l,v,a) q0 = F0 + u (Fa + m(g - a))
//   and lambda_0 = Fa + m(g - a) - m x_c''  (the cage equation).
//   C and K change with l, v, a.  The step matrix S = P + E splits into
//   P = diagonal + m u u^T (inverted exactly by Sherman-Morrison, O(n)) and
//   the small velocity/acceleration-dependent part E (spectral radius of
//   P^-1 E is ~1e-3 for hoist speeds up to 15 m/s), so S x = r is solved by
//   preconditioned fixed-point iteration to round-off in a few O(n^2) sweeps;
//   a dense LU (preallocated) is the fallback if it ever fails to converge.
//
// Lateral/torsional (q1, q2, y_c, theta; constraints g1..g4, Eq. 8):
//   M, C, K are constant.  Each guide rope's stiffness is diagonalized once,
//   K_r = V_r diag(kappa_r) V_r^T (M_r = rho2 L I, C_r = u2 L I stay diagonal),
//   so in modal coordinates z_r = V_r^T q_r the integrator matrix is diagonal
//   and the KKT system
//     [S  -G^T] [qdd]   [r]
//     [G   0  ] [lam] = [d]
//   is solved by a 4 x 4 Schur complement W = G S^-1 G^T.  The constraints are
//   enforced at position level at every step (no drift), which stays accurate
//   over the whole shaft 0 < l < L - 2h where the paper's partition G0 is
//   ill-conditioned.  Cost per step O(n^2) (the rows G = V^T U(l/L)).
//
// No heap allocation in step() (verified by a test with EIGEN_RUNTIME_NO_MALLOC
// and a counting global operator new).
#pragma once

#include "hoist/integrator.hpp"
#include "hoist/solver.hpp"

namespace hoist {

/// Everything FastSolver needs to continue integrating bit-identically from
/// one instant (the forecast's copy of the twin).  It IS the solver's state:
/// FastSolver keeps its own in one FastSolverState, so saving and restoring
/// are plain assignments and a new state field cannot be forgotten in either.  Vectors are sized once by
/// FastSolverState(n) (or the first saveState()); saving into and restoring
/// from a state of the same n allocates nothing, and so does copying one
/// state into another of the same n (Eigen assignment keeps the buffers).
/// Constant model data (M, C, K, the modal bases) is not part of it: a state
/// restores into any FastSolver built on a model with the same parameters.
struct FastSolverState {
  double t = 0.0;        ///< model time [s]
  Kinematics kin;        ///< l, v, a at t
  // lateral/torsional, modal coordinates (2n + 2): z_1, z_2, y_c, theta
  VectorXd x, xd, xdd, xa;   ///< state, rate, acceleration, pseudo-acceleration
  Eigen::Vector4d lam = Eigen::Vector4d::Zero();  ///< lambda_1..4 [N]
  // static correction (zero without it): residual flexibility, step
  // compliance, wave impedance at the sleeves, residual displacement and the
  // spring part of lambda at the last step
  Eigen::Matrix4d R = Eigen::Matrix4d::Zero(), Rc = Eigen::Matrix4d::Zero();
  Eigen::Vector4d Zd = Eigen::Vector4d::Zero(), delta = Eigen::Vector4d::Zero(), lamS = Eigen::Vector4d::Zero();
  // longitudinal: hoisting-rope modal coordinates (n)
  VectorXd y, yd, ydd, ya;   ///< state, rate, acceleration, pseudo-acceleration
  double lambda0 = 0.0;      ///< lambda_0 [N]
  // the eccentric load the state was integrated under (FastSolver::setLoad)
  double Fa = 0.0;           ///< force on x_c [N]
  double moment = 0.0;       ///< moment Fa b on theta [N m]
  int last_iters = 0;        ///< diagnostics carried along
  long fallbacks = 0;
  CageResponse response;     ///< the response at t
  bool valid = false;        ///< set by saveState()

  FastSolverState() = default;
  /// Sized for n modes per rope (2n + 2 lateral, n longitudinal), zeroed.
  explicit FastSolverState(int n);
  int modes() const { return static_cast<int>(y.size()); }
};

/// The same trajectory under another eccentric load, by superposition.
///
/// For given kinematics the model is linear in its loads, and the load enters
/// only as Fa on x_c (longitudinal) and as the moment M = Fa b on theta
/// (lateral).  So if `unit` was saved from a FastSolver with Forcing::LoadOnly
/// (load (unit.Fa, unit.moment), usually 1 N and 1 N m) that started as `s`'s
/// solver did and took the same steps, then
///   s_longitudinal += (dFa / unit.Fa) unit_longitudinal,
///   s_lateral      += (dM / unit.moment) unit_lateral
/// is, to round-off, the state `s`'s solver would have reached under the load
/// (s.Fa + dFa, s.moment + dM); s.Fa and s.moment are updated, so restoring
/// `s` continues under the new load.  The geometric terms (R, Rc, Zd) and the
/// kinematics are kept.  This is how a forecast starts from the load
/// estimator's state (hoist/load_estimator.hpp).  Allocation-free.  Returns
/// false, leaving `s` unchanged, unless both are valid, have the same n and
/// the same time (within 1e-9 s), and unit's loads are nonzero.
bool addLoadResponse(FastSolverState& s, const FastSolverState& unit, double dFa, double dM);

/// What drives the solver.  The model is linear in its loads for given
/// kinematics, so the response to the eccentric load alone is the exact
/// derivative of every output with respect to Fa (longitudinal subsystem) and
/// to the moment Fa b (lateral subsystem): the load estimator's sensitivities.
enum class Forcing {
  Full,      ///< Eq. (17): gravity, the rope's and cage's inertia and the eccentric load
  LoadOnly,  ///< only the eccentric load: F(x_c) = Fa, F(theta) = Fa b; lambda_0 = Fa - m x_c''
};

class FastSolver final : public Solver {
 public:
  explicit FastSolver(std::shared_ptr<const ShaftModel> model, Forcing forcing = Forcing::Full);
  Forcing forcing() const { return forcing_; }

  void initialize(double t0, const Kinematics& k0, InitialState init) override;
  using Solver::initialize;
  void step(double t1, const Kinematics& k1) override;
  const CageResponse& response() const override { return s_.response; }
  void guideRopeCoordinates(VectorXd& q1, VectorXd& q2) const override;
  void residualSleeveLoads(SleeveLoads& out) const override;
  bool finite() const override;
  Method method() const override { return Method::Fast; }

  /// The eccentric load: Fa on x_c [N] and the moment M = Fa b on theta
  /// [N m].  Starts as the model's (params Fa and Fa b); setLoad overrides it
  /// from the next step() on (a forecast from the load estimator's state).
  /// initialize() does not reset it.  saveState/restoreState carry it.
  void setLoad(double Fa, double moment);
  double loadForce() const { return s_.Fa; }
  double loadMoment() const { return s_.moment; }

  // ---- snapshot (look-ahead forecasts) -------------------------------------
  /// Copies the integration state into `s` (no allocation when s was sized
  /// for this n).  Restoring it later and stepping with the same inputs gives
  /// bit-identical results.
  void saveState(FastSolverState& s) const;
  /// Continues from `s` (throws std::invalid_argument if it is not valid or
  /// was saved with another n; allocates nothing).
  void restoreState(const FastSolverState& s);

  // ---- state access (tests, energy checks) --------------------------------
  /// Lateral state in physical coordinates [q1; q2; y_c; theta] and its rate.
  void lateralState(VectorXd& q, VectorXd& qd) const;
  /// Fixed-point sweeps used by the last longitudinal solve, and how many
  /// solves fell back to the dense LU since initialize().
  int lastLongitudinalIterations() const { return s_.last_iters; }
  long longitudinalFallbacks() const { return s_.fallbacks; }
  /// Longitudinal state: hoisting-rope modal coordinates q0 and rates.
  const VectorXd& hoistingRopeCoordinates() const { return s_.y; }
  const VectorXd& hoistingRopeRates() const { return s_.yd; }
  /// Static correction active, and the sleeves' residual flexibility R(l) at
  /// the current position (zero without the correction) [m/N].
  bool staticCorrection() const { return corr_; }
  const Eigen::Matrix4d& residualFlexibility() const { return s_.R; }
  /// The high modes' wave impedance at each sleeve, 2 sqrt(T rho2) [N s/m],
  /// and the spring (quasi-static) part of the sleeve forces, R^-1 (-G q).
  const Eigen::Vector4d& residualDamping() const { return s_.Zd; }
  const Eigen::Vector4d& residualSpringForces() const { return s_.lamS; }
  /// Scales the sleeves' dashpot Z (default 1; 0 removes it, leaving the
  /// residual springs alone).  A sensitivity knob for tests and studies
  /// (docs/model.md: the response is insensitive to 0.25 Z .. 2 Z); takes
  /// effect from the next step; no effect without the static correction.
  void setResidualDampingScale(double s);
  double residualDampingScale() const { return zscale_; }

 private:
  void fillConstraintRows(double l);                 // G_ (4 x N) at l
  void fillConstraintRowDerivatives(double l);       // Gl_, Gll_ (init only)
  void fillResidualFlexibility(double l);            // s_.R at l (after fillConstraintRows)
  // KKT solve  S qdd - G^T lam = r,  G qdd + c R lam = d  (c = 0: rigid sleeves).
  void solveLateral(const VectorXd& Sd, const VectorXd& r, const Eigen::Vector4d& d, double c);
  void longitudinalOperators(const Kinematics& k);  // Ek_ and F0_ at k (initialize(); step() builds E fused)
  void longitudinalLoads(const Kinematics& k);      // F0_ at k
  void updateResponse(double t, const Kinematics& k);

  /// The whole integration state (time, kinematics, lateral and longitudinal
  /// coordinates, multipliers, the static correction's sleeve terms, the
  /// response): saveState()/restoreState() are plain assignments of it.
  /// Everything else below is constant model data or per-step workspace.
  FastSolverState s_;
  GeneralizedAlpha ga_;
  /// Velocities at t0 consistent with the constraints when v(t0) != 0 (see .cpp).
  void consistentInitialVelocity(double v);
  int n_ = 0, N_ = 0;  // modes per rope; lateral size 2n + 2
  double h_cached_ = -1.0;

  // lateral constants (modal coordinates), state and workspace
  VectorXd Md_, Cd_, Kd_, F_;        // diagonal M, C, K and load
  VectorXd Sd_;                       // M + h gamma ca C + h^2 beta ca K (diagonal)
  // Constraint Jacobian stored transposed (N x 4, contiguous columns g1..g4)
  // and its l-derivatives (used for consistent initial accelerations).
  Eigen::Matrix<double, Eigen::Dynamic, 4> Gt_, Glt_, Gllt_;
  Eigen::Matrix<double, Eigen::Dynamic, 4> Y_;  // S^-1 G^T
  VectorXd sa_, sb_, xhat_, vhat_, r_, tmp_;
  bool corr_ = false;                 // static correction
  double zscale_ = 1.0;                           // setResidualDampingScale
  VectorXd kinv_;                     // 1 / kappa (rope entries)
  mutable VectorXd zs_;               // guideRopeCoordinates workspace (2n)

  // longitudinal
  VectorXd u_;                        // U0_i(1)
  MatrixXd S0_, Ek_;                  // step matrix, velocity/accel-dependent stiffness
  Eigen::PartialPivLU<MatrixXd> lu_;
  VectorXd yhat_, yvhat_, r0_, F0_;
  VectorXd k2_, Pd_, w_, res_, dy_;  // k_i^2, diagonal of P, P^-1 u, residual, update
  Forcing forcing_ = Forcing::Full;

  // initialize() workspace, sized in the constructor so that re-initializing
  // (a new winder stream, recovery from a model fault) allocates nothing.
  MatrixXd initA_;                          // static KKT matrix (N + 4)^2
  Eigen::PartialPivLU<MatrixXd> initLu_;    // its factorization
  VectorXd initRhs_, initSol_;              // (N + 4)
  Eigen::Matrix<double, Eigen::Dynamic, 4> D_, MG_;  // dependent-coordinate directions; M^-1 G^T
  MatrixXd initM_, initC_, initK_;          // longitudinal n x n
  Eigen::PartialPivLU<MatrixXd> initLuN_;
  VectorXd initRhsN_;
};

}  // namespace hoist
