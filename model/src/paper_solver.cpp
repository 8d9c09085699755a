#include "hoist/paper_solver.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hoist {

PaperSolver::PaperSolver(std::shared_ptr<const ShaftModel> model)
    : Solver(std::move(model)), ga_(model_->params().rho_inf) {
  n_ = model_->n();
  if (n_ < 2) throw std::invalid_argument("the paper's method needs model.modes >= 2");
  if (model_->params().static_correction)
    throw std::invalid_argument(
        "the paper's method has no static correction: set model.static_correction = false "
        "(--static-correction off) with --method paper");
  nq_ = 3 * n_ + 3;
  n1_ = 3 * n_ - 2;
  // Block order p: [q0_1..q0_n, q1_1..q1_n, q2_1..q2_n, x_c, y_c, theta].
  // Paper order q (Eq. 15): q0_1, q1_1, q1_2, q2_1, q2_2, q0_2, then for
  // k = 3..n: q0_k, q1_k, q2_k, then x_c, y_c, theta.
  const int n = n_;
  auto P0 = [](int k) { return k - 1; };
  auto P1 = [n](int k) { return n + k - 1; };
  auto P2 = [n](int k) { return 2 * n + k - 1; };
  std::vector<int> order = {P0(1), P1(1), P1(2), P2(1), P2(2), P0(2)};
  for (int k = 3; k <= n; ++k) {
    order.push_back(P0(k));
    order.push_back(P1(k));
    order.push_back(P2(k));
  }
  order.push_back(3 * n);
  order.push_back(3 * n + 1);
  order.push_back(3 * n + 2);
  q_of_p_.assign(nq_, -1);
  for (int qi = 0; qi < nq_; ++qi) q_of_p_[order[qi]] = qi;
  z_ = zd_ = zdd_ = za_ = VectorXd::Zero(n1_);
  q_ = qd_ = qdd_ = VectorXd::Zero(nq_);
  lam_.setZero();
}

