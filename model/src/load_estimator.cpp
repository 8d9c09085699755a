#include "hoist/load_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hoist {

namespace {

constexpr double kMaxSpecificForce = 100.0;  // |f_y| [m/s^2] a cage IMU can report
constexpr double kMaxRate = 20.0;            // |omega| [rad/s]
constexpr double kMaxRopeLoad = 1.0e8;       // |rope_load| [N]
constexpr int kImuAccel = 0, kImuRate = 1, kRope = 2;
// Time comparisons tolerate this much [s]: the same data timed by the CSV's t
// (hoist-estimate) or by utime differences (the daemon) differ by an ulp.
constexpr double kTimeEps = 1e-9;
constexpr double kEnvelopeTime = 3.0;        // memory of the oscillation envelopes [s]
constexpr double kStartTransientError = 0.1;  // rope-load model error after a start at a != 0, per N of m a
constexpr double kJumpTransientError = 0.1;   // the same after a jump of a later on ...
constexpr double kJumpTransientTime = 2.5;    // ... decaying faster (the shaft was steady before),
constexpr double kRopeOscillationError = 0.07;  // the rope's oscillation, per N of m x_c'' (frequency error)
constexpr double kJumpRefLength = 50.0;       // ... and less on a longer, softer rope (x 50 m / l)
// (calibrated: n = 25 against n = 100 and 200, tests/model/load_estimator_test.cpp)
constexpr double kStartTransientTime = 5.0;   // its decay time [s]

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
  ShaftParams unit = twin_;
  unit.Fa = 1.0;
  unit.b = 1.0;
  sens_ = std::make_unique<FastSolver>(std::make_shared<const ShaftModel>(unit), Forcing::LoadOnly);
  Fa_c_ = twin_.Fa;
  M_c_ = twin_.Fa * twin_.b;
  const auto cap = static_cast<std::size_t>(std::ceil(set_.nis_window * set_.max_rate)) + 2;
  ring_t_.assign(cap, 0.0);
  ring_nis_.assign(cap, 0.0);
  ring_dof_.assign(cap, 0);
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
  PM_ = set_.moment_sigma0 * set_.moment_sigma0;
  PFaF_ = PFa_;
  PMF_ = PM_;
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
  counts_ = {};
  est_ = {};
  twin_resp_ = sens_->response();
  predict(twin_resp_);
}

void LoadEstimator::restart(double t0, const Kinematics& k0) {
  const double Fa = Fa_, PFa = PFa_, M = M_, PM = PM_, FaF = FaF_, PFaF = PFaF_, MF = MF_, PMF = PMF_;
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
  PM_ = PM;
  FaF_ = FaF;
  PFaF_ = PFaF;
  MF_ = MF;
  PMF_ = PMF;
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
  const double qfa = set_.fa_walk * scale, qm = set_.moment_walk * scale;
  PFa_ += qfa * qfa * h;
  PM_ += qm * qm * h;
  // The short-memory twins forget with time constant constancy_memory.
  const double forget = std::exp(h / set_.constancy_memory);
  PFaF_ = PFaF_ * forget + qfa * qfa * h;
  PMF_ = PMF_ * forget + qm * qm * h;
  trip_QFa_ += qfa * qfa * h;
  trip_QM_ += qm * qm * h;
}

