#include "hoist/load_estimator.hpp"

#include "load_estimator_detail.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hoist {

using namespace estimator_detail;

namespace {

void requirePositive(double v, const char* key) {
  if (!(std::isfinite(v) && v > 0.0)) throw std::invalid_argument(std::string(key) + ": must be > 0");
}
void requireNonNegative(double v, const char* key) {
  if (!(std::isfinite(v) && v >= 0.0)) throw std::invalid_argument(std::string(key) + ": must be >= 0");
}

}  // namespace

SensorValues sensorModel(const CageResponse& r, double g) {
  return {r.y_c_ddot + (g - r.kin.a) * r.theta, r.theta_dot, r.lambda[0]};
}

void EstimatorSettings::validate() const {
  requirePositive(noise.imu_accel, "sensors.imu_accel_noise");
  requirePositive(noise.imu_rate, "sensors.imu_rate_noise");
  requirePositive(noise.rope_load, "sensors.rope_load_noise");
  if (!(std::isfinite(accel_offset_sigma) && accel_offset_sigma >= 0.0 && accel_offset_sigma <= 1.0))
    throw std::invalid_argument("sensors.imu_accel_offset_sigma: must be in [0, 1] m/s^2");
  requireNonNegative(fa_walk, "estimator.fa_walk");
  requireNonNegative(moment_walk, "estimator.moment_walk");
  requireNonNegative(moving_walk_scale, "estimator.moving_walk_scale");
  requireNonNegative(rest_speed, "estimator.rest_speed");
  requirePositive(fa_sigma0, "estimator.fa_sigma0");
  requirePositive(moment_sigma0, "estimator.moment_sigma0");
  requireNonNegative(model_error, "estimator.model_error");
  if (!(gate_sigma >= 3.0 && gate_sigma <= 1e6)) throw std::invalid_argument("estimator.gate_sigma: must be in [3, 1e6]");
  if (gate_reset < 1 || gate_reset > 100000) throw std::invalid_argument("estimator.gate_reset: must be in [1, 100000]");
  if (!(nis_window >= 0.1 && nis_window <= 600.0))
    throw std::invalid_argument("estimator.nis_window: must be in [0.1, 600] s");
  if (!(nis_alpha > 0.0 && nis_alpha < 0.5)) throw std::invalid_argument("estimator.nis_alpha: must be in (0, 0.5)");
  if (!(nis_margin >= 1.0 && nis_margin <= 100.0)) throw std::invalid_argument("estimator.nis_margin: must be in [1, 100]");
  requirePositive(drift_sigma, "estimator.drift_sigma");
  if (!(constancy_memory >= 0.5 && constancy_memory <= 3600.0))
    throw std::invalid_argument("estimator.constancy_memory: must be in [0.5, 3600] s");
  if (!(min_window_fill >= 0.0 && min_window_fill <= 1.0))
    throw std::invalid_argument("estimator.min_window_fill: must be in [0, 1]");
  requirePositive(sensor_timeout, "estimator.sensor_timeout");
  requirePositive(model_band, "estimator.model_band");
  requirePositive(noise_memory, "estimator.noise_memory");
  if (!(quiet_ratio > 0.0 && quiet_ratio < 1.0)) throw std::invalid_argument("estimator.quiet_ratio: must be in (0, 1)");
  requirePositive(quiet_memory, "estimator.quiet_memory");
  requirePositive(stuck_time, "estimator.stuck_time");
  if (!(noisy_factor > 1.0 && std::isfinite(noisy_factor)))
    throw std::invalid_argument("estimator.noisy_factor: must be > 1");
  if (!(band_block >= 0.0 && band_block <= 5.0)) throw std::invalid_argument("estimator.band_block: must be in [0, 5] s");
  requireNonNegative(change_drift, "estimator.change_drift");
  requirePositive(change_threshold, "estimator.change_threshold");
  requireNonNegative(change_holdoff, "estimator.change_holdoff");
  if (max_rate < 1 || max_rate > 100000) throw std::invalid_argument("estimator.max_rate: must be in [1, 100000] Hz");
  if (nis_window * max_rate > 5.0e6)
    throw std::invalid_argument("estimator.nis_window: nis_window * max_rate must stay below 5e6 entries");
}

