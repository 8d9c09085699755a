// hoist/profile.hpp -- the prescribed winder motion l(t), v(t) = dl/dt, a(t) = dv/dt.
// x is depth, positive downward: v > 0 when the cage descends (rope pays out).
#pragma once

#include <string>
#include <vector>

namespace hoist {

/// Hoisting-rope kinematics at one instant.
struct Kinematics {
  double l = 0.0;  ///< hoisting-rope length = depth of the top sleeves [m]
  double v = 0.0;  ///< dl/dt [m/s]
  double a = 0.0;  ///< d2l/dt2 [m/s^2]
};

/// Kinematics at fraction u in [0, 1] of an interval of h seconds from k0 to
/// k1: l by the cubic Hermite consistent with (l, v) at both ends, v and a
/// linear.  The one interpolation used between samples by HoistProfile::at
/// (hence hoist-sim's substeps) and by the forecast's substeps; the daemon's
/// substeps (TwinCore::advance) should call it too to be bit-identical.
Kinematics hermiteKinematics(const Kinematics& k0, const Kinematics& k1, double h, double u);

struct ProfileSample {
  double t = 0.0;
  Kinematics k;
};

/// A sampled hoist profile.  Between samples v and a are interpolated linearly
/// and l by the cubic Hermite consistent with (l, v) at both ends.  Outside the
/// sampled interval the nearest sample is held (at() clamps t).
class HoistProfile {
 public:
  HoistProfile() = default;
  /// Samples must have strictly increasing, finite t (throws std::invalid_argument).
  explicit HoistProfile(std::vector<ProfileSample> samples);

  /// Build from t, v, a only: l integrated from l0 (trapezoidal on v with the
  /// a-consistent correction, i.e. exact for piecewise-linear v).
  static HoistProfile fromVelocity(const std::vector<double>& t, const std::vector<double>& v,
                                   const std::vector<double>& a, double l0);

  /// The paper's Fig. 2 trapezoid (MODEL.md): l(0) = l0, a = +amax until v = vmax,
  /// cruise, a = -amax, rest; sampled every dt up to t_end.  Defaults give the
  /// paper run: 50 m -> 300 m in 55 s, 60 s in all.
  static HoistProfile trapezoid(double l0 = 50.0, double vmax = 5.0, double amax = 1.0,
                                double travel = 250.0, double t_end = 60.0, double dt = 0.01);

  /// Jerk-limited S-curve trip of length `travel` (> 0 descends, < 0 hoists):
  /// jerk `jmax`, then the same shape as trapezoid() with rounded corners.
  static HoistProfile sCurve(double l0 = 50.0, double vmax = 5.0, double amax = 1.0,
                             double jmax = 0.5, double travel = 250.0, double t_end = 70.0,
                             double dt = 0.01);

  /// Cruise at vmax from l0, then an emergency stop at t_stop with deceleration
  /// `decel` (>0), then rest until t_end.
  static HoistProfile emergencyStop(double l0 = 50.0, double vmax = 5.0, double t_stop = 20.0,
                                    double decel = 3.0, double t_end = 30.0, double dt = 0.01);

  /// Kinematics at time t (clamped to [front().t, back().t]).
  Kinematics at(double t) const;

  bool empty() const { return samples_.empty(); }
  double startTime() const { return samples_.front().t; }
  double endTime() const { return samples_.back().t; }
  const std::vector<ProfileSample>& samples() const { return samples_; }

 private:
  std::vector<ProfileSample> samples_;
};

}  // namespace hoist
