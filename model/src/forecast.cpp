#include "hoist/forecast.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hoist {

void ForecastOptions::validate() const {
  if (!std::isfinite(horizon) || !(horizon > 0.0)) throw std::invalid_argument("horizon: must be a finite number > 0");
  if (!std::isfinite(dt) || !(dt > 0.0)) throw std::invalid_argument("dt: must be a finite number > 0");
  if (!std::isfinite(max_step) || !(max_step >= 0.0)) throw std::invalid_argument("max_step: must be >= 0");
  if (horizon / dt > 1e7) throw std::invalid_argument("horizon: more than 1e7 output steps");
  if (max_step > 0.0 && dt / max_step > 1e5) throw std::invalid_argument("max_step: more than 1e5 substeps per step");
  if (envelope_points < 2) throw std::invalid_argument("envelope_points: must be >= 2");
  if (series_points < 1 || series_points > ForecastSummary::kMaxSeries)
    throw std::invalid_argument("series_points: must lie in 1..64");
  if (modes < 0 || modes > kMaxModes) throw std::invalid_argument("modes: must lie in 0..1000 (0: the model's n)");
  if (!std::isfinite(envelope_tolerance) || !(envelope_tolerance >= 0.0))
    throw std::invalid_argument("envelope_tolerance: must be a finite number >= 0");
  limits.validate();
}

const char* toString(ForecastStatus s) {
  switch (s) {
    case ForecastStatus::Ok: return "ok";
    case ForecastStatus::LeftShaft: return "left_shaft";
    case ForecastStatus::NonFinite: return "non_finite";
  }
  return "?";
}

namespace {

std::shared_ptr<const ShaftModel> forecastModel(const std::shared_ptr<const ShaftModel>& model, const ForecastOptions& o) {
  if (!model) throw std::invalid_argument("ForecastWorkspace: no model");
  o.validate();
  if (o.modes > model->n())
    throw std::invalid_argument("modes: " + std::to_string(o.modes) + " is more than the model's " +
                                std::to_string(model->n()) + " modes per rope");
  if (o.modes == 0 || o.modes == model->n()) return model;
  ShaftParams p = model->params();
  p.n = o.modes;
  return std::make_shared<const ShaftModel>(p);
}

}  // namespace

ForecastOptions economicalForecast(const ForecastOptions& exact, int model_modes, int modes) {
  ForecastOptions o = exact;
  o.dt = 0.01;
  o.max_step = 0.0;
  o.modes = std::max(1, std::min(model_modes, modes));
  o.envelope_points = std::min(101, exact.envelope_points);
  o.envelope_tolerance = 1e-4;
  return o;
}

ForecastWorkspace::ForecastWorkspace(std::shared_ptr<const ShaftModel> model, const ForecastOptions& opt)
    : opt_(opt),
      n_start_(model ? model->n() : 0),
      solver_(forecastModel(model, opt)),
      envelope_(solver_.model(), opt.envelope_points) {
  reduced_ = solver_.model().n() != n_start_;
  if (reduced_) {
    full_ = std::make_unique<FastSolver>(model);
    ref_ = FastSolverState(n_start_);
    red_ = FastSolverState(solver_.model().n());
    projected_ = FastSolverState(solver_.model().n());
    last_start_ = FastSolverState(n_start_);  // valid = false: nothing projected yet
    dev_ = VectorXd::Zero(2 * n_start_ + 2);
    q_ = VectorXd::Zero(n_start_);
    sa_ = sb_ = zm_ = wm_ = VectorXd::Zero(solver_.model().n());
    fa_ = fb_ = zn_ = wn_ = VectorXd::Zero(n_start_);
    const Kinematics mid{0.5 * model->params().maxRopeLength(), 0.0, 0.0};
    full_->initialize(0.0, mid);
    full_->saveState(ref_);
  }
  steps_ = std::max(1L, std::lround(opt_.horizon / opt_.dt));
  substeps_ = opt_.max_step > 0.0 ? std::max(1, static_cast<int>(std::ceil(opt_.dt / opt_.max_step - 1e-9))) : 1;
  // Size the solver's lazily sized buffers once (guideRopeCoordinates' q1/q2
  // live in the envelope and are sized there).
  FastSolverState s(solver_.model().n());
  solver_.initialize(0.0, Kinematics{0.5 * model->params().maxRopeLength(), 0.0, 0.0});
  solver_.saveState(s);
  solver_.restoreState(s);
  if (reduced_) solver_.saveState(red_);
  envelope_.evaluate(solver_);
  envelope_.evaluateBounded(solver_, opt_.envelope_tolerance);
}