LoadEstimator::LoadEstimator(const ShaftParams& twin, const EstimatorSettings& settings)
    : twin_(twin), set_(settings) {
  set_.validate();
  twin_.validate();
  Model m = buildModel(twin_);
  sens_ = std::move(m.sens);
  step_ = std::move(m.step);
  Fa_c_ = twin_.Fa;
  M_c_ = twin_.Fa * twin_.b;
  bounds_ = plausibilityBounds(twin_, 1.0);
  const auto cap = static_cast<std::size_t>(std::ceil(set_.nis_window * set_.max_rate)) + 2;
  ring_t_.assign(cap, 0.0);
  ring_nis_.assign(cap, 0.0);
  ring_dof_.assign(cap, 0);
  Pc0_ = set_.accel_offset_sigma * set_.accel_offset_sigma;
}

LoadEstimator::Model LoadEstimator::buildModel(const ShaftParams& twin) {
  twin.validate();
  ShaftParams unit = twin;
  unit.Fa = 1.0;
  unit.b = 1.0;
  auto unit_model = std::make_shared<const ShaftModel>(unit);
  Model m;
  m.twin = twin;
  m.sens = std::make_unique<FastSolver>(unit_model, Forcing::LoadOnly);
  m.step = std::make_unique<FastSolver>(unit_model, Forcing::LoadOnly);
  return m;
}

void LoadEstimator::swapModel(Model& m) {
  if (!m.sens || !m.step || m.twin.n != twin_.n)
    throw std::invalid_argument("LoadEstimator::swapModel: a model of the same n with both solvers is needed");
  // The prior stays the configured load (Fa_c_, M_c_ are kept).
  std::swap(m.twin.Fa, twin_.Fa);
  std::swap(m.twin.b, twin_.b);
  std::swap(twin_, m.twin);
  std::swap(sens_, m.sens);
  std::swap(step_, m.step);
  bounds_ = plausibilityBounds(twin_, 1.0);
  stepping_ = false;  // a followed step's transient belonged to the old model
}

void LoadEstimator::initialize(double t0, const Kinematics& k0) {
  sens_->initialize(t0, k0, twin_.initial);
  t_ = t0;
  kin_ = k0;
  Fa_ = Fa_c_;
  FaF_ = Fa_c_;
  PFa_ = set_.fa_sigma0 * set_.fa_sigma0;
  M_ = M_c_;
  MF_ = M_c_;
  Pl_.setZero();
  Pl_(0, 0) = set_.moment_sigma0 * set_.moment_sigma0;
  // The accelerometer's offset: the learned one (setAccelOffset) or the prior.
  c_ = c0_;
  Pl_(1, 1) = Pc0_;
  cF_ = c_;
  PFaF_ = PFa_;
  PlF_ = Pl_;
  const_drift_ = 0.0;
  run_fa_ = run_m_ = 0;
  env_fy_ = env_om_ = env_rope_ = 0.0;
  // A start while the winder accelerates is not an equilibrium of the shaft:
  // the transient reaches the rope's modes beyond n (measured: n = 25 against
  // n = 100 and 200, 40-60 N at a = 1 m/s^2 for the first 5 s, 10-20 N at 10 s).
  start_rope_ = kStartTransientError * twin_.m * std::abs(k0.a);
  jump_rope_ = 0.0;
  last_a_ = k0.a;
  env_t_ = t0;
  tick_nis_ = 0.0;
  tick_dof_ = 0;
  for (int i = 0; i < 3; ++i) {
    last_upd_[i] = -1e300;
    seen_[i] = false;
  }
  head_ = count_ = 0;
  win_nis_ = 0.0;
  win_dof_ = 0;
  first_t_ = t0;
  have_update_ = false;
  was_moving_ = false;
  trip_ref_warm_ = false;
  trip_drift_ = 0.0;
  nis_flag_ = drift_flag_ = false;
  const double sig[3] = {set_.noise.imu_accel, set_.noise.imu_rate, set_.noise.rope_load};
  for (int i = 0; i < 3; ++i) {
    SensorMonitorSettings ms;
    ms.sigma = sig[i];
    ms.lp_time = set_.model_band;
    ms.noise_memory = set_.noise_memory;
    ms.quiet_memory = set_.quiet_memory;
    ms.quiet_ratio = set_.quiet_ratio;
    ms.stuck_time = set_.stuck_time;
    ms.noisy_factor = set_.noisy_factor;
    mon_[i].reset(ms);
  }
  for (BandInnovation& b : band_) b = BandInnovation(set_.band_block);
  cusum_fa_ = ChangeDetector(set_.change_drift, set_.change_threshold);
  cusum_m_ = cusum_fa_;
  rest_since_ = t0;
  change_t_ = -1.0;
  change_Fa0_ = change_M0_ = 0.0;
  stepping_ = false;
  o_Fa_ = Fa_c_;
  o_M_ = M_c_;
  step_e_fy_ = step_e_om_ = step_e_rope_ = 0.0;
  counts_ = {};
  est_ = {};
  twin_resp_ = sens_->response();
  predict(twin_resp_);
}

