// hoist/load_estimator.hpp -- the twin sees the real shaft: the eccentric
// load's force Fa and moment M = Fa b estimated from a rope load cell and a
// cage IMU, with their covariance, the state they imply, and a model check.
// docs/estimation.md derives everything stated here and shows the figures.
//
// Sensor model (the model's frame: x down, theta > 0 turns the cage's downward
// axis toward +y; ../shared/spec/INTERFACES.md):
//   f_y       = y_c'' + (g - a) theta     specific force along the cage's lateral
//                                        axis at its centre [m/s^2]
//   omega     = theta'                    tilt rate [rad/s]
//   rope_load = lambda_0                  hoisting-rope force at the cage [N]
// each with white noise of a known standard deviation per sample.
//
// Why the problem is linear.  For given kinematics l(t), v(t), a(t) the
// reduced model (Eq. 15, the twin's own n modes with the static correction)
// is linear in its loads.  The eccentric load enters the longitudinal
// subsystem as the force Fa on x_c and the lateral/torsional subsystem as the
// moment M on theta; the subsystems share nothing else.  So every output of
// the twin run with the configured load (Fa_c, M_c) differs from the output
// the true load would give by
//     z(Fa, M) = z_twin + (Fa - Fa_c) dz/dFa + (M - M_c) dz/dM,
// where the derivatives are the response of the same solver driven by the
// eccentric load alone (Forcing::LoadOnly with Fa = 1 N, b = 1 m), stepped
// with exactly the twin's substeps.  This is exact (to round-off) whenever
// the load was constant since the twin's initialization (the static start
// included), which is what the physics says during a trip.
//
// The filter: the augmented Kalman filter (Lourens et al., MSSP 2012) with the
// structural state's own process noise set to zero.  Its augmented state is
// [structural state; Fa; M] with a random walk on Fa and M; with no other
// process noise and the static start, the structural state is the linear
// function  x = x_twin + (Fa - Fa_c) s_Fa + (M - M_c) s_M  of the two load
// states, so its covariance is rank two and is carried exactly by the
// covariance of (Fa, M) and the sensitivities s.  Because the subsystems are
// decoupled this splits into two scalar filters:
//   longitudinal: Fa from rope_load,   H = d lambda_0 / dFa
//   lateral:      M  from (f_y, omega), H = (d f_y / dM, d omega / dM)
// Cost per tick: one extra solver step (the sensitivities) and O(1).
// What this neglects: the dynamic transient of a load that changes while the
// filter runs (a step of the random walk is treated as if the structure
// were already at its new equilibrium).  The load changes only at rest, where
// the transient decays; the model error term below absorbs it.
//
// Model uncertainty: the measurement variance of each channel is the sensor's
// plus (model_error * dynamic part of the predicted value)^2, so that a model
// that is right to about model_error (the n-mode twin against the continuum is
// within 1 %) is not reported as wrong.
//
// Model check.  NIS_k = nu^T S^-1 nu of every accepted update, summed over a
// sliding window of nis_window seconds, is chi-square with dof = the number
// of scalar measurements in the window when the model is right.  MODEL_MISMATCH
// (WARNING) is evidence of a shaft that does not behave like its model:
//   * the window's NIS above its chi-square (1 - nis_alpha) quantile, or
//   * a load estimate that drifts during a trip (the cage moving) by more than
//     drift_sigma times the spread the filter itself expects, or
//   * (constancy) the estimate over the last constancy_memory seconds (a
//     second filter with exponential forgetting, same measurements) away
//     from the whole history's by more than drift_sigma times the sigma of
//     their difference (PF - P for nested estimates): a load that seems to
//     change with depth is a model that is wrong with depth (weak preloads).
// Per-sample gating rejects (and counts) an innovation beyond gate_sigma;
// gate_reset consecutive rejections are a load change, not spikes: the
// load's covariance is re-opened to its initial value.
//
// Observability: the rope load alone gives Fa but not b; the IMU alone gives M
// (and so y_c, theta, lambda_1..4) but not Fa or b; both give Fa and b = M/Fa.
// Without a sensor the estimates stay at the configured load, their sigma
// grows with the random walk, and observed()/sensorsInUse() say so.
//
// Real time: every buffer is sized in the constructor; initialize(),
// advance(), update*() and finish() allocate nothing (tested).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hoist/band_innovation.hpp"
#include "hoist/change_detector.hpp"
#include "hoist/fast_solver.hpp"
#include "hoist/sensor_monitor.hpp"

