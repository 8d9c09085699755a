#include "hoist/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace hoist {

// ---- MotionProfile -------------------------------------------------------------

void MotionProfile::reset(double t0, const Kinematics& k0) {
  t0_ = tend_ = t0;
  start_ = end_ = k0;
  count_ = 0;
}

Kinematics MotionProfile::eval(const Piece& p, double tau) {
  return {p.l + tau * (p.v + tau * (0.5 * p.a + tau * (p.j / 6.0))), p.v + tau * (p.a + 0.5 * p.j * tau),
          p.a + p.j * tau};
}

void MotionProfile::appendJerk(double duration, double jerk) {
  if (!(duration > 0.0)) return;
  if (count_ >= kMaxPieces) throw std::length_error("MotionProfile: more than kMaxPieces pieces");
  Piece p{tend_, end_.l, end_.v, end_.a, jerk};
  pieces_[count_] = p;
  dur_[count_] = duration;
  ++count_;
  end_ = eval(p, duration);
  tend_ += duration;
}

void MotionProfile::appendAccel(double duration, double accel) {
  if (!(duration > 0.0)) return;
  end_.a = accel;
  appendJerk(duration, 0.0);
  end_.a = accel;
}

void MotionProfile::snapEnd(double v, double a) {
  end_.v = v;
  end_.a = a;
}

Kinematics MotionProfile::at(double t) const {
  if (t < t0_) return start_;
  if (t >= tend_) return {end_.l, 0.0, 0.0};
  int i = count_ - 1;
  while (i > 0 && t < pieces_[i].t0) --i;
  return eval(pieces_[i], t - pieces_[i].t0);
}

double MotionProfile::maxSpeed() const {
  double m = std::max(std::abs(start_.v), std::abs(end_.v));
  for (int i = 0; i < count_; ++i) {
    const Piece& p = pieces_[i];
    m = std::max(m, std::abs(p.v));
    m = std::max(m, std::abs(eval(p, dur_[i]).v));
    if (p.j != 0.0) {
      const double tau = -p.a / p.j;  // a = 0: extremum of v
      if (tau > 0.0 && tau < dur_[i]) m = std::max(m, std::abs(eval(p, tau).v));
    }
  }
  return m;
}

namespace {

double sgn(double x) { return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); }

/// Appends the jerk-limited pieces that take (v, a) from the profile's end to
/// (vt, 0): |a| up to A, jerk +-J.  The acceleration goes toward s*ap (s the
/// side the velocity must still move to after a ramps straight to 0), holds
/// and ramps back; ap < A when the change is too small to reach A.
void appendVelocityChange(MotionProfile& p, double vt, double A, double J) {
  const double v0 = p.end().v, a0 = p.end().a;
  const double vnat = v0 + a0 * std::abs(a0) / (2.0 * J);  // v after a ramps to 0 at once
  const double s = vt >= vnat ? 1.0 : -1.0;
  const double b0 = s * a0, w = s * (vt - v0);
  double ap = A;
  double t1 = std::abs(ap - b0) / J;
  double j1 = s * J * sgn(ap - b0);
  double t3 = ap / J;
  double t2 = (w - t1 * (b0 + ap) / 2.0 - ap * ap / (2.0 * J)) / ap;
  if (t2 < 0.0) {
    ap = std::sqrt(std::max(0.0, J * w + 0.5 * b0 * b0));
    t1 = std::max(0.0, (ap - b0) / J);
    j1 = s * J;
    t2 = 0.0;
    t3 = ap / J;
  }
  p.appendJerk(t1, j1);
  p.appendJerk(t2, 0.0);
  p.appendJerk(t3, -s * J);
  p.snapEnd(vt, 0.0);
}

bool finite(const Kinematics& k) { return std::isfinite(k.l) && std::isfinite(k.v) && std::isfinite(k.a); }

}  // namespace

// ---- emergency stop ------------------------------------------------------------

