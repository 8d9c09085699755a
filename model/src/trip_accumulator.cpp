// TripAccumulator: one TripRecord from a trip's samples (hoist/trip_accumulator.hpp).
#include "hoist/trip_accumulator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "hoist/clearance.hpp"
#include "hoist/preload_identification.hpp"

namespace hoist {

namespace {
// The estimate's loads into a record's fields (sigma -1 where not observed).
void copyLoads(const TripEstimate& e, double& Fa, double& sFa, double& M, double& sM, double& b, double& sb) {
  Fa = e.Fa;
  sFa = e.fa_observed ? e.sigma_Fa : -1.0;
  M = e.moment;
  sM = e.moment_observed ? e.sigma_moment : -1.0;
  b = e.b;
  sb = e.sigma_b;
}
}  // namespace

TripEstimate tripEstimate(const LoadEstimate& e) {
  TripEstimate t;
  t.Fa = e.Fa;
  t.sigma_Fa = e.sigma_Fa;
  t.moment = e.moment;
  t.sigma_moment = e.sigma_moment;
  t.b = e.b;
  t.sigma_b = e.sigma_b;
  t.fa_observed = e.fa_observed;
  t.moment_observed = e.moment_observed;
  t.mismatch = e.mismatch;
  t.nis_dof = e.nis_dof;
  t.nis_window = e.nis_window;
  t.drift = e.drift;
  t.y_c = e.y_c;
  t.theta = e.theta;
  t.lambda = e.lambda;
  return t;
}

double conditionBandHz(const ShaftParams& p, double band_hz) {
  if (band_hz > 0.0) return band_hz;
  const double T = std::max(p.Tb1, p.Tb2) + p.rho2 * p.g * p.L;
  return p.n / (2.0 * p.L) * std::sqrt(T / p.rho2);
}

TripAccumulator::TripAccumulator(const ShaftParams& twin, const EstimatorSettings& est,
                                 const ConditionSettings& cond, double max_step, double reserve_seconds)
    : twin_(twin), est_(est), cond_(cond), max_step_(max_step) {
  cond_.validate();
  est_.validate();
  const auto n = static_cast<std::size_t>(std::max(0.0, reserve_seconds) * 100.0);
  samples_.reserve(n);
  y_c_.reserve(n);
  theta_.reserve(n);
}

void TripAccumulator::begin(const MeasurementSample& m, const TripEstimate& e, double guide_deflection) {
  samples_.clear();
  y_c_.clear();
  theta_.clear();
  rec_ = TripRecord{};
  rec_.t_start = m.t;
  rec_.depth_start = m.k.l;
  copyLoads(e, rec_.Fa_start, rec_.sigma_Fa_start, rec_.moment_start, rec_.sigma_moment_start, rec_.b_start,
            rec_.sigma_b_start);
  rec_.min_clearance = std::numeric_limits<double>::infinity();
  rec_.lambda0_min = std::numeric_limits<double>::infinity();
  rec_.lambda0_max = -std::numeric_limits<double>::infinity();
  active_ = true;
  take(m, e, guide_deflection);
}

void TripAccumulator::add(const MeasurementSample& m, const TripEstimate& e, double guide_deflection) {
  if (active_) take(m, e, guide_deflection);
}

void TripAccumulator::addAlarm(std::string_view kind) {
  if (!active_) return;
  if (std::find(rec_.alarms.begin(), rec_.alarms.end(), kind) == rec_.alarms.end()) rec_.alarms.emplace_back(kind);
}

void TripAccumulator::take(const MeasurementSample& m, const TripEstimate& e, double guide_deflection) {
  samples_.push_back(m);
  y_c_.push_back(e.y_c);
  theta_.push_back(e.theta);
  rec_.peak_speed = std::max(rec_.peak_speed, std::abs(m.k.v));
  rec_.peak_accel = std::max(rec_.peak_accel, std::abs(m.k.a));
  if (e.nis_dof > 0) rec_.nis_peak = std::max(rec_.nis_peak, e.nis_window / e.nis_dof);
  rec_.constancy_peak = std::max(rec_.constancy_peak, e.drift);
  rec_.mismatch = rec_.mismatch || e.mismatch;
  const double c = cageClearance(e.y_c, e.theta, twin_.h, guide_deflection, cond_.clearance).min_clearance;
  if (c < rec_.min_clearance) {
    rec_.min_clearance = c;
    rec_.min_clearance_depth = m.k.l;
  }
  rec_.lambda0_min = std::min(rec_.lambda0_min, e.lambda[0]);
  rec_.lambda0_max = std::max(rec_.lambda0_max, e.lambda[0]);
  for (int k = 1; k < 5; ++k) rec_.lambda_guide_max = std::max(rec_.lambda_guide_max, std::abs(e.lambda[k]));
  last_ = e;
}

TripRecord TripAccumulator::finish(double t_arrival, const Kinematics& arrival) {
  TripRecord r = std::move(rec_);
  rec_ = TripRecord{};
  active_ = false;
  r.t_end = t_arrival;
  r.depth_end = arrival.l;
  r.direction = r.depth_end >= r.depth_start ? TripDirection::Down : TripDirection::Up;
  copyLoads(last_, r.Fa_end, r.sigma_Fa_end, r.moment_end, r.sigma_moment_end, r.b_end, r.sigma_b_end);
  r.depth_bin = cond_.depth_bin;

  PreloadFitOptions opt;
  opt.max_sigma = cond_.max_sigma;
  opt.accel_offset_sigma = cond_.accel_offset_sigma;
  opt.max_step = max_step_;
  PreloadFit fit = identifyPreload(twin_, est_, opt, samples_);
  r.id = fit.id;

  // Depth bins.
  struct Acc {
    int n = 0, ns = 0, nr = 0;
    double fy = 0, fy2 = 0, hf2 = 0, res = 0, res2 = 0, y = 0, y2 = 0, th = 0, th2 = 0;
  };
  std::map<long, Acc> bins;
  const double band = conditionBandHz(twin_, cond_.band_hz);
  double lp = 0.0, t_prev = 0.0;
  bool lp_init = false;
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    const MeasurementSample& m = samples_[i];
    Acc& b = bins[static_cast<long>(std::floor(m.k.l / cond_.depth_bin))];
    ++b.ns;
    b.y += y_c_[i];
    b.y2 += y_c_[i] * y_c_[i];
    b.th += theta_[i];
    b.th2 += theta_[i] * theta_[i];
    if (!(m.present & kSensorImuAccel)) continue;
    if (!lp_init) {
      lp = m.z.f_y;
      lp_init = true;
    } else {
      const double h = m.t - t_prev;
      const double f = std::min(band, 0.25 / std::max(h, 1e-6));
      lp += (1.0 - std::exp(-2.0 * M_PI * f * h)) * (m.z.f_y - lp);
    }
    t_prev = m.t;
    ++b.n;
    b.fy += lp;
    b.fy2 += lp * lp;
    b.hf2 += (m.z.f_y - lp) * (m.z.f_y - lp);
    if (std::isfinite(fit.fitted_fy[i])) {
      const double res = m.z.f_y - fit.fitted_fy[i];
      ++b.nr;
      b.res += res;
      b.res2 += res * res;
    }
  }
  for (const auto& [k, b] : bins) {
    DepthBinStats s;
    s.depth_lo = k * cond_.depth_bin;
    s.samples = b.n;
    if (b.n > 0) {
      s.fy_mean = b.fy / b.n;
      s.fy_rms = std::sqrt(b.fy2 / b.n);
      s.fy_hf_rms = std::sqrt(b.hf2 / b.n);
    }
    if (b.nr > 0) {
      s.resid_mean = b.res / b.nr;
      s.resid_rms = std::sqrt(b.res2 / b.nr);
    }
    s.y_c_mean = b.y / b.ns;
    s.y_c_rms = std::sqrt(b.y2 / b.ns);
    s.theta_mean = b.th / b.ns;
    s.theta_rms = std::sqrt(b.th2 / b.ns);
    r.bins.push_back(s);
  }
  return r;
}

}  // namespace hoist