namespace hoist {

/// Standard deviation per sample of each sensor's white noise ([sensors]).
struct SensorNoise {
  double imu_accel = 0.002;  ///< f_y [m/s^2]
  double imu_rate = 1.0e-4;  ///< omega [rad/s]
  double rope_load = 20.0;   ///< rope_load [N]
};

/// The filter's tuning ([estimator]); docs/estimation.md says how to choose it.
struct EstimatorSettings {
  SensorNoise noise;
  double fa_walk = 5.0;         ///< random walk of Fa at rest [N/sqrt(s)]
  double moment_walk = 5.0;     ///< random walk of M at rest [N m/sqrt(s)]
  double moving_walk_scale = 0.01;  ///< factor on both walks while the cage moves (loads do not change then)
  double rest_speed = 0.01;     ///< |v| at or below this, with |a| <= rest_speed, is at rest [m/s]
  double fa_sigma0 = 5000.0;    ///< initial sigma of Fa about the configured load [N]
  double moment_sigma0 = 5000.0;  ///< initial sigma of M about the configured moment [N m]
  double model_error = 0.01;    ///< relative model uncertainty on the predicted dynamic part
  double gate_sigma = 6.0;      ///< per-sample innovation gate [sigma]
  int gate_reset = 10;          ///< consecutive gated samples that mean a load change
  double nis_window = 5.0;      ///< NIS window [s]
  double nis_alpha = 1.0e-3;    ///< MODEL_MISMATCH when the window's NIS exceeds its 1 - alpha quantile ...
  double nis_margin = 1.5;      ///< ... and nis_margin times its degrees of freedom
  double drift_sigma = 3.5;     ///< MODEL_MISMATCH when a load estimate drifts more during a trip [sigma]
  double constancy_memory = 10.0;  ///< memory of the short-memory load estimates of the constancy test [s]
  double min_window_fill = 0.5; ///< the NIS test needs the window at least this full (fraction of nis_window)
  int max_rate = 1000;          ///< largest update rate the NIS window is sized for [Hz]
  double sensor_timeout = 0.5;  ///< a sensor not updated for this long is not "in use" [s]
  // Sensor health and the learned noise (hoist/sensor_monitor.hpp).
  double model_band = 0.05;     ///< low-pass time constant splitting the model's band from the noise [s]
  double noise_memory = 2.0;    ///< memory of the learned high-frequency noise variance [s]
  double quiet_ratio = 0.25;    ///< a channel whose high-pass sigma is below quiet_ratio x its noise is quiet
  double quiet_memory = 1.0;    ///< memory of the quiet test [s]
  double stuck_time = 1.0;      ///< the same value for this long is a stuck channel [s]
  double noisy_factor = 5.0;    ///< a learned noise above noisy_factor x the datasheet's is a fault
  double band_block = 0.2;      ///< block of the band-limited innovations (NIS test, CUSUM) [s]
  // Load changes at rest (hoist/change_detector.hpp): CUSUM on the band-limited innovations.
  double change_drift = 1.0;    ///< CUSUM reference k [sigma per block]
  double change_threshold = 6.0;  ///< CUSUM decision level h [sigma]
  double change_holdoff = 2.0;  ///< the CUSUM runs once the cage has been at rest this long [s]