MotionProfile estopProfile(double t0, const Kinematics& k0, double decel, double jerk) {
  if (!std::isfinite(t0) || !finite(k0)) throw std::invalid_argument("estop: non-finite start state");
  if (!std::isfinite(decel) || !(decel > 0.0)) throw std::invalid_argument("estop_decel: must be a finite number > 0");
  if (!std::isfinite(jerk) || !(jerk > 0.0)) throw std::invalid_argument("estop_jerk: must be a finite number > 0");
  MotionProfile p;
  p.reset(t0, k0);
  if (k0.v == 0.0) return p;  // at rest: a drops to 0 at once
  const double sv = sgn(k0.v), V = std::abs(k0.v), A0 = sv * k0.a;
  if (A0 < 0.0 && V <= A0 * A0 / (2.0 * jerk)) {
    // Decelerating so hard that easing off at `jerk` would reverse the cage:
    // ease off at the jerk that lands exactly at v = a = 0.
    p.appendJerk(2.0 * V / -A0, sv * A0 * A0 / (2.0 * V));
    p.snapEnd(0.0, 0.0);
    return p;
  }
  appendVelocityChange(p, 0.0, decel, jerk);
  return p;
}

// ---- trip plan -------------------------------------------------------------------

const char* toString(PlanError e) {
  switch (e) {
    case PlanError::None: return "ok";
    case PlanError::NotFinite: return "not_finite";
    case PlanError::NonPositiveLimit: return "non_positive_limit";
    case PlanError::TargetOutsideShaft: return "target_outside_shaft";
    case PlanError::SpeedAboveVmax: return "speed_above_vmax";
    case PlanError::AccelAboveAmax: return "accel_above_amax";
    case PlanError::WrongDirection: return "wrong_direction";
    case PlanError::OvershootsVmax: return "overshoots_vmax";
    case PlanError::OvershootsStop: return "overshoots_stop";
    case PlanError::Unreachable: return "unreachable";
  }
  return "?";
}

std::string describe(const PlanCheck& c) {
  char buf[256];
  const double v = c.value, l = c.limit;
  switch (c.error) {
    case PlanError::None: return "plan accepted";
    case PlanError::NotFinite: return "plan rejected: a field is NaN or infinite (or the current kinematics are)";
    case PlanError::NonPositiveLimit:
      std::snprintf(buf, sizeof buf, "plan rejected: vmax, amax and jerk must be > 0 (got %g)", v);
      break;
    case PlanError::TargetOutsideShaft:
      std::snprintf(buf, sizeof buf, "plan rejected: target length %g m outside the shaft (0, L - 2h = %g m)", v, l);
      break;
    case PlanError::SpeedAboveVmax:
      std::snprintf(buf, sizeof buf, "plan contradicts the motion: current speed %g m/s above the plan's vmax %g m/s", v, l);
      break;
    case PlanError::AccelAboveAmax:
      std::snprintf(buf, sizeof buf,
                    "plan contradicts the motion: current acceleration %g m/s^2 above the plan's amax %g m/s^2", v, l);
      break;
    case PlanError::WrongDirection:
      std::snprintf(buf, sizeof buf,
                    "plan contradicts the motion: moving at %g m/s away from the target (%g m to go)", v, l);
      break;
    case PlanError::OvershootsVmax:
      std::snprintf(buf, sizeof buf,
                    "plan contradicts the motion: at the plan's jerk the current acceleration carries the speed to "
                    "%g m/s, above vmax %g m/s", v, l);
      break;
    case PlanError::OvershootsStop:
      std::snprintf(buf, sizeof buf,
                    "plan contradicts the motion: at the plan's jerk the current deceleration reverses the cage "
                    "(speed %g m/s, needs at least %g m/s)", v, l);
      break;
    case PlanError::Unreachable:
      std::snprintf(buf, sizeof buf,
                    "plan rejected: target unreachable, braking distance %g m under the plan's limits exceeds the "
                    "%g m to go", v, l);
      break;
  }
  return buf;
}

