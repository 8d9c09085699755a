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

/// Kinematics inside a sampling interval [t0, t0 + h] at fraction u in [0, 1]:
/// v and a linear in u, l by the cubic Hermite consistent with (l, v) at both
/// ends.  The one interpolation of the project: HoistProfile::at(), the
/// simulator's substeps and the daemon's substeps all use it.
Kinematics interpolate(const Kinematics& k0, const Kinematics& k1, double h, double u);

/// Rope length after an interval h of a winder that reports v and a but no
/// length: the integral of the cubic Hermite interpolant of v through
/// (v0, a0) and (v1, a1),
///   l1 = l0 + h (v0 + v1)/2 + h^2 (a0 - a1)/12        (corrected trapezoid),
/// exact whenever v is a polynomial of degree <= 3 over the interval (constant
/// acceleration or constant jerk: the trapezoid's own error -h^3 v''/12 is
/// what the second term cancels).  Where a jumps at a sample (a trapezoid
/// trip whose corner falls on a sample, with a right-continuous a), the
/// sample's a belongs to only one side and the term errs by at most
/// h^2 |jump|/12 per jump; where the jump falls inside the interval at
/// h tau, the plain trapezoid errs by h^2 tau (1 - tau) |jump|/2 (up to
/// h^2/8) and the corrected one by at most h^2 |jump|/12.  Used by
/// HoistProfile::fromVelocity and the daemon.
double integrateLength(double l0, double v0, double a0, double v1, double a1, double h);

/// Equal substeps of at most max_step that cover `interval` [s]:
/// ceil(interval / max_step) (1 when max_step is 0 or >= interval).  Throws
/// std::invalid_argument if max_step is negative or non-finite, or if more
/// than `limit` substeps would be needed (never clamps in silence).
int substepCount(double interval, double max_step, int limit = 1000000);

/// The default largest integration substep [s] of every program: hoist-sim's
/// --max-step, hoist-twind's [service] max_step (both clock modes),
/// hoist-estimate's and hoist-study's, the forecast's and the preload
/// identification's: 4 substeps per 10-ms output step.  The one place it is written.
inline constexpr double kDefaultMaxStep = 0.0025;

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

  /// The paper's Fig. 2 trapezoid (docs/model.md): l(0) = l0, a = +amax until v = vmax,
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