  /// Throws std::invalid_argument naming the first bad value (its [estimator]/[sensors] key).
  void validate() const;
};

/// Sensors of the estimate (bit mask).
enum SensorBits : unsigned { kSensorImuAccel = 1u, kSensorImuRate = 2u, kSensorRopeLoad = 4u };

/// The estimate after finish().  Fa and M always carry the filter's sigma
/// (the prior's, growing with the random walk, until a sensor observes them:
/// fa_observed, moment_observed); b is observed only with both, else b = 0
/// and sigma_b = -1.
struct LoadEstimate {
  double t = 0.0;
  Kinematics kin;
  double Fa = 0.0, sigma_Fa = -1.0;        ///< eccentric force [N]
  double moment = 0.0, sigma_moment = -1.0;  ///< M = Fa b [N m]
  double b = 0.0, sigma_b = -1.0;          ///< offset [m]; observed only with both sensors
  double x_c = 0.0, sigma_x_c = 0.0;       ///< the state the estimated load implies
  double y_c = 0.0, sigma_y_c = 0.0;
  double theta = 0.0, sigma_theta = 0.0;
  std::array<double, 5> lambda{}, sigma_lambda{};
  double theta_open = 0.0;                 ///< the open-loop twin's theta (configured load)
  double nis = 0.0;          ///< NIS of this tick's updates (0 if none)
  double nis_window = 0.0;   ///< sum over the window
  int nis_dof = 0;           ///< scalar measurements in the window
  double nis_lower = 0.0, nis_upper = 0.0;  ///< the window's 95 % two-sided chi-square bounds
  double nis_bound = 0.0;    ///< the MODEL_MISMATCH bound: max(1 - nis_alpha quantile, nis_margin dof)
  double drift = 0.0;        ///< largest load drift this trip [its sigma]
  bool mismatch = false;     ///< MODEL_MISMATCH condition
  bool nis_exceeded = false; ///< ... because of the NIS window
  bool drift_exceeded = false;  ///< ... because of a drifting load
  unsigned sensors = 0;      ///< SensorBits updated within their timeout
  bool fa_observed = false, moment_observed = false;
  // Sensor health (hoist/sensor_monitor.hpp): SensorFaultBits per channel;
  // sensorFaultReason() names them.  A faulty channel's samples are still
  // applied (the daemon decides what to do: SENSOR_FAULT).
  unsigned fault_imu_accel = 0, fault_imu_rate = 0, fault_rope_load = 0;
  unsigned faulty = 0;       ///< SensorBits of the channels with any fault
  bool imu_quiet = false;    ///< f_y or omega quiet or stuck: quieter than its own noise (the NIS's lower side)
  bool rope_quiet = false;   ///< rope_load quiet or stuck
  /// The noise sigma each channel is weighted with: max(datasheet, learned
  /// from the high-frequency part of its innovations) [m/s^2, rad/s, N].
  double noise_imu_accel = 0.0, noise_imu_rate = 0.0, noise_rope_load = 0.0;
  // Load changes (one event for Fa and M, whichever channel saw it).
  double change_t = -1.0;    ///< time of the last load change (-1: none since initialize())
  double change_Fa = 0.0;    ///< its size so far: Fa now - Fa before it [N]
  double change_moment = 0.0;  ///< M now - M before it [N m]
  double change_level = 0.0; ///< the larger CUSUM statistic / its threshold (1 = a change)
};

/// Counts since initialize().
struct EstimatorCounters {
  std::int64_t accepted = 0;   ///< updates applied (per sensor message)
  std::int64_t gated = 0;      ///< samples rejected by the innovation gate
  std::int64_t load_changes = 0;  ///< load changes: CUSUM at rest, or gate_reset rejections in a row
  std::int64_t implausible = 0;   ///< non-finite or out-of-range samples refused
};

/// What the sensors read when the cage moves as `r` (the sensor model above,
/// without noise): the one definition, used by the estimator's predictions,
/// hoist-sim --write-measurements and the tests.
struct SensorValues {
  double f_y = 0.0;        ///< y_c'' + (g - a) theta [m/s^2]
  double omega = 0.0;      ///< theta' [rad/s]
  double rope_load = 0.0;  ///< lambda_0 [N]
};
SensorValues sensorModel(const CageResponse& r, double g);

/// One row of recorded data: the winder's kinematics and what the sensors
/// read then (`present`: SensorBits of the columns that have a value).
struct MeasurementSample {
  double t = 0.0;
  Kinematics k;
  SensorValues z;
  unsigned present = 0;
};

/// Chi-square quantile (Wilson-Hilferty; relative error < 1e-3 for dof >= 10).
double chiSquareQuantile(double p, double dof);

class LoadEstimator {
 public:
  /// `twin` is the shaft model the twin runs (its [load] is the prior).
  /// Throws std::invalid_argument for bad settings.
  LoadEstimator(const ShaftParams& twin, const EstimatorSettings& settings);

