#include "hoist/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hoist/fast_solver.hpp"
#include "hoist/paper_solver.hpp"

namespace hoist {

const char* toString(Method m) { return m == Method::Fast ? "fast" : "paper"; }

std::unique_ptr<Solver> makeSolver(Method method, std::shared_ptr<const ShaftModel> model) {
  if (method == Method::Paper) return std::make_unique<PaperSolver>(std::move(model));
  return std::make_unique<FastSolver>(std::move(model));
}

GuideRopeEnvelope::GuideRopeEnvelope(const ShaftModel& model, int samples) {
  if (samples < 2) throw std::invalid_argument("GuideRopeEnvelope: need at least 2 samples");
  const int n = model.n();
  const double L = model.params().L;
  x_ = VectorXd::LinSpaced(samples, 0.0, L);
  table_.resize(samples, n);
  VectorXd U(n);
  for (int i = 0; i < samples; ++i) {
    model.guideModes(x_(i) / L, U);
    table_.row(i) = U.transpose();
  }
  umax_ = table_.cwiseAbs().colwise().maxCoeff().transpose();
  S1_.resize(samples);
  S2_.resize(samples);
  for (int i = 0; i < samples; ++i) {
    S1_(i) = model.guideFlexibilityIntegral(1, x_(i));
    S2_(i) = model.guideFlexibilityIntegral(2, x_(i));
  }
  SL1_ = model.guideFlexibilityTotal(1);
  SL2_ = model.guideFlexibilityTotal(2);
  // The tension is linear in depth: its minimum is at an end.
  lip1_ = 1.0 / std::min(model.guideTension(1, 0.0), model.guideTension(1, L));
  lip2_ = 1.0 / std::min(model.guideTension(2, 0.0), model.guideTension(2, L));
  q1_ = q2_ = q1r_ = q2r_ = VectorXd::Zero(n);
  y1_ = y2_ = VectorXd::Zero(samples);
}

double GuideRopeEnvelope::evaluate(const Solver& s) {
  s.guideRopeCoordinates(q1_, q2_);
  SleeveLoads loads;
  s.residualSleeveLoads(loads);
  return exact(s, loads);
}

double GuideRopeEnvelope::exact(const Solver& s, const SleeveLoads& loads) {
  y1_.noalias() = table_ * q1_;
  y2_.noalias() = table_ * q2_;
  for (int k = 0; k < loads.count; ++k) {
    // G(x, a) f = S(min)(S(L) - S(max)) / S(L) f on the grid.
    const bool r1 = loads.rope[k] == 1;
    const VectorXd& S = r1 ? S1_ : S2_;
    const double SL = r1 ? SL1_ : SL2_;
    const double Sa = s.model().guideFlexibilityIntegral(r1 ? 1 : 2, loads.x[k]);
    const double f = loads.f[k] / SL;
    VectorXd& y = r1 ? y1_ : y2_;
    const Eigen::Index m = x_.size();
    for (Eigen::Index i = 0; i < m; ++i)
      y(i) += x_(i) <= loads.x[k] ? S(i) * (SL - Sa) * f : Sa * (SL - S(i)) * f;
  }
  e1r_ = y1_.cwiseAbs().maxCoeff();
  e2r_ = y2_.cwiseAbs().maxCoeff();
  q1r_ = q1_;
  q2r_ = q2_;
  ref_loads_ = loads;
  have_ref_ = true;
  last_exact_ = true;
  ++exact_count_;
  return std::max(e1r_, e2r_);
}

double GuideRopeEnvelope::evaluateBounded(const Solver& s, double tolerance) {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) return evaluate(s);
  s.guideRopeCoordinates(q1_, q2_);
  SleeveLoads loads;
  s.residualSleeveLoads(loads);
  if (!have_ref_ || loads.count != ref_loads_.count) return exact(s, loads);
  double d1 = umax_.dot((q1_ - q1r_).cwiseAbs());
  double d2 = umax_.dot((q2_ - q2r_).cwiseAbs());
  for (int k = 0; k < loads.count; ++k) {
    const int r = loads.rope[k];
    if (r != ref_loads_.rope[k]) return exact(s, loads);
    const double SL = r == 1 ? SL1_ : SL2_;
    const double Sa = s.model().guideFlexibilityIntegral(r, loads.x[k]);
    const double gaa = Sa * (SL - Sa) / SL;  // max_x G_r(x, a) = G_r(a, a)
    const double d = gaa * std::fabs(loads.f[k] - ref_loads_.f[k]) +
                     std::fabs(ref_loads_.f[k]) * std::fabs(loads.x[k] - ref_loads_.x[k]) * (r == 1 ? lip1_ : lip2_);
    (r == 1 ? d1 : d2) += d;
  }
  // Not (2 D <= tolerance) also catches a non-finite state: exact then.
  if (!(2.0 * std::max(d1, d2) <= tolerance)) return exact(s, loads);
  last_exact_ = false;
  ++bounded_count_;
  return std::max(e1r_ + d1, e2r_ + d2);
}