namespace {

bool sameState(const FastSolverState& a, const FastSolverState& b) {
  auto eq = [](const VectorXd& u, const VectorXd& v) { return u.size() == v.size() && (u.array() == v.array()).all(); };
  return a.valid && b.valid && a.t == b.t && a.kin.l == b.kin.l && a.kin.v == b.kin.v && a.kin.a == b.kin.a &&
         eq(a.x, b.x) && eq(a.xd, b.xd) && eq(a.xdd, b.xdd) && eq(a.xa, b.xa) && eq(a.y, b.y) && eq(a.yd, b.yd) &&
         eq(a.ydd, b.ydd) && eq(a.ya, b.ya) && a.lam == b.lam && a.lamS == b.lamS && a.delta == b.delta &&
         a.lambda0 == b.lambda0 && a.Fa == b.Fa && a.moment == b.moment;
}

}  // namespace

void ForecastWorkspace::project(const FastSolverState& start) {
  // The same start as the last forecast's (the other scenario of one
  // snapshot): its projection is known.
  if (sameState(start, last_start_)) {
    solver_.restoreState(projected_);
    return;
  }
  // Both models' equilibria at the start kinematics under the start's load
  // (a forecast from the load estimate carries its own; initialize() keeps
  // the load set) -- allocation-free: initialize() works in buffers sized at
  // construction.
  full_->setLoad(start.Fa, start.moment);
  solver_.setLoad(start.Fa, start.moment);
  full_->initialize(start.t, start.kin, InitialState::Static);
  full_->saveState(ref_);
  solver_.initialize(start.t, start.kin, InitialState::Static);
  solver_.saveState(red_);
  const int n = n_start_, m = solver_.model().n();
  const ShaftModel& fm = full_->model();
  const ShaftModel& rm = solver_.model();
  // Lateral (modal coordinates of each guide rope, then y_c, theta): the
  // position's deviation from the equilibrium back to sine coordinates,
  // truncated, into the reduced basis.  Rates and accelerations are
  // projected as they are: the equilibria's velocities (initialize's
  // consistent sliding-sleeve velocities) differ between the models in the
  // lowest modes, and subtracting them would set the cage swaying.  The
  // position's quasi-static part -- each model's modal response to the
  // sleeves' spring forces, sum_k lamS_k kappa^-1 .* g_k, which the static
  // correction completes with the exact Green's function -- is not
  // truncated but rebuilt in the reduced model: truncating it would leave
  // the sleeves displaced against their stiff residual springs (a kick that
  // sets the cage swaying).
  const ShaftParams& p = rm.params();
  const double la = start.kin.l / p.L, lb = (start.kin.l + 2.0 * p.h) / p.L;
  fm.guideModes(la, fa_);
  fm.guideModes(lb, fb_);
  rm.guideModes(la, sa_);
  rm.guideModes(lb, sb_);
  const Eigen::Vector4d dlS = start.lamS - ref_.lamS;
  // sleeve k on rope r at a (k = 0, 1) or b (k = 2, 3): g1 rope 1 at a, g2 rope 2 at a, g3 rope 2 at b, g4 rope 1 at b
  auto lateral = [&](const VectorXd& st, const VectorXd& rf, VectorXd& out, bool quasiStatic) {
    if (quasiStatic) dev_ = st - rf;
    else {
      dev_ = st;
      out.setZero();
    }
    for (int r = 1; r <= 2; ++r) {
      const int off = (r - 1) * n, offm = (r - 1) * m;
      const double fa = r == 1 ? dlS(0) : dlS(1), fb = r == 1 ? dlS(3) : dlS(2);
      const MatrixXd& Vn = fm.guideModalVectors(r);
      const MatrixXd& Vm = rm.guideModalVectors(r);
      // back to sine coordinates, minus the full model's quasi-static part
      q_.noalias() = Vn * dev_.segment(off, n);
      if (quasiStatic) {
        // sum_k f_k V diag(1/kappa) V^T U(a_k) in sine coordinates
        wn_ = fa * fa_ + fb * fb_;
        zn_.noalias() = Vn.transpose() * wn_;
        zn_.array() /= fm.guideModalStiffness(r).array();
        q_.noalias() -= Vn * zn_;
      }
      out.segment(offm, m).noalias() += Vm.transpose() * q_.head(m);
      if (quasiStatic) {
        wm_ = fa * sa_ + fb * sb_;
        zm_.noalias() = Vm.transpose() * wm_;
        out.segment(offm, m).array() += zm_.array() / rm.guideModalStiffness(r).array();
      }
    }
    out.tail(2) += dev_.tail(2);
  };
  lateral(start.x, ref_.x, red_.x, true);
  lateral(start.xd, ref_.xd, red_.xd, false);
  lateral(start.xdd, ref_.xdd, red_.xdd, false);
  lateral(start.xa, ref_.xa, red_.xa, false);
  red_.lam += start.lam - ref_.lam;
  red_.lamS += start.lamS - ref_.lamS;
  // The sleeves' residual displacement delta = -G x of the projected state
  // (the dashpot of the static correction acts on its change per step: a
  // stale value would be a velocity jump at the first step).
  {
    const auto z1 = red_.x.segment(0, m), z2 = red_.x.segment(m, m);
    const double yc = red_.x(2 * m), th = red_.x(2 * m + 1);
    q_.head(m).noalias() = rm.guideModalVectors(1) * z1;
    const double r1a = sa_.dot(q_.head(m)), r1b = sb_.dot(q_.head(m));
    q_.head(m).noalias() = rm.guideModalVectors(2) * z2;
    const double r2a = sa_.dot(q_.head(m)), r2b = sb_.dot(q_.head(m));
    red_.delta << -(r1a - yc + p.h * th), -(r2a - yc + p.h * th), -(r2b - yc - p.h * th), -(r1b - yc - p.h * th);
  }
  // Longitudinal: the sine basis is nested, truncation keeps the first m.
  red_.y += start.y.head(m) - ref_.y.head(m);
  red_.yd += start.yd.head(m) - ref_.yd.head(m);
  red_.ydd += start.ydd.head(m) - ref_.ydd.head(m);
  red_.ya += start.ya.head(m) - ref_.ya.head(m);
  red_.lambda0 = start.lambda0;
  red_.response = start.response;
  solver_.restoreState(red_);
  last_start_ = start;  // same sizes: copies, no allocation
  projected_ = red_;
}