PlanCheck planProfile(double t0, const Kinematics& k0, const TripPlan& plan, double max_length,
                      MotionProfile& out) {
  auto fail = [](PlanError e, double v = 0.0, double l = 0.0) { return PlanCheck{e, v, l}; };
  if (!std::isfinite(t0) || !finite(k0) || !std::isfinite(plan.target_length) || !std::isfinite(plan.vmax) ||
      !std::isfinite(plan.amax) || !std::isfinite(plan.jerk) || !std::isfinite(max_length))
    return fail(PlanError::NotFinite);
  if (!(plan.vmax > 0.0)) return fail(PlanError::NonPositiveLimit, plan.vmax);
  if (!(plan.amax > 0.0)) return fail(PlanError::NonPositiveLimit, plan.amax);
  if (!(plan.jerk > 0.0)) return fail(PlanError::NonPositiveLimit, plan.jerk);
  if (!(plan.target_length > 0.0 && plan.target_length < max_length))
    return fail(PlanError::TargetOutsideShaft, plan.target_length, max_length);
  const double tolv = 1e-9 * plan.vmax + 1e-12, tola = 1e-9 * plan.amax + 1e-12;
  if (std::abs(k0.v) > plan.vmax + tolv) return fail(PlanError::SpeedAboveVmax, std::abs(k0.v), plan.vmax);
  if (std::abs(k0.a) > plan.amax + tola) return fail(PlanError::AccelAboveAmax, std::abs(k0.a), plan.amax);
  const double D = plan.target_length - k0.l;
  const double d = D > 0.0 ? 1.0 : (D < 0.0 ? -1.0 : (k0.v != 0.0 ? sgn(k0.v) : 1.0));
  const double V = d * k0.v, A0 = d * k0.a, dist = std::abs(D);
  const double J = plan.jerk, A = plan.amax;
  if (V < -1e-6) return fail(PlanError::WrongDirection, std::abs(k0.v), dist);
  if (A0 > 0.0 && V + A0 * A0 / (2.0 * J) > plan.vmax + tolv)
    return fail(PlanError::OvershootsVmax, V + A0 * A0 / (2.0 * J), plan.vmax);
  if (A0 < 0.0 && V < A0 * A0 / (2.0 * J) - 1e-12)
    return fail(PlanError::OvershootsStop, V, A0 * A0 / (2.0 * J));
  // Distance (toward the target) of "change to peak speed vp, then stop".
  MotionProfile trial;
  auto build = [&](MotionProfile& p, double vp, double cruise) {
    p.reset(t0, k0);
    appendVelocityChange(p, d * vp, A, J);
    if (cruise > 0.0) p.appendJerk(cruise, 0.0);
    appendVelocityChange(p, 0.0, A, J);
    return d * (p.end().l - k0.l);
  };
  const double tol = 1e-9 * std::max(1.0, dist);
  // The shortest stop: straight to v = 0.
  trial.reset(t0, k0);
  appendVelocityChange(trial, 0.0, A, J);
  const double stop = d * (trial.end().l - k0.l);
  if (stop > dist + tol) return fail(PlanError::Unreachable, stop, dist);
  double vp = plan.vmax, cruise = 0.0;
  const double full = build(trial, plan.vmax, 0.0);
  if (full <= dist) {
    cruise = (dist - full) / plan.vmax;
  } else {
    double lo = 0.0, hi = plan.vmax;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * plan.vmax; ++it) {
      const double mid = 0.5 * (lo + hi);
      (build(trial, mid, 0.0) > dist ? hi : lo) = mid;
    }
    vp = lo;
  }
  build(out, vp, cruise);
  out.snapEndLength(plan.target_length);
  if (out.maxSpeed() > plan.vmax + tolv) return fail(PlanError::OvershootsVmax, out.maxSpeed(), plan.vmax);
  return {};
}

// ---- continue without a plan -------------------------------------------------------