void LoadEstimator::restart(double t0, const Kinematics& k0) {
  const double Fa = Fa_, PFa = PFa_, M = M_, FaF = FaF_, PFaF = PFaF_, MF = MF_, c = c_, cF = cF_;
  const Eigen::Matrix2d Pl = Pl_, PlF = PlF_;
  double last[3];
  bool seen[3];
  for (int i = 0; i < 3; ++i) {
    last[i] = last_upd_[i];
    seen[i] = seen_[i];
  }
  const EstimatorCounters counts = counts_;
  SensorMonitor mon[3] = {mon_[0], mon_[1], mon_[2]};
  const double change_t = change_t_, change_Fa0 = change_Fa0_, change_M0 = change_M0_;
  initialize(t0, k0);
  for (int i = 0; i < 3; ++i) mon_[i] = mon[i];
  change_t_ = change_t;
  change_Fa0_ = change_Fa0;
  change_M0_ = change_M0;
  Fa_ = Fa;
  PFa_ = PFa;
  M_ = M;
  Pl_ = Pl;
  c_ = c;
  cF_ = cF;
  FaF_ = FaF;
  PFaF_ = PFaF;
  MF_ = MF;
  PlF_ = PlF;
  for (int i = 0; i < 3; ++i) {
    last_upd_[i] = last[i];
    seen_[i] = seen[i];
  }
  counts_ = counts;
  predict(CageResponse(twin_resp_));
}

bool LoadEstimator::moving() const {
  return std::abs(kin_.v) > set_.rest_speed || std::abs(kin_.a) > set_.rest_speed;
}

void LoadEstimator::advance(double t1, const Kinematics& k1, int substeps) {
  const double t0 = t_, h = t1 - t0;
  const Kinematics k0 = kin_;
  const int n = std::max(1, substeps);
  for (int j = 1; j < n; ++j) {
    const double u = static_cast<double>(j) / n;
    sens_->step(t0 + u * h, interpolate(k0, k1, h, u));
  }
  sens_->step(t1, k1);
  if (stepping_) {
    for (int j = 1; j < n; ++j) {
      const double u = static_cast<double>(j) / n;
      step_->step(t0 + u * h, interpolate(k0, k1, h, u));
    }
    step_->step(t1, k1);
    if (t1 - step_t_ > kStepFoldTime) foldStep();
  }
  if (h > 0.0) sub_h_ = h / n;
  const bool was_moving = moving();
  t_ = t1;
  kin_ = k1;
  if (moving()) {
    cusum_fa_.reset();
    cusum_m_.reset();
  } else if (was_moving) {
    rest_since_ = t1;
  }
  // Random walk of the loads over the interval (slower while the cage moves).
  const double scale = moving() ? set_.moving_walk_scale : 1.0;
  // A declared known load is pinned: no walk (declareKnownLoad()).
  const double pin = knownLoad() ? 0.0 : 1.0;
  const double qfa = set_.fa_walk * scale * pin, qm = set_.moment_walk * scale * pin;
  PFa_ += qfa * qfa * h;
  Pl_(0, 0) += qm * qm * h;
  // The short-memory twins forget with time constant constancy_memory.
  const double forget = std::exp(h / set_.constancy_memory);
  PFaF_ = PFaF_ * forget + qfa * qfa * h;
  PlF_ *= forget;  // the offset's information too: nested estimates, PF - P >= 0
  PlF_(0, 0) += qm * qm * h;
  trip_QFa_ += qfa * qfa * h;
  trip_QM_ += qm * qm * h;
}