void forecast(ForecastWorkspace& ws, const FastSolverState& start, const MotionProfile& scenario,
              ForecastSummary& out) {
  const ForecastOptions& o = ws.opt_;
  FastSolver& s = ws.solver_;
  if (!start.valid) throw std::invalid_argument("forecast: the start state was never saved");
  if (start.modes() != ws.n_start_)
    throw std::invalid_argument("forecast: start state has " + std::to_string(start.modes()) +
                                " modes, the workspace's model " + std::to_string(ws.n_start_));
  if (ws.reduced_) {
    // A start that cannot be projected (initialize needs a finite state
    // inside the shaft) is reported as the exact path would find it.
    const bool finite = std::isfinite(start.t) && std::isfinite(start.kin.l) && std::isfinite(start.kin.v) &&
                        std::isfinite(start.kin.a) && start.x.allFinite() && start.y.allFinite() &&
                        start.xd.allFinite() && start.yd.allFinite() && start.xdd.allFinite() &&
                        start.ydd.allFinite() && start.xa.allFinite() && start.ya.allFinite() &&
                        start.lam.allFinite() && std::isfinite(start.lambda0);
    const bool inside = start.kin.l > 0.0 && start.kin.l < s.model().params().maxRopeLength();
    if (!finite || !inside) {
      out = ForecastSummary{};
      out.t_start = start.t;
      out.horizon = o.horizon;
      out.status = finite ? ForecastStatus::LeftShaft : ForecastStatus::NonFinite;
      return;
    }
    ws.project(start);
  } else {
    s.restoreState(start);
  }
  const ShaftParams& p = s.model().params();
  const double h = p.h, lmax = p.maxRopeLength();
  const long steps = ws.steps_;
  const double t0 = start.t;

  out = ForecastSummary{};
  out.t_start = t0;
  out.horizon = o.horizon;
  const int P = static_cast<int>(std::min<long>(o.series_points, steps + 1));
  out.series_count = 0;

  Kinematics kprev = start.kin;
  double tprev = t0;
  const bool bounded = o.envelope_tolerance > 0.0;
  auto record = [&](long k, double tau) {
    const CageResponse& r = k == 0 ? start.response : s.response();
    const double gdef = bounded ? ws.envelope_.evaluateBounded(s, o.envelope_tolerance) : ws.envelope_.evaluate(s);
    const CageClearance c = cageClearance(r.y_c, r.theta, h, gdef, o.limits);
    const double l0 = r.lambda[0];
    if (k == 0) {
      out.min_clearance = c.min_clearance;
      out.t_min_clearance = 0.0;
      out.lambda0_min = out.lambda0_max = l0;
    } else {
      if (c.min_clearance < out.min_clearance) {
        out.min_clearance = c.min_clearance;
        out.t_min_clearance = tau;
      }
      out.lambda0_min = std::min(out.lambda0_min, l0);
      out.lambda0_max = std::max(out.lambda0_max, l0);
    }
    if (out.t_warning < 0.0 && c.level >= ClearanceLevel::Warning) out.t_warning = tau;
    if (out.t_critical < 0.0 && c.level >= ClearanceLevel::Critical) out.t_critical = tau;
    out.peak_y_c = std::max(out.peak_y_c, std::abs(r.y_c));
    out.peak_theta = std::max(out.peak_theta, std::abs(r.theta));
    for (int i = 0; i < 4; ++i) out.peak_lambda[i] = std::max(out.peak_lambda[i], std::abs(r.lambda[i + 1]));
    const int b = static_cast<int>((k * P) / (steps + 1));
    if (b >= out.series_count) {  // a new bucket
      out.series_count = b + 1;
      out.series_min_clearance[b] = c.min_clearance;
      out.series_lambda0_min[b] = out.series_lambda0_max[b] = l0;
    } else {
      out.series_min_clearance[b] = std::min(out.series_min_clearance[b], c.min_clearance);
      out.series_lambda0_min[b] = std::min(out.series_lambda0_min[b], l0);
      out.series_lambda0_max[b] = std::max(out.series_lambda0_max[b], l0);
    }
    out.series_t[b] = tau;
    out.steps = k;
    out.t_reached = tau;
  };

  if (!s.finite()) {
    out.status = ForecastStatus::NonFinite;
    return;
  }
  record(0, 0.0);
  const int nsub = ws.substeps_;
  for (long k = 1; k <= steps; ++k) {
    const double t = t0 + static_cast<double>(k) * o.dt;
    const Kinematics kk = scenario.at(t);
    const double hh = t - tprev;
    // Substeps as simulate() and TwinCore::advance: cubic Hermite l, linear v and a.
    const int n = o.max_step > 0.0
                      ? std::clamp(static_cast<int>(std::ceil(hh / o.max_step - 1e-9)), 1, 100000)
                      : 1;
    (void)nsub;
    bool ok = true;
    for (int j = 1; j <= n && ok; ++j) {
      Kinematics ks;
      double ts;
      if (j < n) {
        // simulate()'s substep times and HoistProfile::at's interpolation.
        const double u = static_cast<double>(j) / n;
        ts = t0 + (static_cast<double>(k - 1) + u) * o.dt;
        ks = interpolate(kprev, kk, hh, (ts - tprev) / hh);
      } else {
        ks = kk;
        ts = t;
      }
      if (!(ks.l > 0.0 && ks.l < lmax) || !std::isfinite(ks.v) || !std::isfinite(ks.a)) {
        out.status = ForecastStatus::LeftShaft;
        ok = false;
        break;
      }
      s.step(ts, ks);
    }
    if (!ok) return;
    if (!s.finite()) {
      out.status = ForecastStatus::NonFinite;
      return;
    }
    record(k, static_cast<double>(k) * o.dt);
    kprev = kk;
    tprev = t;
  }
}

}  // namespace hoist
