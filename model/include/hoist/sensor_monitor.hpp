// hoist/sensor_monitor.hpp -- one sensor channel's health, judged from its own
// samples: the noise it really carries, and whether it is quieter than any
// real sensor of its datasheet can be (flat, zeroed, stuck).
//
// Who calls it: hoist::LoadEstimator, one monitor per channel (f_y, omega,
// rope_load), on every finite sample and every accepted innovation.  O(1),
// no allocation (the real-time step path).
//
// Why.  The estimator's model check compares innovations with their
// predicted spread.  A real IMU also carries vibration no n-mode model has
// (higher rope modes, the cage's structure, sleeve impacts: 15-50 Hz and
// more); that content is *noise* to the model, and only the data say how
// much there is.  So the monitor splits each signal at the model's band
// with a first-order low-pass (time constant lp_time, 0.05 s: 3 Hz):
//   hp_k = x_k - lp_{k-1},  var(hp) = sigma^2 2 / (2 - alpha) for white noise
//   (alpha = 1 - exp(-dt / lp_time)); the estimate is corrected by (2 - alpha) / 2.
//   The estimator weights a channel with max(datasheet^2 + model error^2,
//   learnedVariance()): the learned part already holds the model error's
//   high-frequency share, so the two are not added.
// * noise: the high-pass part of the *innovations* (the model's prediction
//   removed), averaged over noise_memory (2 s, exponential), is the
//   channel's noise variance as the data show it (learnedVariance()).  The
//   datasheet is a floor: a sensor is never believed to be better than its
//   specification.
// * quiet: the high-pass part of the *raw samples* (the signal itself adds
//   to it, never subtracts) averaged over quiet_memory (1 s) below
//   (quiet_ratio sigma)^2: no real sensor of that datasheet reads so
//   smoothly.  A zeroed, stuck or held stream.  Raised within
//   quiet_memory ln(1 / quiet_ratio^2) (2.8 s at the defaults); cleared at
//   twice the ratio (hysteresis).
// * stuck: the very same value repeated for stuck_time (1 s) and at least
//   5 samples (a float from a noisy sensor never repeats).
// * noisy: the learned noise sigma above noisy_factor (5) times the datasheet.
#pragma once

namespace hoist {

/// Why a channel is judged faulty (bit mask).
enum SensorFaultBits : unsigned {
  kFaultQuiet = 1u,  ///< far quieter than its datasheet noise (flat, zeroed, held)
  kFaultStuck = 2u,  ///< the same value repeated
  kFaultNoisy = 4u,  ///< far noisier than its datasheet
};
/// The first reason of `bits` as a word ("quiet", "stuck", "noisy"), "" for none.
const char* sensorFaultReason(unsigned bits);

struct SensorMonitorSettings {
  double sigma = 1.0;         ///< datasheet noise per sample
  double lp_time = 0.05;      ///< the model's band: low-pass time constant [s]
  double noise_memory = 2.0;  ///< memory of the learned noise variance [s]
  double quiet_memory = 1.0;  ///< memory of the raw high-pass variance [s]
  double quiet_ratio = 0.25;  ///< quiet below quiet_ratio x sigma
  double stuck_time = 1.0;    ///< stuck after the same value for this long [s]
  double noisy_factor = 5.0;  ///< noisy above noisy_factor x sigma
};

class SensorMonitor {
 public:
  /// Forget everything; the channel is assumed healthy with its datasheet noise.
  void reset(const SensorMonitorSettings& s);
  /// A finite sample `z` at time `t` (accepted or gated).
  void sample(double t, double z);
  /// The innovation `nu` of an accepted sample at time `t`.
  void innovation(double t, double nu);
  /// The learned high-frequency variance of the innovations, discounted by
  /// three standard deviations of its own estimate (relative sd
  /// sqrt(dt / noise_memory)), so that a right datasheet is not inflated by
  /// the estimate's scatter.
  double learnedVariance() const { return var_nu_ / (1.0 + 3.0 * rel_sd_); }
  /// max(sigma^2, learnedVariance()).
  double noiseVariance() const {
    const double l = learnedVariance();
    return l > s_.sigma * s_.sigma ? l : s_.sigma * s_.sigma;
  }
  /// The high-pass variance of the raw samples (what the quiet test judges).
  double rawVariance() const { return var_z_; }
  unsigned faults() const { return faults_; }

 private:
  struct HighPass {
    double lp = 0.0, var = 0.0, t = 0.0;
    bool started = false;
    // Adds x at t (the first sample only starts the low-pass).
    void add(double t1, double x, double lp_time, double memory);
  };
  SensorMonitorSettings s_;
  HighPass raw_, inn_;
  double var_z_ = 0.0, var_nu_ = 0.0, rel_sd_ = 0.0;
  double last_z_ = 0.0, same_since_ = 0.0;
  int same_run_ = 0;
  unsigned faults_ = 0;
};

}  // namespace hoist
