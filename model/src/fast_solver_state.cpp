// FastSolver's state between steps (hoist/fast_solver.hpp): the snapshot
// (FastSolverState, saveState, restoreState), the load it integrates under
// (setLoad) and the superposition of a load change (addLoadResponse), and
// the read-outs of its coordinates (guide-rope coordinates, residual sleeve
// loads, lateral state, finite).  Called between steps by the forecast, the
// load estimator, the shapes and the envelope, once the solver and the
// caller's buffers have their size (saveState and the read-outs do not
// allocate).  The stepping itself is fast_solver.cpp.
#include <cmath>
#include <stdexcept>

#include "hoist/fast_solver.hpp"

namespace hoist {

FastSolverState::FastSolverState(int n) {
  if (n < 1) throw std::invalid_argument("FastSolverState: n must be >= 1");
  const int N = 2 * n + 2;
  x = xd = xdd = xa = VectorXd::Zero(N);
  y = yd = ydd = ya = VectorXd::Zero(n);
}

void FastSolver::saveState(FastSolverState& s) const {
  s = s_;  // same n: Eigen assigns into the existing buffers (no allocation)
  s.valid = true;
}

void FastSolver::restoreState(const FastSolverState& s) {
  if (!s.valid) throw std::invalid_argument("FastSolver::restoreState: the state was never saved");
  if (s.modes() != n_ || s.x.size() != N_)
    throw std::invalid_argument("FastSolver::restoreState: state saved with another number of modes");
  s_ = s;
  F_(N_ - 1) = s_.moment;  // the load the state was integrated under (setLoad)
  // Sd_ depends on the step size only: recomputing it gives the same bits.
  // Gt_ (the sleeve rows at l) is read between steps by the shapes and the
  // envelope (the static correction's residual term), so rebuild it at the
  // restored l; Y_ and Ek_ are rebuilt by every step before use.
  h_cached_ = -1.0;
  fillConstraintRows(s_.kin.l);
}

void FastSolver::setLoad(double Fa, double moment) {
  s_.Fa = Fa;
  s_.moment = moment;
  F_(N_ - 1) = moment;
}

bool addLoadResponse(FastSolverState& s, const FastSolverState& unit, double dFa, double dM) {
  if (!s.valid || !unit.valid || s.modes() != unit.modes() || s.x.size() != unit.x.size()) return false;
  if (!(std::abs(s.t - unit.t) <= 1e-9) || unit.Fa == 0.0 || unit.moment == 0.0) return false;
  if (!std::isfinite(dFa) || !std::isfinite(dM)) return false;
  const double cl = dFa / unit.Fa;     // longitudinal subsystem: driven by Fa only
  const double cm = dM / unit.moment;  // lateral/torsional: driven by M only
  s.x += cm * unit.x;
  s.xd += cm * unit.xd;
  s.xdd += cm * unit.xdd;
  s.xa += cm * unit.xa;
  s.lam += cm * unit.lam;
  s.delta += cm * unit.delta;
  s.lamS += cm * unit.lamS;
  s.y += cl * unit.y;
  s.yd += cl * unit.yd;
  s.ydd += cl * unit.ydd;
  s.ya += cl * unit.ya;
  s.lambda0 += cl * unit.lambda0;
  s.Fa += dFa;
  s.moment += dM;
  CageResponse& r = s.response;
  const CageResponse& u = unit.response;
  r.x_c += cl * u.x_c;
  r.x_c_ddot += cl * u.x_c_ddot;
  r.lambda[0] += cl * u.lambda[0];
  r.y_c += cm * u.y_c;
  r.theta += cm * u.theta;
  r.y_c_ddot += cm * u.y_c_ddot;
  r.theta_dot += cm * u.theta_dot;
  for (int i = 1; i < 5; ++i) r.lambda[i] += cm * u.lambda[i];
  return true;
}

// With the static correction the shape is y = U.(V z) + sum R(x, a_k) lam_k,
// R(x, a) = G(x, a) - U(x)^T K^-1 U(a): the modal part is shifted by
// -K^-1 sum U(a_k) lam_k (in modal coordinates -kappa^-1 .* G^T lam) and the
// exact Green's function of the sleeve loads is added (residualSleeveLoads).
// At the sleeves this is exactly G q + R lam, i.e. the cage position.
void FastSolver::guideRopeCoordinates(VectorXd& q1, VectorXd& q2) const {
  q1.resize(n_);
  q2.resize(n_);
  if (corr_) {
    // tmp: modal coordinates shifted by the modal part of the sleeve loads
    VectorXd& z = zs_;  // preallocated workspace (keeps GuideRopeEnvelope::evaluate allocation-free)
    z = s_.x.head(2 * n_);
    for (int k = 0; k < 4; ++k) z -= s_.lamS(k) * kinv_.cwiseProduct(Gt_.col(k).head(2 * n_));
    q1.noalias() = model_->guideModalVectors(1) * z.head(n_);
    q2.noalias() = model_->guideModalVectors(2) * z.segment(n_, n_);
    return;
  }
  q1.noalias() = model_->guideModalVectors(1) * s_.x.head(n_);
  q2.noalias() = model_->guideModalVectors(2) * s_.x.segment(n_, n_);
}

void FastSolver::residualSleeveLoads(SleeveLoads& out) const {
  if (!corr_) {
    out.count = 0;
    return;
  }
  const double l = s_.kin.l, b = l + 2.0 * model_->params().h;
  out.count = 4;
  out.rope = {1, 2, 2, 1};  // g1..g4
  out.x = {l, l, b, b};
  // The quasi-static (spring) part of the sleeve forces deflects the high modes.
  out.f = {s_.lamS(0), s_.lamS(1), s_.lamS(2), s_.lamS(3)};
}

void FastSolver::lateralState(VectorXd& q, VectorXd& qd) const {
  q.resize(N_);
  qd.resize(N_);
  const MatrixXd& V1 = model_->guideModalVectors(1);
  const MatrixXd& V2 = model_->guideModalVectors(2);
  q.head(n_) = V1 * s_.x.head(n_);
  q.segment(n_, n_) = V2 * s_.x.segment(n_, n_);
  q.tail(2) = s_.x.tail(2);
  qd.head(n_) = V1 * s_.xd.head(n_);
  qd.segment(n_, n_) = V2 * s_.xd.segment(n_, n_);
  qd.tail(2) = s_.xd.tail(2);
}

bool FastSolver::finite() const {
  return s_.x.allFinite() && s_.xd.allFinite() && s_.xdd.allFinite() && s_.y.allFinite() && s_.yd.allFinite() &&
         s_.ydd.allFinite() && std::isfinite(s_.lambda0) && s_.lam.allFinite();
}

}  // namespace hoist