MotionProfile continueProfile(double t0, const Kinematics& k0, double vmax, double amax, double max_length,
                              double margin) {
  if (!std::isfinite(t0) || !finite(k0)) throw std::invalid_argument("continue: non-finite start state");
  if (!std::isfinite(vmax) || !(vmax > 0.0)) throw std::invalid_argument("vmax: must be a finite number > 0");
  if (!std::isfinite(amax) || !(amax > 0.0)) throw std::invalid_argument("amax: must be a finite number > 0");
  if (!std::isfinite(margin) || !(margin >= 0.0) || !(2.0 * margin < max_length))
    throw std::invalid_argument("continue: margin must be >= 0 and leave room in the shaft");
  MotionProfile p;
  p.reset(t0, k0);
  const double sv = k0.v != 0.0 ? sgn(k0.v) : sgn(k0.a);
  if (sv == 0.0) return p;  // at rest, a = 0
  const double V = sv * k0.v;                            // >= 0
  double A0 = sv * k0.a;                                 // along the motion
  if (A0 > 0.0 && V >= vmax) A0 = 0.0;                   // already at/above vmax: cruise
  const double lstop = sv > 0.0 ? max_length - margin : margin;
  const double R = sv * (lstop - k0.l);                  // distance left to the stop point
  auto brakeNow = [&]() {
    // Too close for amax: the deceleration that stops at lstop (amax if R <= 0).
    const double dec = R > 0.0 ? std::max(amax, V * V / (2.0 * R)) : amax;
    if (V > 0.0) p.appendAccel(V / dec, -sv * dec);
    p.snapEnd(0.0, 0.0);
  };
  if (V > 0.0 && V * V / (2.0 * amax) >= R) {
    brakeNow();
    return p;
  }
  if (A0 < 0.0) {
    const double Tstop = V / -A0;
    if (V * V / (2.0 * -A0) <= R) {  // the current deceleration stops in time
      p.appendAccel(Tstop, sv * A0);
      p.snapEnd(0.0, 0.0);
      return p;
    }
    if (-A0 >= amax) {  // braking at amax would not help: stop exactly at lstop
      brakeNow();
      return p;
    }
  }
  // Phase 1 at A0 for T1 (to vmax, or to rest when A0 < 0), braking at amax
  // once the distance left equals the braking distance:
  //   f(tau) = u^2/(2 amax) + d(tau) - R = 0,  u = V + A0 tau,  d = V tau + A0 tau^2/2.
  const double T1 = A0 > 0.0 ? (vmax - V) / A0 : (A0 < 0.0 ? V / -A0 : 0.0);
  const double alpha = A0 * (A0 + amax) / (2.0 * amax), beta = V * (A0 + amax) / amax,
               gamma = V * V / (2.0 * amax) - R;  // gamma < 0 here
  double tau = -1.0;
  if (A0 != 0.0) {
    if (alpha == 0.0) {
      tau = beta > 0.0 ? -gamma / beta : -1.0;
    } else {
      const double disc = beta * beta - 4.0 * alpha * gamma;
      if (disc >= 0.0) {
        const double q = -0.5 * (beta + std::sqrt(disc));
        const double r1 = q / alpha, r2 = q != 0.0 ? gamma / q : -1.0;
        tau = -1.0;
        for (double r : {r1, r2})
          if (r > 0.0 && (tau < 0.0 || r < tau)) tau = r;
      }
    }
  }
  if (A0 != 0.0 && tau > 0.0 && tau <= T1) {
    p.appendAccel(tau, sv * A0);
    const double u = V + A0 * tau;
    p.appendAccel(u / amax, -sv * amax);
    p.snapEnd(0.0, 0.0);
    return p;
  }
  double u = V, covered = 0.0;
  if (A0 > 0.0) {
    p.appendAccel(T1, sv * A0);
    u = vmax;
    covered = V * T1 + 0.5 * A0 * T1 * T1;
    p.snapEnd(sv * u, 0.0);
  }
  const double cruise = (R - covered - u * u / (2.0 * amax)) / u;
  p.appendAccel(std::max(0.0, cruise), 0.0);
  p.appendAccel(u / amax, -sv * amax);
  p.snapEnd(0.0, 0.0);
  return p;
}

// ---- splicing ----------------------------------------------------------------------

HoistProfile spliceProfile(const HoistProfile& before, double T, const MotionProfile& after, double dt,
                           double t_end) {
  if (before.empty()) throw std::invalid_argument("splice: empty profile");
  if (!(dt > 0.0) || !std::isfinite(dt) || !std::isfinite(T) || !std::isfinite(t_end))
    throw std::invalid_argument("splice: dt must be > 0 and T, t_end finite");
  if (!(T >= before.startTime())) throw std::invalid_argument("splice: T before the profile start");
  std::vector<ProfileSample> s;
  for (const auto& x : before.samples())
    if (x.t < T) s.push_back(x);
  const auto steps = static_cast<long>(std::floor((t_end - T) / dt + 1e-9));
  if (steps > 100'000'000) throw std::invalid_argument("splice: too many samples");
  s.push_back({T, after.at(T)});
  for (long k = 1; k <= steps; ++k) {
    const double t = T + static_cast<double>(k) * dt;
    s.push_back({t, after.at(t)});
  }
  return HoistProfile(std::move(s));
}

}  // namespace hoist