void LoadEstimator::predict(const CageResponse& twin) {
  twin_resp_ = twin;
  const CageResponse& s = sens_->response();
  const double dFa = Fa_ - Fa_c_, dM = M_ - M_c_;
  // The sensor model is linear: the sensitivities read through it (the
  // sensitivity solver's own a-term is the twin's: same kinematics).
  const SensorValues zt = sensorModel(twin, twin_.g), zs = sensorModel(s, twin_.g);
  h_fy_ = zs.f_y;
  h_om_ = zs.omega;
  h_rope_ = zs.rope_load;
  base_fy_ = zt.f_y;
  base_om_ = zt.omega;
  base_rope_ = zt.rope_load;
  pred_fy_ = zt.f_y + dM * h_fy_;
  pred_om_ = zt.omega + dM * h_om_;
  pred_rope_ = zt.rope_load + dFa * h_rope_;
  // Envelopes (peak hold, decaying over kEnvelopeTime) of the predicted
  // oscillations: a model a few per cent off in frequency is off by up to
  // twice their amplitude a few cycles later, also at a zero crossing.
  const double dt = std::max(twin.t - env_t_, 0.0);
  env_t_ = twin.t;
  const double decay = std::exp(-dt / kEnvelopeTime);
  const double yddot = twin.y_c_ddot + dM * s.y_c_ddot;
  env_fy_ = std::max(std::abs(yddot), env_fy_ * decay);
  env_om_ = std::max(std::abs(pred_om_), env_om_ * decay);
  // lambda_0 = Fa + m (g - a) - m x_c'': the rigid part is exact, m x_c'' oscillates.
  const double xcdd = twin.x_c_ddot + dFa * s.x_c_ddot;
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
  const double ea = eps * (std::abs(pred_fy_) + env_fy_), ew = eps * env_om_;
  const double ra = set_.noise.imu_accel * set_.noise.imu_accel + ea * ea;
  const double rw = set_.noise.imu_rate * set_.noise.imu_rate + ew * ew;
  // Innovation, its covariance S = H P H^T + R (1 or 2 rows), in closed form.
  Eigen::Vector2d H(use_a ? h_fy_ : 0.0, use_w ? h_om_ : 0.0);
  Eigen::Vector2d nu(use_a ? f_y - pred_fy_ : 0.0, use_w ? omega - pred_om_ : 0.0);
  auto covariance = [&](double P) {
    Eigen::Matrix2d S = P * H * H.transpose();
    S(0, 0) += use_a ? ra : 1.0;
    S(1, 1) += use_w ? rw : 1.0;
    // an unused row has H = 0 and nu = 0: it adds nothing to K or the NIS
    return S;
  };
  Eigen::Matrix2d S = covariance(PM_);
  const bool gated = (use_a && std::abs(nu(0)) > set_.gate_sigma * std::sqrt(S(0, 0))) ||
                     (use_w && std::abs(nu(1)) > set_.gate_sigma * std::sqrt(S(1, 1)));
  if (gated) {
    if (++run_m_ < set_.gate_reset) {
      ++counts_.gated;
      return false;
    }
    loadChange();
    S = covariance(PM_);
  }
  run_m_ = 0;
  const Eigen::Matrix2d Si = S.inverse();
  const Eigen::RowVector2d K = PM_ * H.transpose() * Si;
  M_ += K * nu;
  PM_ = std::max(PM_ - (K * S * K.transpose())(0, 0), 0.0);
  {  // the short-memory estimate, same measurement
    const double dMF = MF_ - M_c_;
    const Eigen::Vector2d nuF(use_a ? f_y - (base_fy_ + dMF * h_fy_) : 0.0,
                              use_w ? omega - (base_om_ + dMF * h_om_) : 0.0);
    const Eigen::Matrix2d SF = covariance(PMF_);
    const Eigen::RowVector2d KF = PMF_ * H.transpose() * SF.inverse();
    MF_ += KF * nuF;
    PMF_ = std::max(PMF_ - (KF * SF * KF.transpose())(0, 0), 0.0);
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
  const double dM = K * nu;
  pred_fy_ += dM * h_fy_;
  pred_om_ += dM * h_om_;
  return true;
}

void LoadEstimator::band(int ch, double nu, double S, double e) {
  if (!band_[ch].add(t_, nu, S, e)) return;
  const double s = band_[ch].statistic();
  tick_nis_ += s * s;
  tick_dof_ += 1;
  // f_y carries the moment's evidence at rest (the static tilt); omega only its transient.
  if (ch == kRope ? changeAtRest(cusum_fa_, s) : ch == kImuAccel && changeAtRest(cusum_m_, s)) loadChange();
}

bool LoadEstimator::changeAtRest(ChangeDetector& c, double z) {
  if (moving() || t_ - rest_since_ + kTimeEps < set_.change_holdoff) return false;
  return c.add(z);
}

void LoadEstimator::loadChange() {
  // One load changed: both its force and its moment re-open, whichever
  // channel saw it (the rope load sees Fa at once, f_y the moment slowly).
  change_t_ = t_;
  change_Fa0_ = Fa_;
  change_M0_ = M_;
  PFa_ = std::max(PFa_, set_.fa_sigma0 * set_.fa_sigma0);
  PM_ = std::max(PM_, set_.moment_sigma0 * set_.moment_sigma0);
  FaF_ = Fa_;
  PFaF_ = PFa_;
  MF_ = M_;
  PMF_ = PM_;
  run_fa_ = run_m_ = 0;
  cusum_fa_.reset();
  cusum_m_.reset();
  ++counts_.load_changes;
  // A load cannot change while the cage moves: a change then is evidence of mismatch.
  if (moving()) trip_drift_ = std::max(trip_drift_, set_.drift_sigma + 1.0);
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
                   jump_rope_ * jump_rope_;
  const double nu = force - pred_rope_;
  double S = h_rope_ * h_rope_ * PFa_ + R;
  if (std::abs(nu) > set_.gate_sigma * std::sqrt(S)) {
    if (++run_fa_ < set_.gate_reset) {
      ++counts_.gated;
      return false;
    }
    loadChange();
    S = h_rope_ * h_rope_ * PFa_ + R;
  }
  run_fa_ = 0;
  const double K = PFa_ * h_rope_ / S;
  Fa_ += K * nu;
  PFa_ = std::max(PFa_ - K * K * S, 0.0);
  {  // the short-memory estimate, same measurement
    const double nuF = force - (base_rope_ + (FaF_ - Fa_c_) * h_rope_);
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
  // A tick the daemon flagged degraded stays out of the model check
  // (excludeTickFromModelCheck); its updates still applied.
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
    trip_PM0_ = PM_;
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
      trip_drift_ = std::max(trip_drift_, drift(M_, trip_M0_, PM_, trip_PM0_, trip_QM_));
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
    if (seen_[kImuAccel] || seen_[kImuRate]) c = std::max(c, gap(MF_, M_, PMF_, PM_));
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

  const double sFa = std::sqrt(PFa_), sM = std::sqrt(PM_);
  e.Fa = Fa_;
  e.sigma_Fa = sFa;
  e.moment = M_;
  e.sigma_moment = sM;
  if (e.fa_observed && e.moment_observed && std::abs(Fa_) > 3.0 * sFa) {
    e.b = M_ / Fa_;
    e.sigma_b = std::sqrt(PM_ + e.b * e.b * PFa_) / std::abs(Fa_);
  } else {
    e.b = 0.0;
    e.sigma_b = -1.0;
  }

  // The state the estimated load implies, and its sigma (load + model error).
  const CageResponse& tw = twin_resp_;
  const CageResponse& s = sens_->response();
  const double dFa = Fa_ - Fa_c_, dM = M_ - M_c_, eps = set_.model_error;
  auto lateral = [&](double open, double sens, double& value, double& sigma) {
    value = open + dM * sens;
    sigma = std::hypot(sens * sM, eps * value);
  };
  e.x_c = tw.x_c + dFa * s.x_c;
  e.sigma_x_c = std::hypot(s.x_c * sFa, eps * e.x_c);
  lateral(tw.y_c, s.y_c, e.y_c, e.sigma_y_c);
  lateral(tw.theta, s.theta, e.theta, e.sigma_theta);
  e.lambda[0] = tw.lambda[0] + dFa * s.lambda[0];
  e.sigma_lambda[0] = std::hypot(s.lambda[0] * sFa, eps * (e.lambda[0] - (twin_.m * twin_.g + Fa_)));
  for (int i = 1; i < 5; ++i) lateral(tw.lambda[i], s.lambda[i], e.lambda[i], e.sigma_lambda[i]);
  e.theta_open = tw.theta;
  return e;
}

}  // namespace hoist
