// LoadEstimator::finish() (hoist/load_estimator.hpp): closes a tick -- the
// NIS window, the model check's tests, the estimate, the state it implies
// and its plausibility.
#include <algorithm>
#include <cmath>

#include "hoist/load_estimator.hpp"
#include "load_estimator_detail.hpp"

namespace hoist {

using namespace estimator_detail;

void LoadEstimator::pushNis(double nis, int dof) {
  const std::size_t cap = ring_t_.size();
  if (count_ == cap) {  // full: the oldest entry leaves early (the window is shorter than asked)
    const std::size_t tail = (head_ + cap - count_) % cap;
    win_nis_ -= ring_nis_[tail];
    win_dof_ -= ring_dof_[tail];
    --count_;
  }
  ring_t_[head_] = t_;
  ring_nis_[head_] = nis;
  ring_dof_[head_] = dof;
  head_ = (head_ + 1) % cap;
  ++count_;
  win_nis_ += nis;
  win_dof_ += dof;
}

const LoadEstimate& LoadEstimator::finish() {
  // The tests wait until the filter has had warm = min_window_fill x
  // nis_window of data: the first samples' gains are large (the prior's
  // spread), and a gain that large chases even the vibration, whose
  // echo then reaches the model's band.  The NIS window collects from then
  // on and is tested once it is min_window_fill full again.
  const double warm = set_.min_window_fill * set_.nis_window;
  // A tick the daemon flags degraded (excludeTickFromModelCheck) is no
  // evidence against the model: what it completed stays out of the window.
  const bool skip = skip_nis_;
  skip_nis_ = false;
  if (tick_dof_ > 0 && !skip) {
    if (!have_update_) {
      have_update_ = true;
      first_t_ = t_;
    }
    if (t_ - first_t_ + kTimeEps >= warm) pushNis(tick_nis_, tick_dof_);
  }
  // Entries older than the window leave it.
  const std::size_t cap = ring_t_.size();
  while (count_ > 0) {
    const std::size_t tail = (head_ + cap - count_) % cap;
    if (ring_t_[tail] > t_ - set_.nis_window + kTimeEps) break;
    win_nis_ -= ring_nis_[tail];
    win_dof_ -= ring_dof_[tail];
    --count_;
  }
  if (count_ == 0) {  // no round-off residue in an empty window
    win_nis_ = 0.0;
    win_dof_ = 0;
  }

  const bool filled = have_update_ && t_ - first_t_ + kTimeEps >= warm;
  // Drift of the loads during a trip (the cage moving).
  const bool mov = moving();
  // The trip's reference: its start, or the end of the warm-up if it began before.
  if (mov && (!was_moving_ || (filled && !trip_ref_warm_))) {
    trip_ref_warm_ = filled;
    trip_Fa0_ = Fa_;
    trip_PFa0_ = PFa_;
    trip_M0_ = M_;
    trip_PM0_ = Pl_(0, 0);
    trip_QFa_ = trip_QM_ = 0.0;
    trip_drift_ = 0.0;
    drift_flag_ = false;
  }
  was_moving_ = mov;
  if (mov) {
    // With a right model, x - x0 has variance P0 - P (the information gained)
    // plus the random walk's variance added since the trip began.  Floored at
    // a quarter of P0: just after the reference P0 - P is one sample's worth,
    // and the drift would be that sample's normalized innovation (any
    // vibration the noise model leaves out would then raise the alarm).
    auto drift = [](double x, double x0, double P, double P0, double Q) {
      const double var = std::max(std::max(P0 - P, 0.0) + Q, 0.25 * P0) + 1e-12 * (P0 + 1.0);
      return std::abs(x - x0) / std::sqrt(var);
    };
    if (seen_[kRope]) trip_drift_ = std::max(trip_drift_, drift(Fa_, trip_Fa0_, PFa_, trip_PFa0_, trip_QFa_));
    if (seen_[kImuAccel] || seen_[kImuRate])
      trip_drift_ = std::max(trip_drift_, drift(M_, trip_M0_, Pl_(0, 0), trip_PM0_, trip_QM_));
    if (trip_drift_ > set_.drift_sigma && filled) drift_flag_ = true;
  }
  // Constancy: the short-memory estimate against the whole history's.  With
  // a right model their difference has variance PF - P (nested estimates).
  if (t_ - first_t_ + kTimeEps >= set_.constancy_memory && have_update_) {
    auto gap = [](double xf, double x, double PF, double P) {
      return std::abs(xf - x) / std::sqrt(std::max(PF - P, 1e-9 * (P + 1.0)));
    };
    double c = 0.0;
    if (seen_[kRope]) c = std::max(c, gap(FaF_, Fa_, PFaF_, PFa_));
    if (seen_[kImuAccel] || seen_[kImuRate]) c = std::max(c, gap(MF_, M_, PlF_(0, 0), Pl_(0, 0)));
    const_drift_ = c;
    if (c > set_.drift_sigma) drift_flag_ = true;
  }

  LoadEstimate& e = est_;
  e.t = t_;
  e.kin = kin_;
  e.nis = tick_nis_;
  e.nis_window = win_nis_;
  e.nis_dof = win_dof_;
  if (win_dof_ > 0) {
    e.nis_lower = chiSquareQuantile(0.025, win_dof_);
    e.nis_upper = chiSquareQuantile(0.975, win_dof_);
    e.nis_bound = chiSquareQuantile(1.0 - set_.nis_alpha, win_dof_);
  } else {
    e.nis_lower = e.nis_upper = e.nis_bound = 0.0;
  }
  // The alarm's bound: the chi-square quantile, and never below nis_margin
  // times the expectation (a model right to about 1 % leaves a systematic
  // residual that a test over thousands of samples resolves: significant,
  // but not a shaft that behaves differently from its model).
  e.nis_bound = std::max(e.nis_bound, set_.nis_margin * win_dof_);
  const bool nis_ready = have_update_ && t_ - first_t_ + kTimeEps >= 2.0 * warm;
  if (nis_ready && win_dof_ > 0 && win_nis_ > e.nis_bound) nis_flag_ = true;
  else if (nis_flag_ && (win_dof_ == 0 || win_nis_ < e.nis_upper)) nis_flag_ = false;  // hysteresis
  e.nis_exceeded = nis_flag_;
  e.drift = std::max(trip_drift_, const_drift_);
  e.drift_exceeded = drift_flag_;
  e.mismatch = nis_flag_ || drift_flag_;

  e.sensors = 0;
  const unsigned bits[3] = {kSensorImuAccel, kSensorImuRate, kSensorRopeLoad};
  for (int i = 0; i < 3; ++i)
    if (t_ - last_upd_[i] <= set_.sensor_timeout + kTimeEps) e.sensors |= bits[i];
  e.fault_imu_accel = mon_[kImuAccel].faults();
  e.fault_imu_rate = mon_[kImuRate].faults();
  e.fault_rope_load = mon_[kRope].faults();
  e.faulty = (e.fault_imu_accel ? kSensorImuAccel : 0u) | (e.fault_imu_rate ? kSensorImuRate : 0u) |
             (e.fault_rope_load ? kSensorRopeLoad : 0u);
  constexpr unsigned kQuietBits = kFaultQuiet | kFaultStuck;
  e.imu_quiet = ((e.fault_imu_accel | e.fault_imu_rate) & kQuietBits) != 0;
  e.rope_quiet = (e.fault_rope_load & kQuietBits) != 0;
  e.noise_imu_accel = std::sqrt(mon_[kImuAccel].noiseVariance());
  e.noise_imu_rate = std::sqrt(mon_[kImuRate].noiseVariance());
  e.noise_rope_load = std::sqrt(mon_[kRope].noiseVariance());
  e.change_t = change_t_;
  e.change_Fa = change_t_ >= 0.0 ? Fa_ - change_Fa0_ : 0.0;
  e.change_moment = change_t_ >= 0.0 ? M_ - change_M0_ : 0.0;
  e.change_level = std::max(cusum_fa_.level(), cusum_m_.level());
  e.fa_observed = seen_[kRope];
  e.moment_observed = seen_[kImuAccel] || seen_[kImuRate];

  const double sFa = std::sqrt(PFa_), sM = std::sqrt(Pl_(0, 0));
  e.Fa = Fa_;
  e.sigma_Fa = sFa;
  e.moment = M_;
  e.sigma_moment = sM;
  e.accel_offset = c_;
  e.sigma_accel_offset = accelOffsetSigma();
  e.known_load = knownLoad();
  if (e.fa_observed && e.moment_observed && std::abs(Fa_) > 3.0 * sFa) {
    e.b = M_ / Fa_;
    e.sigma_b = std::sqrt(Pl_(0, 0) + e.b * e.b * PFa_) / std::abs(Fa_);
  } else {
    e.b = 0.0;
    e.sigma_b = -1.0;
  }

  // The state the estimated load implies, and its sigma (load + model error).
  const CageResponse& tw = twin_resp_;
  const CageResponse& s = sens_->response();
  const CageResponse& q = stepping_ ? step_->response() : s;
  const double oFa = o_Fa_ - Fa_c_, oM = o_M_ - M_c_;  // 0 unless following a load change
  const double dFa = Fa_ - o_Fa_, dM = M_ - o_M_, eps = set_.model_error;
  auto lateral = [&](double open, double sens, double step, double& value, double& sigma) {
    value = open + oM * sens + dM * step;
    sigma = std::hypot(step * sM, eps * value);
  };
  e.x_c = tw.x_c + oFa * s.x_c + dFa * q.x_c;
  e.sigma_x_c = std::hypot(q.x_c * sFa, eps * e.x_c);
  lateral(tw.y_c, s.y_c, q.y_c, e.y_c, e.sigma_y_c);
  lateral(tw.theta, s.theta, q.theta, e.theta, e.sigma_theta);
  e.lambda[0] = tw.lambda[0] + oFa * s.lambda[0] + dFa * q.lambda[0];
  e.sigma_lambda[0] = std::hypot(q.lambda[0] * sFa, eps * (e.lambda[0] - (twin_.m * twin_.g + Fa_)));
  for (int i = 1; i < 5; ++i) lateral(tw.lambda[i], s.lambda[i], q.lambda[i], e.lambda[i], e.sigma_lambda[i]);
  e.theta_open = tw.theta;
  judgePlausibility();
  return e;
}

void LoadEstimator::judgePlausibility() {
  LoadEstimate& e = est_;
  const double fa_max = twin_.payloadLimit(), b_max = twin_.offsetLimit();
  e.implausible = "";
  // Below zero only within 3 sigma, and only once settled (sigma under 5 %
  // of the rating): an empty conveyance, not a payload pulled below zero.
  if (e.fa_observed && (e.Fa + 3.0 * e.sigma_Fa < 0.0 || (e.Fa < 0.0 && e.sigma_Fa > 0.05 * fa_max)))
    e.implausible = "Fa < 0";
  else if (e.fa_observed && e.Fa - 3.0 * e.sigma_Fa > fa_max) e.implausible = "Fa > max_payload";
  else if (e.moment_observed && std::abs(e.moment) - 3.0 * e.sigma_moment > fa_max * b_max)
    e.implausible = "|M| > max_payload * max_offset";
  else if (e.sigma_b >= 0.0 && std::abs(e.b) - 3.0 * e.sigma_b > b_max) e.implausible = "|b| > max_offset";
  else if (!std::isfinite(e.Fa) || !std::isfinite(e.moment)) e.implausible = "non-finite";
  else {
    CageResponse r = twin_resp_;
    r.x_c = e.x_c;
    r.y_c = e.y_c;
    r.theta = e.theta;
    for (int i = 0; i < 5; ++i) r.lambda[i] = e.lambda[i];
    double value = 0.0, limit = 0.0;
    if (const char* what = implausible(r, twin_.h, bounds_, value, limit)) e.implausible = what;
  }
  e.plausible = e.implausible[0] == '\0';
}

}  // namespace hoist
