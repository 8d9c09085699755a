// hoist/load_estimator.hpp -- the twin sees the real shaft: the eccentric
// load's force Fa and moment M = Fa b estimated from a rope load cell and a
// cage IMU, with their covariance, the state they imply, and a model check.
// docs/estimation.md derives everything stated here and shows the figures.
//
// Sensor model (the model's frame: x down, theta > 0 turns the cage's downward
// axis toward +y; docs/model.md, "Frame and signs"):
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
// Model check (docs/estimation.md, "The model check").  Each channel's
// innovations are summed over blocks of band_block seconds
// (hoist/band_innovation.hpp): vibration above the model's band cancels,
// what the model carries adds; s^2 of each block is one dof of the windowed
// NIS over nis_window seconds.  MODEL_MISMATCH (WARNING) is evidence of a
// shaft that does not behave like its model:
//   * the window's NIS above its chi-square (1 - nis_alpha) quantile and
//     nis_margin dof, or
//   * a load estimate that drifts during a trip (the cage moving) by more than
//     drift_sigma times the spread the filter itself expects, or
//   * (constancy) the estimate over the last constancy_memory seconds (a
//     second filter with exponential forgetting, same measurements) away
//     from the whole history's by more than drift_sigma times the sigma of
//     their difference (PF - P for nested estimates): a load that seems to
//     change with depth is a model that is wrong with depth (weak preloads).
// The tests start after a warm-up of min_window_fill x nis_window.
// The other side -- a sensor quieter than its own noise (zeroed, stuck,
// held), or one whose samples the gate mostly rejects -- is judged per
// channel by hoist/sensor_monitor.hpp: LoadEstimate::fault_*, imu_quiet,
// rope_quiet (SENSOR_FAULT in the daemon), not by MODEL_MISMATCH.
// Per-sample gating rejects (and counts) an innovation beyond gate_sigma.
// Load changes: gate_reset rejections in a row, or a CUSUM on the blocks at
// rest (hoist/change_detector.hpp), on either channel, re-open both Fa and
// M (one load changed).  At rest the change is a step: a third solver
// (the unit load from rest at the change's onset) carries its transient for
// kStepFoldTime (60 s); followingLoadChange() says so.  The transient is in
// the prediction only: M is told from the steady response (its ringing's
// phase is not known well enough to learn from; docs/estimation.md).
// Physical bounds: LoadEstimate::plausible ([load] max_payload, max_offset
// and hoist/plausibility.hpp).
// Observability: the rope load alone gives Fa but not b; the IMU alone gives M
// (and so y_c, theta, lambda_1..4) but not Fa or b; both give Fa and b = M/Fa.
// Without a sensor the estimates stay at the configured load, their sigma
// grows with the random walk, and observed()/sensorsInUse() say so.
//
// Real time: every buffer and the three solvers are sized in the
// constructor; initialize(), advance(), update*() and finish() allocate
// nothing, a load change included (tests/model/no_alloc_test.cpp).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hoist/band_innovation.hpp"
#include "hoist/change_detector.hpp"
#include "hoist/fast_solver.hpp"
#include "hoist/plausibility.hpp"
#include "hoist/profile.hpp"
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
  /// Prior sigma of the accelerometer's constant offset on f_y ([sensors]
  /// imu_accel_offset_sigma) [m/s^2]; 0 declares it calibrated (the offset
  /// is then the one setAccelOffset() gave, 0 by default, and not estimated).
  /// Default 0.005 (about 0.5 mg): an uncalibrated industrial accelerometer.
  double accel_offset_sigma = 0.005;
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
  double moment = 0.0, sigma_moment = -1.0;  ///< M = Fa b [N m]; its sigma includes what the offset leaves unknown
  /// The accelerometer's offset on f_y, estimated jointly with M [m/s^2]
  /// (sigma 0: calibrated, imu_accel_offset_sigma = 0).
  double accel_offset = 0.0, sigma_accel_offset = 0.0;
  bool known_load = false;   ///< a declared known load is pinned (declareKnownLoad())
  double b = 0.0, sigma_b = -1.0;          ///< offset [m]; observed only with both sensors
  double x_c = 0.0, sigma_x_c = 0.0;       ///< the state the estimated load implies
  double y_c = 0.0, sigma_y_c = 0.0;
  double theta = 0.0, sigma_theta = 0.0;
  std::array<double, 5> lambda{}, sigma_lambda{};
  double theta_open = 0.0;                 ///< the open-loop twin's theta (configured load)
  double nis = 0.0;          ///< NIS of the band blocks that closed this tick (0 if none)
  double nis_window = 0.0;   ///< sum over the window
  int nis_dof = 0;           ///< blocks (one per channel and band_block) in the window
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
  /// Physical bounds ([load] max_payload, max_offset: ShaftParams::payloadLimit(),
  /// offsetLimit()) and the twin's plausibility bounds (hoist/plausibility.hpp,
  /// lateral limit 1 m) on the estimate and the state it implies.  false:
  /// the estimate must not be used (a forged or failed sensor, or a model far
  /// off), whatever its sigma says.  An observed load is judged 3 sigma
  /// generously: 0 <= Fa + 3 sigma_Fa (and Fa >= 0 unless sigma_Fa < 5 % of
  /// max_payload: an empty conveyance), Fa - 3 sigma_Fa <= max_payload,
  /// |M| - 3 sigma_M <= max_payload max_offset, |b| - 3 sigma_b <= max_offset.
  bool plausible = true;
  /// Why not plausible: "Fa < 0", "Fa > max_payload", "|M| > max_payload * max_offset",
  /// "|b| > max_offset", or the state's quantity ("y_c", "theta", "x_c",
  /// "lambda_k", "non-finite"); "" when plausible.  A static string.
  const char* implausible = "";
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

  /// The estimator's share of a shaft model: the shaft and its unit-load
  /// solvers.  Built off the real-time loop (it allocates) for swapModel().
  struct Model {
    ShaftParams twin;
    std::unique_ptr<FastSolver> sens, step;
  };
  /// Throws ParamError for bad parameters.
  static Model buildModel(const ShaftParams& twin);
  /// The twin now runs another model of the same shaft (an operator adopted
  /// a guide-rope preload): its solvers are swapped in, `m` receives the old
  /// ones (release them off the loop).  The load prior (twin.Fa, twin.b)
  /// stays the one given at construction.  Call restart() next: the loads,
  /// their covariance, the offset and the sensors seen carry over.
  /// Allocation-free.  Throws std::invalid_argument (nothing changed) for a
  /// model with another n or without solvers.
  void swapModel(Model& m);

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
  /// The operator's calibration: the load is (Fa, b) until model time
  /// `until_t`, so the data teach the accelerometer's offset.  Pins Fa and
  /// M = Fa b (sigma kKnownLoadRelSigma = 0.1 % of them, at least 1 N and
  /// 1 N m; no random walk) from now to until_t; afterwards they carry on
  /// from there as usual.  Throws std::invalid_argument for non-finite
  /// values or Fa < 0.  Allocation-free (the daemon calls it between ticks).
  void declareKnownLoad(double Fa, double b, double until_t);
  /// Ends a declared known load now (the loads keep their pinned values).
  void clearKnownLoad();
  bool knownLoad() const { return t_ < known_until_; }
  /// The accelerometer's offset learned so far and its sigma [m/s^2].
  double accelOffset() const { return c_; }
  double accelOffsetSigma() const;
  /// Start from a learned offset (a calibration kept across trips and
  /// restarts): used now and by every later initialize().  sigma >= 0
  /// (0: known exactly); with imu_accel_offset_sigma = 0 the offset is
  /// applied but held fixed.  Throws std::invalid_argument for bad values.
  void setAccelOffset(double value, double sigma);
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
  /// True while a load change's transient is followed (for kStepFoldTime =
  /// 60 s after a change at rest): the state the estimate implies is then
  /// the steady superposition plus the step's transient, and a forecast
  /// built from sensitivitySolver() alone omits the transient.
  bool followingLoadChange() const { return stepping_; }

 private:
  bool updateLateral(double f_y, double omega, unsigned which);
  /// A load change (CUSUM or gate_reset, either channel) that began at
  /// `onset`: re-opens Fa and M; at rest the step solver starts.
  void loadChange(double onset);
  /// The CUSUM of a channel at rest; true: a change.
  bool changeAtRest(ChangeDetector& c, double z);
  /// An accepted innovation of channel `ch` into its band block (NIS window, CUSUM).
  void band(int ch, double nu, double S, double e);
  /// Stop following a load change's transient (decayed, or a restart).
  void foldStep();
  void pushNis(double nis, int dof);
  bool moving() const;

  ShaftParams twin_;
  EstimatorSettings set_;
  std::unique_ptr<FastSolver> sens_;       // unit load (Fa = 1 N, M = 1 N m) since initialize(): dz/dFa, dz/dM
  // A load change at rest is a step: the ropes ring.  step_ is the unit load
  // applied as a step at the change's onset (started at rest), so the
  // prediction after it is exact superposition:
  //   z = z_twin + (o - c) dz/d(steady) + (x - o) dz/d(step),  o = the load before the change,
  // until the transient has decayed (kStepFoldTime), then folded back.
  std::unique_ptr<FastSolver> step_;
  bool stepping_ = false;
  double step_t_ = 0.0;                    // the step's onset
  double o_Fa_ = 0.0, o_M_ = 0.0;          // origin of the step part (= the configured load when not stepping)
  double sub_h_ = kDefaultMaxStep;         // the last advance()'s substep [s]
  bool step_fresh_ = false;                // no step sensitivity of the previous tick yet
  SensorValues step_zq_;                   // the step's sensitivities at the previous tick
  double step_e_fy_ = 0.0, step_e_om_ = 0.0, step_e_rope_ = 0.0;  // model error of the onset's one-sample uncertainty
  double gate_t0_fa_ = 0.0, gate_t0_m_ = 0.0;  // first gated sample of the current run
  double t_ = 0.0;
  Kinematics kin_;
  double Fa_c_ = 0.0, M_c_ = 0.0;          // the configured load (prior)
  double Fa_ = 0.0, PFa_ = 0.0;            // longitudinal filter: estimate and variance
  double M_ = 0.0;                         // lateral filter: M and the accelerometer's offset c,
  double c_ = 0.0;                         // with their 2x2 covariance Pl_ (M first)
  Eigen::Matrix2d Pl_ = Eigen::Matrix2d::Zero();
  double c0_ = 0.0, Pc0_ = 0.0;            // the offset's start: setAccelOffset() or the prior
  double known_until_ = -1e300;            // declareKnownLoad(): pinned until then
  double FaF_ = 0.0, PFaF_ = 0.0, MF_ = 0.0, cF_ = 0.0;  // the same with a short memory (constancy test)
  Eigen::Matrix2d PlF_ = Eigen::Matrix2d::Zero();
  double const_drift_ = 0.0;               // |short - whole| / its sigma, largest of Fa and M
  double base_fy_ = 0.0, base_om_ = 0.0, base_rope_ = 0.0;  // the open-loop twin's measurements
  CageResponse twin_resp_;                 // the twin's response at this tick
  double pred_fy_ = 0.0, pred_om_ = 0.0, pred_rope_ = 0.0;  // predictions (prior)
  double h_fy_ = 0.0, h_om_ = 0.0, h_rope_ = 0.0;           // sensitivities of the measurements
  double hs_fy_ = 0.0, hs_om_ = 0.0;  // their steady parts (differ from h_fy_, h_om_ while a step's transient is followed)
  double step_env_fy_ = 0.0, step_env_om_ = 0.0;  // envelopes of the step's lateral transient (decay as env_*)
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
  PlausibilityBounds bounds_;              // the twin's, lateral limit 1 m
  LoadEstimate est_;
  EstimatorCounters counts_;
  /// Sets est_.plausible / implausible from est_ (after the state is filled).
  void judgePlausibility();
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

/// A load declared known over [t0, t1) (hoist-estimate --known-load T0,T1,FA,B).
struct KnownLoadInterval {
  double t0 = 0.0, t1 = 0.0, Fa = 0.0, b = 0.0;
};
/// The calibration hoist-estimate runs with: known-load intervals (declared
/// at their first sample: LoadEstimator::declareKnownLoad) and a learned
/// offset to start from (--offset-in: setAccelOffset).  The learned offset
/// comes out in every LoadEstimate (accel_offset, sigma_accel_offset).
struct RecordedCalibration {
  std::vector<KnownLoadInterval> known;
  bool has_offset = false;
  double offset = 0.0, offset_sigma = 0.0;
};
/// estimateRecorded with a calibration.
void estimateRecorded(const ShaftParams& twin, const EstimatorSettings& settings, double max_step,
                      const std::vector<MeasurementSample>& samples, const RecordedCalibration& cal,
                      const std::function<void(const LoadEstimate&, const EstimatorCounters&)>& sink,
                      const std::function<void(double)>& progress = {});

}  // namespace hoist
