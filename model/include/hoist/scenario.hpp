// hoist/scenario.hpp -- winder motions for look-ahead forecasts:
// what the winder will do from the current instant, as exact piecewise
// polynomials.  Pure math: no allocation (fixed capacity), no I/O.
//
// Conventions (MODEL.md): l rope length = depth of the top sleeves [m],
// v = dl/dt > 0 descending [m/s], a = dv/dt [m/s^2], jerk = da/dt [m/s^3].
//
//   estopProfile     emergency stop from the current (l, v, a): the
//                    deceleration builds up at the brake's jerk to
//                    estop_decel, holds, and eases off at the same jerk so
//                    that v and a reach 0 together; then rest.
//   planProfile      the winder follows a trip plan (target length, vmax,
//                    amax, jerk): a jerk-limited S-curve from the current
//                    (l, v, a) to rest at the target; bad plans are rejected
//                    with a reason (PlanCheck).
//   continueProfile  no plan known: keep the current acceleration until
//                    vmax or standstill, cruise, and brake at amax so as to
//                    stop `margin` inside the shaft (0, L - 2h).
//   spliceProfile    a sampled HoistProfile that follows one profile up to T
//                    and a MotionProfile after it (hoist-sim --estop-at, tests).
#pragma once

#include <array>
#include <string>

#include "hoist/profile.hpp"

namespace hoist {

/// Motion from t0 in pieces of constant jerk (each piece may start with an
/// acceleration step), then, after the last piece, rest at its end length
/// (v = a = 0).  Before t0 the start state is held.  Fixed capacity.
class MotionProfile {
 public:
  static constexpr int kMaxPieces = 10;

  MotionProfile() = default;
  /// Starts a new profile at time t0 in state k0 (no pieces: rest at k0.l from t0... see at()).
  void reset(double t0, const Kinematics& k0);
  /// Appends a piece of `duration` s (>= 0; 0 is ignored) with constant jerk
  /// `jerk` from the current end state.  Throws std::length_error when full.
  void appendJerk(double duration, double jerk);
  /// Appends a piece of constant acceleration `accel` (a step from the
  /// current end acceleration if they differ).
  void appendAccel(double duration, double accel);
  /// Sets the end state's v and a exactly (removes round-off after a phase
  /// that ends at known values).
  void snapEnd(double v, double a);
  void snapEndLength(double l) { end_.l = l; }

  /// Kinematics at time t: exact polynomial of the piece containing t
  /// (pieces are right-continuous: at a knot, the new piece).  After the
  /// last piece: rest at the end length, v = a = 0.
  Kinematics at(double t) const;

  double startTime() const { return t0_; }
  const Kinematics& start() const { return start_; }
  /// Time the last piece ends (rest from then on).
  double endTime() const { return tend_; }
  /// State at the end of the last piece (before the rest that follows).
  const Kinematics& end() const { return end_; }
  int pieces() const { return count_; }
  /// Largest |v| and smallest/largest l over the pieces (knots and interior extrema).
  double maxSpeed() const;

 private:
  struct Piece {
    double t0, l, v, a, j;
  };
  static Kinematics eval(const Piece& p, double tau);
  double t0_ = 0.0, tend_ = 0.0;
  Kinematics start_, end_;
  std::array<Piece, kMaxPieces> pieces_{};
  std::array<double, kMaxPieces> dur_{};
  int count_ = 0;
};

/// Emergency stop from (t0, k0): |a| builds up to `decel` (> 0, m/s^2) at
/// jerk `jerk` (> 0, m/s^3) against the motion, holds, then eases to 0 at the
/// same jerk so that v and a reach 0 together.  Special cases: v = 0: the
/// acceleration drops to 0 at once (rest); already decelerating so hard that
/// the jerk limit cannot land at v = 0 without reversing (|a|^2 / (2 jerk) >=
/// |v|): a to 0 with the (higher) jerk a^2 / (2 |v|) that lands exactly.
/// Throws std::invalid_argument on non-finite input or non-positive limits.
MotionProfile estopProfile(double t0, const Kinematics& k0, double decel, double jerk);

/// A winder trip plan (trip_plan_t).
struct TripPlan {
  double target_length = 0.0;  ///< rope length to stop at [m], in (0, L - 2h)
  double vmax = 0.0;           ///< > 0 [m/s]
  double amax = 0.0;           ///< > 0 [m/s^2]
  double jerk = 0.0;           ///< > 0 [m/s^3]
};

enum class PlanError {
  None = 0,
  NotFinite,          ///< a plan field or the current kinematics is NaN/inf
  NonPositiveLimit,   ///< vmax, amax or jerk <= 0
  TargetOutsideShaft, ///< target not in (0, L - 2h)
  SpeedAboveVmax,     ///< contradicts the motion: |v| > plan vmax
  AccelAboveAmax,     ///< contradicts the motion: |a| > plan amax
  WrongDirection,     ///< contradicts the motion: moving away from the target
  OvershootsVmax,     ///< contradicts the motion: the current a carries v past vmax at the plan's jerk
  OvershootsStop,     ///< contradicts the motion: decelerating so hard that v reverses at the plan's jerk
  Unreachable,        ///< the target is closer than the braking distance under the plan's limits
};

/// Result of planProfile: `value` and `limit` are the numbers compared (SI).
struct PlanCheck {
  PlanError error = PlanError::None;
  double value = 0.0, limit = 0.0;
  bool ok() const { return error == PlanError::None; }
};

/// Short name of the error ("unreachable", ...), for counters and logs.
const char* toString(PlanError e);
/// A full sentence naming the numbers (allocates: not for the real-time loop).
std::string describe(const PlanCheck& c);

/// Jerk-limited trip from (t0, k0) to rest at plan.target_length (exactly),
/// with |v| <= vmax, |a| <= amax, |da/dt| = jerk (or 0).  `max_length` is
/// L - 2h.  On success fills `out`; on failure returns the reason and leaves
/// `out` unspecified.  Allocation-free.
PlanCheck planProfile(double t0, const Kinematics& k0, const TripPlan& plan, double max_length,
                      MotionProfile& out);

/// No plan known: from (t0, k0) keep the current acceleration until |v|
/// reaches vmax (then cruise) or v reaches 0 (then rest); brake at amax so as
/// to stop at `margin` [m] inside the shaft end the cage moves toward
/// (L - 2h - margin when descending, margin when hoisting).  If that needs
/// more than amax (already too close), brake at once at the deceleration that
/// stops there.  At rest with a = 0: rest.  Throws std::invalid_argument on
/// non-finite input or non-positive vmax / amax / negative margin.
MotionProfile continueProfile(double t0, const Kinematics& k0, double vmax, double amax, double max_length,
                              double margin = 1.0);

/// Samples of `before` with t < T, then `after` (which should start at T from
/// before.at(T)) at T, T + dt, ... up to t_end (inclusive when on the grid).
HoistProfile spliceProfile(const HoistProfile& before, double T, const MotionProfile& after, double dt,
                           double t_end);

}  // namespace hoist