void LoadEstimator::predict(const CageResponse& twin) {
  twin_resp_ = twin;
  const CageResponse& s = sens_->response();
  const CageResponse& q = stepping_ ? step_->response() : s;
  const double oFa = o_Fa_ - Fa_c_, oM = o_M_ - M_c_;  // 0 unless following a load change
  const double dFa = Fa_ - o_Fa_, dM = M_ - o_M_;
  // The sensor model is linear: the sensitivities read through it (the
  // sensitivity solver's own a-term is the twin's: same kinematics).
  const SensorValues zt = sensorModel(twin, twin_.g), zs = sensorModel(s, twin_.g);
  const SensorValues zq = stepping_ ? sensorModel(q, twin_.g) : zs;
  h_fy_ = zq.f_y;
  h_om_ = zq.omega;
  hs_fy_ = zs.f_y;
  hs_om_ = zs.omega;
  h_rope_ = zq.rope_load;
  base_fy_ = zt.f_y + oM * zs.f_y;
  base_om_ = zt.omega + oM * zs.omega;
  base_rope_ = zt.rope_load + oFa * zs.rope_load;
  pred_fy_ = base_fy_ + dM * h_fy_ + c_;
  pred_om_ = base_om_ + dM * h_om_;
  pred_rope_ = base_rope_ + dFa * h_rope_;
  // Envelopes (peak hold, decaying over kEnvelopeTime) of the predicted
  // oscillations: a model a few per cent off in frequency is off by up to
  // twice their amplitude a few cycles later, also at a zero crossing.
  const double dt = std::max(twin.t - env_t_, 0.0);
  env_t_ = twin.t;
  const double decay = std::exp(-dt / kEnvelopeTime);
  // The step's onset is known to one sample: its response one sample early
  // or late differs by about its change over one tick.  And the transient
  // (the step's response less the steady one) rings the modes the n-mode
  // model resolves least: kStepModelError of it -- of the lateral one's
  // envelope, growing as its phase is lost (kStepPhaseLoss).  All allowed as
  // model error.
  if (stepping_) {
    if (step_fresh_) {
      step_zq_ = zq;
      step_env_fy_ = step_env_om_ = 0.0;
    }
    step_fresh_ = false;
    step_env_fy_ = std::max(std::abs(zq.f_y - zs.f_y), step_env_fy_ * decay);
    step_env_om_ = std::max(std::abs(zq.omega - zs.omega), step_env_om_ * decay);
    const double rel = std::min(kStepModelErrorMax, kStepModelError + kStepPhaseLoss * std::max(twin.t - step_t_, 0.0));
    step_e_fy_ = std::hypot(dM * (zq.f_y - step_zq_.f_y), rel * dM * step_env_fy_);
    step_e_om_ = std::hypot(dM * (zq.omega - step_zq_.omega), rel * dM * step_env_om_);
    step_e_rope_ = std::hypot(dFa * (zq.rope_load - step_zq_.rope_load),
                              kStepModelError * dFa * (zq.rope_load - zs.rope_load));
    step_zq_ = zq;
  } else {
    step_e_fy_ = step_e_om_ = step_e_rope_ = 0.0;
  }
  const double yddot = twin.y_c_ddot + oM * s.y_c_ddot + dM * q.y_c_ddot;
  env_fy_ = std::max(std::abs(yddot), env_fy_ * decay);
  env_om_ = std::max(std::abs(pred_om_), env_om_ * decay);
  // lambda_0 = Fa + m (g - a) - m x_c'': the rigid part is exact, m x_c'' oscillates.
  const double xcdd = twin.x_c_ddot + oFa * s.x_c_ddot + dFa * q.x_c_ddot;
  env_rope_ = std::max(twin_.m * std::abs(xcdd), env_rope_ * decay);
  // A later jump of the winder's acceleration does the same, less (the
  // shaft was in a steady state before it); a jerk-limited profile hardly.
  start_rope_ *= std::exp(-dt / kStartTransientTime);
  jump_rope_ = std::max(jump_rope_ * std::exp(-dt / kJumpTransientTime),
                        kJumpTransientError * twin_.m * std::abs(twin.kin.a - last_a_) *
                            std::min(1.0, kJumpRefLength / twin.kin.l));
  last_a_ = twin.kin.a;
  tick_nis_ = 0.0;
  tick_dof_ = 0;
}

