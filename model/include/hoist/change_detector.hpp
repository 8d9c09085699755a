// hoist/change_detector.hpp -- a two-sided CUSUM on normalized innovations:
// finds a step in a channel's mean that no single sample shows.
//
// Who calls it: hoist::LoadEstimator, one per channel (rope load for Fa,
// f_y for M), with z = nu / sqrt(S) of every accepted or gated sample while
// the cage is at rest.  O(1), no allocation.
//
// Page's CUSUM: g+ = max(0, g+ + z - k), g- = max(0, g- - z - k); a change
// when either exceeds h.  With z ~ N(0, 1) (a right model) the mean run
// between false changes is about exp(2 k h) / (2 k^2) samples (Siegmund's
// approximation with h + 1.166: 2.9e5 at k = 0.5, h = 12, i.e. 48 min at
// 100 Hz per channel); a step of d sigma (d > k) is found after about
// h / (d - k) samples (24 at d = 1: 0.24 s at 100 Hz).  The innovations of a
// filter whose model is right are white, so the CUSUM needs no decorrelation.
#pragma once

#include <algorithm>

namespace hoist {

class ChangeDetector {
 public:
  ChangeDetector() = default;
  ChangeDetector(double k, double h) : k_(k), h_(h) {}
  void reset() { up_ = down_ = 0.0; }
  /// Adds the normalized innovation z; true when a change is detected (the
  /// statistic then starts again from 0).
  bool add(double z) {
    up_ = std::max(0.0, up_ + z - k_);
    down_ = std::max(0.0, down_ - z - k_);
    if (up_ > h_ || down_ > h_) {
      reset();
      return true;
    }
    return false;
  }
  /// The larger of the two one-sided statistics (in units of h: 1 = alarm).
  double level() const { return std::max(up_, down_) / h_; }

 private:
  double k_ = 0.5, h_ = 12.0;
  double up_ = 0.0, down_ = 0.0;
};

}  // namespace hoist