void PaperSolver::assemble(const Kinematics& k, PaperSystem& s) const {
  const ShaftParams& p = model_->params();
  const int n = n_, nq = nq_;
  // ---- Eq. (17) in block order, then permuted: M = T_r M-bar T_r^T ----------
  HoistingRopeMatrices hr;
  model_->hoistingRopeMatrices(k.l, k.v, k.a, hr);
  MatrixXd Mb = MatrixXd::Zero(nq, nq), Cb = MatrixXd::Zero(nq, nq), Kb = MatrixXd::Zero(nq, nq);
  VectorXd Fb = VectorXd::Zero(nq);
  Mb.topLeftCorner(n, n) = hr.M;
  Cb.topLeftCorner(n, n) = hr.C;
  Kb.topLeftCorner(n, n) = hr.K;
  Fb.head(n) = hr.F;
  for (int r = 1; r <= 2; ++r) {
    Mb.block(r * n, r * n, n, n) = MatrixXd::Identity(n, n) * (p.rho2 * p.L);
    Cb.block(r * n, r * n, n, n) = MatrixXd::Identity(n, n) * (p.u2 * p.L);
    Kb.block(r * n, r * n, n, n) = model_->guideStiffness(r);
  }
  Mb(3 * n, 3 * n) = p.m;
  Mb(3 * n + 1, 3 * n + 1) = p.m;
  Mb(3 * n + 2, 3 * n + 2) = p.J;
  Fb(3 * n) = p.Fa + p.m * (p.g - k.a);
  Fb(3 * n + 2) = p.Fa * p.b;
  s.M.setZero(nq, nq);
  s.C.setZero(nq, nq);
  s.K.setZero(nq, nq);
  s.F.setZero(nq);
  for (int a = 0; a < nq; ++a) {
    s.F(q_of_p_[a]) = Fb(a);
    for (int b = 0; b < nq; ++b) {
      s.M(q_of_p_[a], q_of_p_[b]) = Mb(a, b);
      s.C(q_of_p_[a], q_of_p_[b]) = Cb(a, b);
      s.K(q_of_p_[a], q_of_p_[b]) = Kb(a, b);
    }
  }
  // ---- G(l) (Eqs. 6, 8) and d/dl, d2/dl2 -------------------------------------
  s.G.setZero(5, nq);
  s.Gl.setZero(5, nq);
  s.Gll.setZero(5, nq);
  const auto& H = model_->hoistingRope();
  for (int i = 1; i <= n; ++i) s.G(0, q_of_p_[i - 1]) = H.U1(i - 1);
  s.G(0, q_of_p_[3 * n]) = -1.0;
  VectorXd Ua(n), Ub(n), dUa(n), dUb(n), ddUa(n), ddUb(n);
  const double ea = k.l / p.L, eb = (k.l + 2 * p.h) / p.L;
  model_->guideModes(ea, Ua);
  model_->guideModes(eb, Ub);
  model_->guideModeSlopes(ea, dUa);
  model_->guideModeSlopes(eb, dUb);
  model_->guideModeCurvatures(ea, ddUa);
  model_->guideModeCurvatures(eb, ddUb);
  // rows: g1 rope 1 top, g2 rope 2 top, g3 rope 2 bottom, g4 rope 1 bottom
  const int rope[4] = {1, 2, 2, 1};
  const bool top[4] = {true, true, false, false};
  for (int row = 1; row <= 4; ++row) {
    const int r = rope[row - 1];
    const bool t = top[row - 1];
    for (int i = 1; i <= n; ++i) {
      const int col = q_of_p_[r * n + i - 1];
      s.G(row, col) = t ? Ua(i - 1) : Ub(i - 1);
      s.Gl(row, col) = (t ? dUa(i - 1) : dUb(i - 1)) / p.L;
      s.Gll(row, col) = (t ? ddUa(i - 1) : ddUb(i - 1)) / (p.L * p.L);
    }
    s.G(row, q_of_p_[3 * n + 1]) = -1.0;
    s.G(row, q_of_p_[3 * n + 2]) = t ? p.h : -p.h;
  }
  // ---- Eqs. (19)-(20) and the l-derivatives of Phi (docs/model.md) ------------------
  s.G0 = s.G.leftCols(5);
  const Eigen::PartialPivLU<Eigen::Matrix<double, 5, 5>> G0lu(s.G0);
  const int n1 = n1_;
  s.Phi.setZero(nq, n1);
  s.Phi.topRows(5) = -G0lu.solve(s.G.rightCols(n1));
  s.Phi.bottomRows(n1).setIdentity();
  s.Phil.setZero(nq, n1);
  s.Phil.topRows(5) = -G0lu.solve(s.Gl * s.Phi);
  s.Phill.setZero(nq, n1);
  s.Phill.topRows(5) = -G0lu.solve(s.Gll * s.Phi + 2.0 * s.Gl * s.Phil);
  // ---- Eq. (23) -------------------------------------------------------------------
  const MatrixXd Phid = k.v * s.Phil;
  const MatrixXd Phidd = k.a * s.Phil + k.v * k.v * s.Phill;
  const MatrixXd MPhi = s.M * s.Phi;
  s.MG = s.Phi.transpose() * MPhi;
  s.CG = 2.0 * s.Phi.transpose() * (s.M * Phid) + s.Phi.transpose() * (s.C * s.Phi);
  s.KG = s.Phi.transpose() * (s.M * Phidd) + s.Phi.transpose() * (s.C * Phid) + s.Phi.transpose() * (s.K * s.Phi);
  s.FG = s.Phi.transpose() * s.F;
}

double PaperSolver::conditionG0(double l) const {
  PaperSystem s;
  assemble({l, 0.0, 0.0}, s);
  Eigen::JacobiSVD<Eigen::Matrix<double, 5, 5>> svd(s.G0);
  return svd.singularValues()(0) / svd.singularValues()(4);
}