bool LoadEstimator::updateImu(double f_y, double omega) { return updateLateral(f_y, omega, 3u); }
bool LoadEstimator::updateImuAccel(double f_y) { return updateLateral(f_y, 0.0, 1u); }
bool LoadEstimator::updateImuRate(double omega) { return updateLateral(0.0, omega, 2u); }

bool LoadEstimator::updateLateral(double f_y, double omega, unsigned which) {
  const bool use_a = which & 1u, use_w = which & 2u;
  if ((use_a && !(std::isfinite(f_y) && std::abs(f_y) <= kMaxSpecificForce)) ||
      (use_w && !(std::isfinite(omega) && std::abs(omega) <= kMaxRate))) {
    ++counts_.implausible;
    return false;
  }
  if (use_a) mon_[kImuAccel].sample(t_, f_y);
  if (use_w) mon_[kImuRate].sample(t_, omega);
  const double eps = set_.model_error;
  const double ea = std::hypot(eps * (std::abs(pred_fy_ - c_) + env_fy_), step_e_fy_);
  const double ew = std::hypot(eps * env_om_, step_e_om_);
  double ra = set_.noise.imu_accel * set_.noise.imu_accel + ea * ea;
  double rw = set_.noise.imu_rate * set_.noise.imu_rate + ew * ew;
  // The lateral state (M, c), c the accelerometer's offset (on f_y only):
  // innovation, its covariance S = H P H^T + R (1 or 2 rows), in closed form.
  Eigen::Matrix2d H;  // rows f_y, omega; columns M, c
  H << (use_a ? h_fy_ : 0.0), (use_a ? 1.0 : 0.0), (use_w ? h_om_ : 0.0), 0.0;
  if (stepping_) {
    // While a load change's transient is followed, M is told from the
    // steady response only.  The transient rings the lightly damped modes
    // the n-mode model resolves least: a few per cent off in frequency, its
    // phase is lost within seconds (n = 25 against 100: 30-60 % of its
    // amplitude 5-20 s after the change), and read as information it
    // pulled M 7-35 sigma off on the trip that followed (and, at rest, told
    // M from the offset, which there are one number).  It stays in the
    // prediction; what it does with M's error is noise to the update.
    H(0, 0) = use_a ? hs_fy_ : 0.0;
    H(1, 0) = use_w ? hs_om_ : 0.0;
    const double da = h_fy_ - hs_fy_, dw = h_om_ - hs_om_;
    ra += da * da * Pl_(0, 0);
    rw += dw * dw * Pl_(0, 0);
  }
  Eigen::Vector2d nu(use_a ? f_y - pred_fy_ : 0.0, use_w ? omega - pred_om_ : 0.0);
  auto covariance = [&](const Eigen::Matrix2d& P) {
    Eigen::Matrix2d S = H * P * H.transpose();
    S(0, 0) += use_a ? ra : 1.0;
    S(1, 1) += use_w ? rw : 1.0;
    // an unused row has H = 0 and nu = 0: it adds nothing to K or the NIS
    return S;
  };
  Eigen::Matrix2d S = covariance(Pl_);
  const bool gated = (use_a && std::abs(nu(0)) > set_.gate_sigma * std::sqrt(S(0, 0))) ||
                     (use_w && std::abs(nu(1)) > set_.gate_sigma * std::sqrt(S(1, 1)));
  if (use_a) mon_[kImuAccel].gate(t_, gated);
  if (use_w) mon_[kImuRate].gate(t_, gated);
  if (gated) {
    if (run_m_ == 0) gate_t0_m_ = t_;
    if (++run_m_ < set_.gate_reset) {
      ++counts_.gated;
      return false;
    }
    // A load change: this sample was predicted without it; the next ones
    // are predicted with the change's step (and the re-opened loads).
    loadChange(gate_t0_m_);
    ++counts_.gated;
    return false;
  }
  run_m_ = 0;
  const Eigen::Vector2d dx = kalmanUpdate(Pl_, H, S, nu);
  M_ += dx(0);
  c_ += dx(1);
  {  // the short-memory estimate, same measurement
    const double dMF = MF_ - o_M_;
    const Eigen::Vector2d nuF(use_a ? f_y - (base_fy_ + dMF * h_fy_ + cF_) : 0.0,
                              use_w ? omega - (base_om_ + dMF * h_om_) : 0.0);
    const Eigen::Vector2d dxF = kalmanUpdate(PlF_, H, covariance(PlF_), nuF);
    MF_ += dxF(0);
    cF_ += dxF(1);
  }
  const int dof = (use_a ? 1 : 0) + (use_w ? 1 : 0);
  (void)dof;
  if (use_a) {
    mon_[kImuAccel].innovation(t_, nu(0));
    band(kImuAccel, nu(0), S(0, 0), ea);
  }
  if (use_w) {
    mon_[kImuRate].innovation(t_, nu(1));
    band(kImuRate, nu(1), S(1, 1), ew);
  }
  ++counts_.accepted;
  if (use_a) {
    last_upd_[kImuAccel] = t_;
    seen_[kImuAccel] = true;
  }
  if (use_w) {
    last_upd_[kImuRate] = t_;
    seen_[kImuRate] = true;
  }
  // The other channel's prediction follows the new moment.
  pred_fy_ += dx(0) * h_fy_ + dx(1);
  pred_om_ += dx(0) * h_om_;
  return true;
}