  /// Start (again) at (t0, k0), the twin's initialization: the sensitivity
  /// solver starts as the twin does (its params().initial), the loads return
  /// to the prior.  Call after the twin's initialize().
  void initialize(double t0, const Kinematics& k0);
  /// The twin was re-initialized (a new winder stream, a model fault): the
  /// sensitivities start again with it, the NIS window and the trip's drift
  /// start afresh, but the load estimates and their covariance, the sensors
  /// seen and the counts stay (the load did not change).
  void restart(double t0, const Kinematics& k0);
  /// Step the sensitivities to (t1, k1) in `substeps` equal substeps with
  /// hoist::interpolate -- exactly the twin's substeps -- and add the random
  /// walk's variance.  Throws std::domain_error as the solver does.
  void advance(double t1, const Kinematics& k1, int substeps);
  /// Predicted measurements for the twin's response at the same instant.
  /// Call once per tick after advance(), before the updates.
  void predict(const CageResponse& twin);
  /// Sensor updates (any subset, each at most once per tick).  false: refused
  /// (implausible) or gated; counted.
  bool updateImu(double f_y, double omega);
  bool updateImuAccel(double f_y);
  bool updateImuRate(double omega);
  bool updateRopeLoad(double force);
  /// The caller marks this tick's samples as no evidence about the model
  /// (hoist-twind: a tick it flags degraded, e.g. its loop fell behind): the
  /// updates still apply, but the next finish() keeps their NIS out of the
  /// window (est.nis still reports it).  Applies to one tick only.
  void excludeTickFromModelCheck() { skip_nis_ = true; }
  /// Close the tick: NIS window, mismatch test, the estimate.
  const LoadEstimate& finish();

  const LoadEstimate& estimate() const { return est_; }
  const EstimatorCounters& counters() const { return counts_; }
  const EstimatorSettings& settings() const { return set_; }
  /// The sensitivity response (per N of Fa and per N m of M) at the last advance().
  const CageResponse& sensitivity() const { return sens_->response(); }
  /// The solver behind sensitivity() (Forcing::LoadOnly, Fa = 1 N, M = 1 N m),
  /// stepped exactly as the twin: its saved state turns the twin's state into
  /// the estimate's with hoist::addLoadResponse (forecasts from the estimate).
  const FastSolver& sensitivitySolver() const { return *sens_; }

 private:
  bool updateLateral(double f_y, double omega, unsigned which);
  /// A load change (CUSUM or gate_reset, either channel): re-opens Fa and M.
  void loadChange();
  /// The CUSUM of a channel at rest; true: a change.
  bool changeAtRest(ChangeDetector& c, double z);
  /// An accepted innovation of channel `ch` into its band block (NIS window, CUSUM).
  void band(int ch, double nu, double S, double e);
  void pushNis(double nis, int dof);
  bool moving() const;