void Solver::guideRopeShapes(const VectorXd& x, VectorXd& y1, VectorXd& y2) const {
  VectorXd q1, q2;
  guideRopeCoordinates(q1, q2);
  VectorXd U(q1.size());
  SleeveLoads loads;
  residualSleeveLoads(loads);
  y1.resize(x.size());
  y2.resize(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    model_->guideModes(x(i) / model_->params().L, U);
    y1(i) = U.dot(q1);
    y2(i) = U.dot(q2);
    for (int k = 0; k < loads.count; ++k)
      (loads.rope[k] == 1 ? y1(i) : y2(i)) += model_->guideGreen(loads.rope[k], x(i), loads.x[k]) * loads.f[k];
  }
}

double maxGuideRopeDeflection(const Solver& s, int samples) {
  GuideRopeEnvelope env(s.model(), samples);
  return env.evaluate(s);
}

int substepsFor(const SimulationOptions& opt) {
  if (!(opt.max_step >= 0.0) || !std::isfinite(opt.max_step))
    throw std::invalid_argument("simulate: max_step must be >= 0");
  if (opt.max_step >= opt.dt) return 1;
  try {
    return substepCount(opt.dt, opt.max_step, 1000000);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("simulate: dt / max_step exceeds 1e6 substeps");
  }
}

void simulate(Solver& solver, const HoistProfile& profile, const SimulationOptions& opt,
              const std::function<void(const CageResponse&)>& sink, const std::function<void(double)>& progress) {
  if (profile.empty()) throw std::invalid_argument("simulate: empty profile");
  if (!(opt.dt > 0.0) || !std::isfinite(opt.dt)) throw std::invalid_argument("simulate: dt must be > 0");
  const double t0 = profile.startTime();
  const double t_end = opt.t_end < 0 ? profile.endTime() : opt.t_end;
  const long steps = std::lround((t_end - t0) / opt.dt);
  if (steps < 0) throw std::invalid_argument("simulate: t_end before the profile start");
  solver.initialize(t0, profile.at(t0), opt.initial);
  if (sink) sink(solver.response());
  const long every = std::max(1L, steps / 100);
  const int sub = substepsFor(opt);
  for (long k = 1; k <= steps; ++k) {
    const double t = t0 + static_cast<double>(k) * opt.dt;
    for (int j = 1; j < sub; ++j) {
      const double ts = t0 + (static_cast<double>(k - 1) + static_cast<double>(j) / sub) * opt.dt;
      solver.step(ts, profile.at(ts));
    }
    solver.step(t, profile.at(t));
    if (sink) sink(solver.response());
    if (progress && k % every == 0) progress(static_cast<double>(k) / static_cast<double>(steps));
  }
  if (progress) progress(1.0);
}

}  // namespace hoist
