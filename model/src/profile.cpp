#include "hoist/profile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hoist {

HoistProfile::HoistProfile(std::vector<ProfileSample> samples) : samples_(std::move(samples)) {
  if (samples_.empty()) throw std::invalid_argument("profile has no samples");
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    const auto& s = samples_[i];
    if (!std::isfinite(s.t) || !std::isfinite(s.k.l) || !std::isfinite(s.k.v) || !std::isfinite(s.k.a))
      throw std::invalid_argument("profile sample " + std::to_string(i) + " is not finite");
    if (i > 0 && !(s.t > samples_[i - 1].t))
      throw std::invalid_argument("profile time must be strictly increasing (sample " + std::to_string(i) + ")");
  }
}

HoistProfile HoistProfile::fromVelocity(const std::vector<double>& t, const std::vector<double>& v,
                                        const std::vector<double>& a, double l0) {
  if (t.size() != v.size() || t.size() != a.size())
    throw std::invalid_argument("profile columns t, v, a differ in length");
  std::vector<ProfileSample> s(t.size());
  double l = l0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (i > 0) {
      const double dt = t[i] - t[i - 1];
      // Exact for a cubic l whose derivative is the linear-in-a Hermite of v:
      // l1 = l0 + dt (v0 + v1)/2 + dt^2 (a0 - a1)/12.
      l += dt * 0.5 * (v[i - 1] + v[i]) + dt * dt * (a[i - 1] - a[i]) / 12.0;
    }
    s[i] = {t[i], {l, v[i], a[i]}};
  }
  return HoistProfile(std::move(s));
}

Kinematics HoistProfile::at(double t) const {
  if (samples_.empty()) throw std::logic_error("empty profile");
  if (t <= samples_.front().t) return samples_.front().k;
  if (t >= samples_.back().t) return samples_.back().k;
  const auto it = std::upper_bound(samples_.begin(), samples_.end(), t,
                                   [](double x, const ProfileSample& s) { return x < s.t; });
  const ProfileSample& s1 = *it;
  const ProfileSample& s0 = *(it - 1);
  const double dt = s1.t - s0.t;
  const double u = (t - s0.t) / dt;
  if (u == 0.0) return s0.k;
  return hermiteKinematics(s0.k, s1.k, dt, u);
}

Kinematics hermiteKinematics(const Kinematics& k0, const Kinematics& k1, double dt, double u) {
  Kinematics k;
  k.v = k0.v + u * (k1.v - k0.v);
  k.a = k0.a + u * (k1.a - k0.a);
  // Cubic Hermite on (l, v) at both ends.
  const double h00 = (1 + 2 * u) * (1 - u) * (1 - u), h10 = u * (1 - u) * (1 - u);
  const double h01 = u * u * (3 - 2 * u), h11 = u * u * (u - 1);
  k.l = h00 * k0.l + h10 * dt * k0.v + h01 * k1.l + h11 * dt * k1.v;
  return k;
}

namespace {

/// Samples a piecewise-constant-jerk/acceleration motion given by a function
/// returning (l, v, a) at t; t grid 0, dt, ..., t_end (t_end included).
template <class F>
HoistProfile sampleGrid(double t_end, double dt, F&& f) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("profile dt must be > 0");
  if (!(t_end > 0.0) || !std::isfinite(t_end)) throw std::invalid_argument("profile t_end must be > 0");
  const auto steps = static_cast<long>(std::llround(t_end / dt));
  if (steps > 100'000'000) throw std::invalid_argument("profile too long (more than 1e8 samples)");
  std::vector<ProfileSample> s;
  s.reserve(static_cast<std::size_t>(steps) + 1);
  for (long i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) * dt;
    s.push_back({t, f(t)});
  }
  return HoistProfile(std::move(s));
}

/// Motion with piecewise-constant acceleration: segments (duration, accel).
struct PiecewiseAccel {
  struct Seg {
    double t0, dur, a, l0, v0;
  };
  std::vector<Seg> segs;
  PiecewiseAccel(double l0, const std::vector<std::pair<double, double>>& spec) {
    double t = 0, l = l0, v = 0;
    for (auto [dur, a] : spec) {
      if (dur <= 0) continue;
      segs.push_back({t, dur, a, l, v});
      l += v * dur + 0.5 * a * dur * dur;
      v += a * dur;
      t += dur;
    }
    segs.push_back({t, 1e300, 0.0, l, v});
  }
  Kinematics operator()(double t) const {
    const Seg* s = &segs.front();
    // Right-continuous acceleration: at a segment boundary the new segment's a.
    for (const auto& sg : segs)
      if (t >= sg.t0 - 1e-12) s = &sg;
    const double tau = std::max(0.0, t - s->t0);
    return {s->l0 + s->v0 * tau + 0.5 * s->a * tau * tau, s->v0 + s->a * tau, s->a};
  }
};

}  // namespace

