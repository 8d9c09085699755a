// FastSolver's longitudinal step in either form: see longitudinal_reference.hpp.
#include "longitudinal_reference.hpp"

#include <stdexcept>

namespace hoist::bench {

namespace {
constexpr int kMaxSweeps = 12;  // as FastSolver
}  // namespace

LongitudinalStep::LongitudinalStep(std::shared_ptr<const ShaftModel> model, StepMatrix form)
    : model_(std::move(model)), form_(form), ga_(model_->params().rho_inf) {
  const int n = model_->params().n;
  u_ = model_->hoistingRope().U1;
  k2_ = model_->hoistingRope().k.array().square();
  y_ = yd_ = ydd_ = ya_ = yhat_ = yvhat_ = r0_ = F0_ = Pd_ = w_ = res_ = dy_ = VectorXd::Zero(n);
  S0_ = Ek_ = MatrixXd::Zero(n, n);
  lu_ = Eigen::PartialPivLU<MatrixXd>(n);
}

void LongitudinalStep::start(const FastSolverState& s) {
  if (!s.valid || s.modes() != model_->params().n)
    throw std::invalid_argument("LongitudinalStep::start: no saved state for this n");
  t_ = s.t;
  y_ = s.y;
  yd_ = s.yd;
  ydd_ = s.ydd;
  ya_ = s.ya;
  lambda0_ = s.lambda0;
}

void LongitudinalStep::loads(const Kinematics& k) {
  const ShaftParams& p = model_->params();
  const auto& H = model_->hoistingRope();
  const double Fxc = p.Fa + p.m * (p.g - k.a);
  F0_ = (-p.rho1 * k.l * k.a) * H.intU - (p.m * p.g) * H.U1 + Fxc * u_;
}

void LongitudinalStep::step(double t1, const Kinematics& k1) {
  const ShaftParams& p = model_->params();
  const auto& H = model_->hoistingRope();
  const GeneralizedAlpha& g = ga_;
  const double h = t1 - t_;
  const double hb = h * h * g.beta * g.ca, hg = h * g.gamma * g.ca;
  if (form_ == StepMatrix::Previous)
    Ek_ = (p.rho1 * k1.a) * H.A_acc - (p.u1 * k1.v) * H.A_vel - (p.rho1 * k1.v * k1.v / k1.l) * H.A_cent;
  loads(k1);
  r0_ = (g.alpha_f * ydd_ - g.alpha_m * ya_) / (1.0 - g.alpha_m);  // abar (r0_ reused below)
  yhat_ = y_ + h * yd_ + (h * h * (0.5 - g.beta)) * ya_ + (h * h * g.beta) * r0_;
  yvhat_ = yd_ + (h * (1.0 - g.gamma)) * ya_ + (h * g.gamma) * r0_;
  ya_ = r0_;
  const double cdiag = p.rho1 * k1.v + p.u1 * k1.l;
  const double kscale = p.EA / k1.l;
  r0_ = F0_ - cdiag * yvhat_ - kscale * k2_.cwiseProduct(yhat_);
  const double c4 = p.rho1 * k1.v;
  if (form_ == StepMatrix::Fused) {
    const double c1 = p.rho1 * k1.a, c2 = -p.u1 * k1.v, c3 = -p.rho1 * k1.v * k1.v / k1.l;
    Ek_ = (hb * c1) * H.A_acc + (hb * c2) * H.A_vel + (hb * c3) * H.A_cent + (hg * c4) * H.A_gyro;  // E
    r0_.noalias() -= (1.0 / hb) * (Ek_ * yhat_);
    dy_ = yvhat_ - (hg / hb) * yhat_;
    r0_.noalias() -= c4 * (H.A_gyro * dy_);
  } else {
    r0_.noalias() -= c4 * (H.A_gyro * yvhat_);
    r0_.noalias() -= Ek_ * yhat_;
    Ek_ *= hb;
    Ek_.noalias() += (hg * c4) * H.A_gyro;  // Ek_ now holds E
  }
  Pd_ = (p.rho1 * k1.l + hg * cdiag) + (hb * kscale) * k2_.array();
  w_ = u_.cwiseQuotient(Pd_);
  const double sm = p.m / (1.0 + p.m * u_.dot(w_));  // Sherman-Morrison
  auto applyPinv = [&](const VectorXd& rhs, VectorXd& out) {
    out = rhs.cwiseQuotient(Pd_);
    out -= (sm * u_.dot(out)) * w_;
  };
  applyPinv(r0_, ydd_);
  bool converged = false;
  int it = 0;
  for (; it < kMaxSweeps && !converged; ++it) {
    res_ = r0_ - Pd_.cwiseProduct(ydd_) - (p.m * u_.dot(ydd_)) * u_;
    res_.noalias() -= Ek_ * ydd_;
    applyPinv(res_, dy_);
    ydd_ += dy_;
    converged = dy_.cwiseAbs().maxCoeff() <= 1e-14 * ydd_.cwiseAbs().maxCoeff() + 1e-300;
  }
  last_iters_ = it;
  if (!converged) {
    S0_ = Ek_;
    S0_.noalias() += p.m * (u_ * u_.transpose());
    S0_.diagonal() += Pd_;
    lu_.compute(S0_);
    ydd_.noalias() = lu_.solve(r0_);
  }
  ya_ += g.ca * ydd_;
  y_ = yhat_ + hb * ydd_;
  yd_ = yvhat_ + hg * ydd_;
  t_ = t1;
  lambda0_ = p.Fa + p.m * (p.g - k1.a) - p.m * u_.dot(ydd_);
}

}  // namespace hoist::bench