  ShaftParams twin_;
  EstimatorSettings set_;
  std::unique_ptr<FastSolver> sens_;       // unit load (Fa = 1 N, M = 1 N m) since initialize(): dz/dFa, dz/dM
  double t_ = 0.0;
  Kinematics kin_;
  double Fa_c_ = 0.0, M_c_ = 0.0;          // the configured load (prior)
  double Fa_ = 0.0, PFa_ = 0.0;            // longitudinal filter: estimate and variance
  double M_ = 0.0, PM_ = 0.0;              // lateral filter
  double FaF_ = 0.0, PFaF_ = 0.0, MF_ = 0.0, PMF_ = 0.0;  // the same with a short memory (constancy test)
  double const_drift_ = 0.0;               // |short - whole| / its sigma, largest of Fa and M
  double base_fy_ = 0.0, base_om_ = 0.0, base_rope_ = 0.0;  // the open-loop twin's measurements
  CageResponse twin_resp_;                 // the twin's response at this tick
  double pred_fy_ = 0.0, pred_om_ = 0.0, pred_rope_ = 0.0;  // predictions (prior)
  double h_fy_ = 0.0, h_om_ = 0.0, h_rope_ = 0.0;           // sensitivities of the measurements
  int run_fa_ = 0, run_m_ = 0;             // consecutive gated samples
  double env_fy_ = 0.0, env_om_ = 0.0, env_rope_ = 0.0, env_t_ = 0.0;
  double start_rope_ = 0.0, jump_rope_ = 0.0;  // rope-load model error of the start transient, of a jump of a [N]
  double last_a_ = 0.0;                    // a at the last prediction  // oscillation envelopes (model error)
  double tick_nis_ = 0.0;
  int tick_dof_ = 0;
  bool skip_nis_ = false;                  // excludeTickFromModelCheck() for this tick
  double last_upd_[3] = {-1e300, -1e300, -1e300};  // model time of each sensor's last accepted update
  bool seen_[3] = {false, false, false};
  // sliding NIS window (ring buffer; sized once)
  std::vector<double> ring_t_, ring_nis_;
  std::vector<int> ring_dof_;
  std::size_t head_ = 0, count_ = 0;
  double win_nis_ = 0.0;
  int win_dof_ = 0;
  double first_t_ = 0.0;                   // time of the first update
  bool have_update_ = false;
  // drift during a trip
  bool was_moving_ = false;
  bool trip_ref_warm_ = false;             // the trip's reference was taken after the warm-up
  double trip_Fa0_ = 0.0, trip_PFa0_ = 0.0, trip_M0_ = 0.0, trip_PM0_ = 0.0, trip_QFa_ = 0.0, trip_QM_ = 0.0;
  double trip_drift_ = 0.0;
  bool nis_flag_ = false, drift_flag_ = false;  // the two MODEL_MISMATCH conditions
  SensorMonitor mon_[3];                   // per channel (kImuAccel, kImuRate, kRope)
  BandInnovation band_[3];                 // per channel: innovations summed over band_block
  ChangeDetector cusum_fa_, cusum_m_;      // load changes at rest
  double rest_since_ = 0.0;                // time the cage came to rest
  double change_t_ = -1.0, change_Fa0_ = 0.0, change_M0_ = 0.0;  // the last load change and the loads before it
  LoadEstimate est_;
  EstimatorCounters counts_;
};

/// The offline estimator (hoist-estimate), the same sequence the daemon runs
/// per input with --clock input: the twin (FastSolver, `twin` params) starts
/// at the first sample as `twin.initial` says, then for every further sample
/// both the twin and the sensitivities take substepCount(h, max_step) substeps
/// (hoist::interpolate), the estimator predicts, applies the sample's sensors
/// and finishes.  `sink` gets the estimate at every sample (the first one
/// included); `progress` (optional) the fraction done about 100 times.
void estimateRecorded(const ShaftParams& twin, const EstimatorSettings& settings, double max_step,
                      const std::vector<MeasurementSample>& samples,
                      const std::function<void(const LoadEstimate&, const EstimatorCounters&)>& sink,
                      const std::function<void(double)>& progress = {});

}  // namespace hoist
