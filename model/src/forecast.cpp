#include "hoist/forecast.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

ForecastWorkspace::ForecastWorkspace(std::shared_ptr<const ShaftModel> model, const ForecastOptions& opt)
    : opt_((opt.validate(), opt)), solver_(model), envelope_(*model, opt.envelope_points) {
  steps_ = std::max(1L, std::lround(opt_.horizon / opt_.dt));
  substeps_ = opt_.max_step > 0.0 ? std::max(1, static_cast<int>(std::ceil(opt_.dt / opt_.max_step - 1e-9))) : 1;
  // Size the solver's lazily sized buffers once (guideRopeCoordinates' q1/q2
  // live in the envelope and are sized there).
  FastSolverState s(model->n());
  solver_.initialize(0.0, Kinematics{0.5 * model->params().maxRopeLength(), 0.0, 0.0});
  solver_.saveState(s);
  solver_.restoreState(s);
  envelope_.evaluate(solver_);
}

void forecast(ForecastWorkspace& ws, const FastSolverState& start, const MotionProfile& scenario,
              ForecastSummary& out) {
  const ForecastOptions& o = ws.opt_;
  FastSolver& s = ws.solver_;
  s.restoreState(start);
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
  auto record = [&](long k, double tau) {
    const CageResponse& r = s.response();
    const double gdef = ws.envelope_.evaluate(s);
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