bool LoadEstimator::updateRopeLoad(double force) {
  if (!(std::isfinite(force) && std::abs(force) <= kMaxRopeLoad)) {
    ++counts_.implausible;
    return false;
  }
  mon_[kRope].sample(t_, force);
  // The oscillating part of lambda_0 (m x_c''): the rope's modes beyond n,
  // and their frequency error, scale with it.
  // (both larger on a short, stiff rope, whose modes beyond n are the least resolved)
  const double er = kRopeOscillationError * env_rope_ * std::min(1.0, kJumpRefLength / kin_.l);
  const double R = set_.noise.rope_load * set_.noise.rope_load + er * er + start_rope_ * start_rope_ +
                   jump_rope_ * jump_rope_ + step_e_rope_ * step_e_rope_;
  const double nu = force - pred_rope_;
  double S = h_rope_ * h_rope_ * PFa_ + R;
  const bool gated = std::abs(nu) > set_.gate_sigma * std::sqrt(S);
  mon_[kRope].gate(t_, gated);
  if (gated) {
    if (run_fa_ == 0) gate_t0_fa_ = t_;
    if (++run_fa_ < set_.gate_reset) {
      ++counts_.gated;
      return false;
    }
    loadChange(gate_t0_fa_);  // as in updateLateral: from the next sample on
    ++counts_.gated;
    return false;
  }
  run_fa_ = 0;
  const double K = PFa_ * h_rope_ / S;
  Fa_ += K * nu;
  PFa_ = std::max(PFa_ - K * K * S, 0.0);
  {  // the short-memory estimate, same measurement
    const double nuF = force - (base_rope_ + (FaF_ - o_Fa_) * h_rope_);
    const double SF = h_rope_ * h_rope_ * PFaF_ + R;
    const double KF = PFaF_ * h_rope_ / SF;
    FaF_ += KF * nuF;
    PFaF_ = std::max(PFaF_ - KF * KF * SF, 0.0);
  }
  mon_[kRope].innovation(t_, nu);
  band(kRope, nu, S, std::sqrt(std::max(R - set_.noise.rope_load * set_.noise.rope_load, 0.0)));
  ++counts_.accepted;
  last_upd_[kRope] = t_;
  seen_[kRope] = true;
  pred_rope_ += K * nu * h_rope_;
  return true;
}

}  // namespace hoist