void PaperSolver::recover(const Kinematics& k) {
  // Eq. (24) and its time derivatives (Eq. 21, corrected first part).
  const MatrixXd Phid = k.v * sys_.Phil;
  const MatrixXd Phidd = k.a * sys_.Phil + k.v * k.v * sys_.Phill;
  q_ = sys_.Phi * z_;
  qd_ = sys_.Phi * zd_ + Phid * z_;
  qdd_ = sys_.Phi * zdd_ + 2.0 * Phid * zd_ + Phidd * z_;
  // lambda from the first five rows of Eq. (15): G0^T lambda = [M q'' + C q' + K q - F]_{q0}.
  const VectorXd res = sys_.M * qdd_ + sys_.C * qd_ + sys_.K * q_ - sys_.F;
  lam_ = sys_.G0.transpose().partialPivLu().solve(res.head(5));
  const int n = n_;
  resp_.kin = k;
  resp_.x_c = q_(q_of_p_[3 * n]);
  resp_.y_c = q_(q_of_p_[3 * n + 1]);
  resp_.theta = q_(q_of_p_[3 * n + 2]);
  for (int i = 0; i < 5; ++i) resp_.lambda[i] = lam_(i);
}

void PaperSolver::initialize(double t0, const Kinematics& k0, InitialState init) {
  const ShaftParams& p = model_->params();
  if (!(k0.l > 0.0 && k0.l < p.maxRopeLength()))
    throw std::domain_error("initial rope length " + std::to_string(k0.l) + " m outside (0, L - 2h)");
  t_ = t0;
  zd_.setZero();
  if (init == InitialState::Static) {
    assemble({k0.l, 0.0, 0.0}, sys_);
    z_ = sys_.KG.partialPivLu().solve(sys_.FG);  // K_G q1 = F_G at v = a = 0
  } else {
    z_.setZero();
  }
  assemble(k0, sys_);
  zdd_ = sys_.MG.partialPivLu().solve(sys_.FG - sys_.CG * zd_ - sys_.KG * z_);
  za_ = zdd_;
  resp_.t = t0;
  recover(k0);
}

void PaperSolver::step(double t1, const Kinematics& k1) {
  const ShaftParams& p = model_->params();
  const double h = t1 - t_;
  if (!(h > 0.0) || !std::isfinite(h)) throw std::invalid_argument("step: t1 must be after the current time");
  if (!(k1.l > 0.0 && k1.l < p.maxRopeLength()))
    throw std::domain_error("step: rope length outside (0, L - 2h)");
  const GeneralizedAlpha& g = ga_;
  const double hb = h * h * g.beta * g.ca, hg = h * g.gamma * g.ca;
  assemble(k1, sys_);
  const VectorXd abar = (g.alpha_f * zdd_ - g.alpha_m * za_) / (1.0 - g.alpha_m);
  const VectorXd zhat = z_ + h * zd_ + (h * h * (0.5 - g.beta)) * za_ + (h * h * g.beta) * abar;
  const VectorXd vhat = zd_ + (h * (1.0 - g.gamma)) * za_ + (h * g.gamma) * abar;
  const MatrixXd S = sys_.MG + hg * sys_.CG + hb * sys_.KG;
  zdd_ = S.partialPivLu().solve(sys_.FG - sys_.CG * vhat - sys_.KG * zhat);
  za_ = abar + g.ca * zdd_;
  z_ = zhat + hb * zdd_;
  zd_ = vhat + hg * zdd_;
  t_ = t1;
  resp_.t = t1;
  recover(k1);
}

void PaperSolver::guideRopeCoordinates(VectorXd& q1, VectorXd& q2) const {
  q1.resize(n_);
  q2.resize(n_);
  for (int i = 0; i < n_; ++i) {
    q1(i) = q_(q_of_p_[n_ + i]);
    q2(i) = q_(q_of_p_[2 * n_ + i]);
  }
}

bool PaperSolver::finite() const {
  return z_.allFinite() && zd_.allFinite() && zdd_.allFinite() && q_.allFinite() && lam_.allFinite();
}

}  // namespace hoist
