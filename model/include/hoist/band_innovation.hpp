// hoist/band_innovation.hpp -- a channel's innovations summed over short
// blocks: the residual the model can represent, without the vibration it
// cannot.  The statistic behind MODEL_MISMATCH's NIS test and the load
// change CUSUM (docs/estimation.md, "The model check").
//
// Who calls it: hoist::LoadEstimator, one per channel, with every accepted
// update's innovation nu, its predicted variance S (the filter's, noise and
// model error included) and the model-error part e (a standard deviation,
// e^2 is inside S).  O(1), no allocation.
//
// Why blocks.  A real IMU carries vibration above the model's band (15-50
// Hz and more: higher rope modes, the cage's structure, sleeve impacts).  To
// the per-sample NIS it is extra noise (1.5-2 times dof with 0.6-1 times the
// white noise), so a healthy shaft raised MODEL_MISMATCH.  Summed over a
// block of block_time seconds (0.2 s: zeros of the sum at 5, 10, 15, ... Hz)
// that content cancels while what the model carries (its modes, a few Hz
// and below, and any model error there) adds.  Under a right model the
// innovations are white with variance S_i, except for the model error,
// which is systematic and adds in amplitude, not in variance:
//     s = sum nu_i / sqrt( sum (S_i - e_i^2) + (sum e_i)^2 )  ~  N(0, 1) (at most),
// one scalar measurement (1 dof) per block and channel.  A mismatch of the
// shaft at low frequency adds to s^2 coherently (N times its per-sample
// share), white noise and vibration do not, so the block test is also the
// sharper one.
#pragma once

#include <cmath>

namespace hoist {

class BandInnovation {
 public:
  explicit BandInnovation(double block_time = 0.2) : block_(block_time) {}
  void reset() {
    n_ = 0;
    sum_nu_ = sum_var_ = sum_e_ = 0.0;
  }
  /// Adds one innovation at time t.  true: a block closed; statistic() is its s.
  bool add(double t, double nu, double S, double e) {
    const double dt = n_ > 0 ? t - t_prev_ : 0.0;
    if (n_ == 0) t0_ = t;
    t_prev_ = t;
    ++n_;
    sum_nu_ += nu;
    sum_var_ += S - e * e;
    sum_e_ += e;
    // closes after block_time of samples (20 at 100 Hz for 0.2 s)
    if (t - t0_ + dt + 1e-9 < block_) return false;
    const double var = sum_var_ + sum_e_ * sum_e_;
    s_ = var > 0.0 ? sum_nu_ / std::sqrt(var) : 0.0;
    reset();
    return true;
  }
  /// The last closed block's normalized sum s.
  double statistic() const { return s_; }

 private:
  double block_;
  double t0_ = 0.0, t_prev_ = 0.0;
  int n_ = 0;
  double sum_nu_ = 0.0, sum_var_ = 0.0, sum_e_ = 0.0, s_ = 0.0;
};

}  // namespace hoist
