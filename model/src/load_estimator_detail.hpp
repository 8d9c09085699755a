// The load estimator's internal constants, shared by load_estimator.cpp (the
// filter) and load_estimator_finish.cpp (the tests and the estimate).  Not
// installed: model/src only.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace hoist::estimator_detail {

inline constexpr double kMaxSpecificForce = 100.0;  // |f_y| [m/s^2] a cage IMU can report
inline constexpr double kMaxRate = 20.0;            // |omega| [rad/s]
inline constexpr double kMaxRopeLoad = 1.0e8;       // |rope_load| [N]
inline constexpr int kImuAccel = 0, kImuRate = 1, kRope = 2;
// Time comparisons tolerate this much [s]: the same data timed by the CSV's t
// (hoist-estimate) or by utime differences (the daemon) differ by an ulp.
inline constexpr double kTimeEps = 1e-9;
inline constexpr double kEnvelopeTime = 3.0;        // memory of the oscillation envelopes [s]
inline constexpr double kStartTransientError = 0.1;  // rope-load model error after a start at a != 0, per N of m a
inline constexpr double kJumpTransientError = 0.1;   // the same after a jump of a later on ...
inline constexpr double kStepFoldTime = 60.0;      // a load change's step transient is followed this long [s]
inline constexpr double kStepModelError = 0.2;     // relative model error of a step's transient (n = 25 against n = 100)
// ... of its lateral part, growing as its phase is lost: 0.2 + kStepPhaseLoss t
// of its envelope, at most kStepModelErrorMax (n = 25 against n = 100: 0.3-0.6
// of it 5-20 s after the change; tests/model/load_estimator_change_test.cpp).
inline constexpr double kStepPhaseLoss = 0.05;     // [1/s]
inline constexpr double kStepModelErrorMax = 2.0;  // the phase lost: up to twice the envelope
inline constexpr double kMaxCatchUp = 2.0;         // the step solver catches up at most this much of the past [s]
inline constexpr double kJumpTransientTime = 2.5;    // ... decaying faster (the shaft was steady before),
inline constexpr double kRopeOscillationError = 0.07;  // the rope's oscillation, per N of m x_c'' (frequency error)
inline constexpr double kJumpRefLength = 50.0;       // ... and less on a longer, softer rope (x 50 m / l)
// (calibrated: n = 25 against n = 100 and 200, tests/model/load_estimator_test.cpp)
inline constexpr double kStartTransientTime = 5.0;   // its decay time [s]

// The known-load calibration pins the loads to this relative sigma (floor 1 N, 1 N m).
inline constexpr double kKnownLoadRelSigma = 1e-3;

/// One Kalman update of a two-state (M, accelerometer offset) filter with
/// covariance P, measurement matrix H, innovation covariance S = H P H^T + R
/// and innovation nu: P becomes the posterior (kept symmetric and positive
/// semi-definite); returns the state's correction.  Fixed-size: no allocation.
inline Eigen::Vector2d kalmanUpdate(Eigen::Matrix2d& P, const Eigen::Matrix2d& H, const Eigen::Matrix2d& S,
                                    const Eigen::Vector2d& nu) {
  const Eigen::Matrix2d K = P * H.transpose() * S.inverse();
  const Eigen::Vector2d dx = K * nu;
  P -= K * S * K.transpose();
  P(0, 0) = std::max(P(0, 0), 0.0);
  P(1, 1) = std::max(P(1, 1), 0.0);
  const double lim = std::sqrt(P(0, 0) * P(1, 1));
  P(0, 1) = P(1, 0) = std::clamp(0.5 * (P(0, 1) + P(1, 0)), -lim, lim);
  return dx;
}

}  // namespace hoist::estimator_detail