HoistProfile HoistProfile::trapezoid(double l0, double vmax, double amax, double travel, double t_end,
                                     double dt) {
  if (!(vmax > 0) || !(amax > 0)) throw std::invalid_argument("trapezoid: vmax and amax must be > 0");
  if (!std::isfinite(l0) || !std::isfinite(travel) || travel == 0.0)
    throw std::invalid_argument("trapezoid: travel must be finite and non-zero");
  const double dir = travel > 0 ? 1.0 : -1.0;
  const double D = std::abs(travel);
  double ta = vmax / amax, tc;
  double vpk = vmax;
  if (amax * ta * ta > D) {  // triangle: never reaches vmax
    ta = std::sqrt(D / amax);
    vpk = amax * ta;
    tc = 0.0;
  } else {
    tc = (D - amax * ta * ta) / vpk;
  }
  PiecewiseAccel m(l0, {{ta, dir * amax}, {tc, 0.0}, {ta, -dir * amax}});
  (void)vpk;
  return sampleGrid(t_end, dt, m);
}

HoistProfile HoistProfile::sCurve(double l0, double vmax, double amax, double jmax, double travel, double t_end,
                                  double dt) {
  if (!(vmax > 0) || !(amax > 0) || !(jmax > 0))
    throw std::invalid_argument("scurve: vmax, amax and jmax must be > 0");
  if (!std::isfinite(l0) || !std::isfinite(travel) || travel == 0.0)
    throw std::invalid_argument("scurve: travel must be finite and non-zero");
  const double dir = travel > 0 ? 1.0 : -1.0;
  const double D = std::abs(travel);
  // Jerk phases of tj = amax/jmax; if vmax is reached before amax, shorten.
  double tj = amax / jmax, ap = amax;
  if (jmax * tj * tj > vmax) {  // vmax reached during the jerk phases
    tj = std::sqrt(vmax / jmax);
    ap = jmax * tj;
  }
  double ta = vmax / ap - tj;  // constant-acceleration time
  if (ta < 0) ta = 0;
  const double t_acc = 2 * tj + ta;              // time to reach vmax
  const double d_acc = 0.5 * vmax * t_acc;       // symmetric S: distance = v t / 2
  double v = vmax;
  double tc = (D - 2 * d_acc) / v;
  if (tc < 0) {
    // Scale the peak velocity down (bisection on v) so that 2 d_acc(v) = D.
    double lo = 0, hi = vmax;
    for (int it = 0; it < 200; ++it) {
      const double vm = 0.5 * (lo + hi);
      double tj2 = amax / jmax, ap2 = amax;
      if (jmax * tj2 * tj2 > vm) {
        tj2 = std::sqrt(vm / jmax);
        ap2 = jmax * tj2;
      }
      const double ta2 = std::max(0.0, vm / ap2 - tj2);
      const double dd = vm * (2 * tj2 + ta2);
      (dd > D ? hi : lo) = vm;
    }
    v = lo;
    tj = amax / jmax;
    ap = amax;
    if (jmax * tj * tj > v) {
      tj = std::sqrt(v / jmax);
      ap = jmax * tj;
    }
    ta = std::max(0.0, v / ap - tj);
    tc = 0;
  }
  // Integrate the piecewise-constant jerk exactly.
  struct Seg {
    double dur, j;
  };
  const double j = dir * jmax;
  const std::vector<Seg> segs = {{tj, j}, {ta, 0}, {tj, -j}, {tc, 0}, {tj, -j}, {ta, 0}, {tj, j}};
  struct State {
    double t0, l, v, a, j;
  };
  std::vector<State> st;
  double t = 0, l = l0, vv = 0, a = 0;
  for (const auto& s : segs) {
    if (s.dur <= 0) continue;
    st.push_back({t, l, vv, a, s.j});
    const double d = s.dur;
    l += vv * d + 0.5 * a * d * d + s.j * d * d * d / 6.0;
    vv += a * d + 0.5 * s.j * d * d;
    a += s.j * d;
    t += d;
  }
  st.push_back({t, l, 0.0 * vv, 0.0, 0.0});
  st.back().v = 0.0;  // exact rest at the end (removes round-off)
  return sampleGrid(t_end, dt, [&](double tt) {
    const State* s = &st.front();
    for (const auto& x : st)
      if (tt >= x.t0 - 1e-12) s = &x;
    const double tau = std::max(0.0, tt - s->t0);
    return Kinematics{s->l + s->v * tau + 0.5 * s->a * tau * tau + s->j * tau * tau * tau / 6.0,
                      s->v + s->a * tau + 0.5 * s->j * tau * tau, s->a + s->j * tau};
  });
}

HoistProfile HoistProfile::emergencyStop(double l0, double vmax, double t_stop, double decel, double t_end,
                                         double dt) {
  if (!(decel > 0)) throw std::invalid_argument("estop: decel must be > 0");
  if (!std::isfinite(vmax) || vmax == 0.0) throw std::invalid_argument("estop: vmax must be non-zero");
  if (!(t_stop >= 0)) throw std::invalid_argument("estop: t_stop must be >= 0");
  const double dir = vmax > 0 ? 1.0 : -1.0;
  // Cruise from t = 0 (the trip is already under way), then stop.
  struct M {
    double l0, v, ts, d, tstop_end, dir;
    Kinematics operator()(double t) const {
      if (t < ts) return {l0 + v * t, v, 0.0};
      const double tau = std::min(t - ts, tstop_end);
      const double l = l0 + v * ts + v * tau - 0.5 * dir * d * tau * tau;
      if (t - ts >= tstop_end) return {l, 0.0, 0.0};
      return {l, v - dir * d * tau, -dir * d};
    }
  } m{l0, vmax, t_stop, decel, std::abs(vmax) / decel, dir};
  return sampleGrid(t_end, dt, m);
}

}  // namespace hoist
