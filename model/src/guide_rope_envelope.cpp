// The guide-rope envelope: see hoist/guide_rope_envelope.hpp.
#include "hoist/guide_rope_envelope.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hoist {

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
  last_deferred_ = false;
  deferred_run_ = 0;
  ++exact_count_;
  return std::max(e1r_, e2r_);
}

double GuideRopeEnvelope::evaluateBounded(const Solver& s, double tolerance) {
  return evaluateBounded(s, tolerance, -std::numeric_limits<double>::infinity());
}

double GuideRopeEnvelope::evaluateBounded(const Solver& s, double tolerance, double defer_below) {
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
  const double bound = std::max(e1r_ + d1, e2r_ + d2);
  // Not (2 D <= tolerance) also catches a non-finite state: exact then --
  // unless the caller defers it and the (wider, still rigorous) bound is
  // below defer_below (false for NaN).
  if (!(2.0 * std::max(d1, d2) <= tolerance)) {
    if (!(bound < defer_below)) return exact(s, loads);
    last_exact_ = false;
    last_deferred_ = true;
    ++deferred_count_;
    ++deferred_run_;
    longest_deferral_ = std::max(longest_deferral_, deferred_run_);
    return bound;
  }
  last_exact_ = false;
  last_deferred_ = false;
  deferred_run_ = 0;
  ++bounded_count_;
  return bound;
}

double maxGuideRopeDeflection(const Solver& s, int samples) {
  GuideRopeEnvelope env(s.model(), samples);
  return env.evaluate(s);
}

}  // namespace hoist
