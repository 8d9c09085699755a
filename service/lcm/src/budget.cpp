// Start-up budget measurement: see hoist/service/lcm/budget.hpp.
#include "hoist/service/lcm/budget.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/service/lcm/messages.hpp"
#include "hoist/service/twin/twin_core.hpp"
#include "hoist/solver.hpp"

namespace hoist::service::inline lcm {

namespace {

using Clock = std::chrono::steady_clock;

double usSince(Clock::time_point t0) { return std::chrono::duration<double, std::micro>(Clock::now() - t0).count(); }

/// Every `div`-th tick publishes at `sub_rate` (0: every tick), as ShaftOutputs does.
int divider(double rate, double sub_rate) {
  if (!(sub_rate > 0.0)) return 1;
  return std::max(1, static_cast<int>(std::lround(rate / sub_rate)));
}

/// The synthetic trip: from the initial length toward the farther end of
/// the shaft, cruising at `v0` with the acceleration swinging by `A` at 1 Hz
/// (a(t) = A sin(w t)), so that the cage moves and its load changes every
/// tick.  Encoder length, speed and acceleration agree exactly.
struct MovingTrip {
  double l0, dir, v0, A, w;
  Kinematics at(double t) const {
    const double s = std::sin(w * t), c = std::cos(w * t);
    return Kinematics{l0 + dir * (v0 * t + A / w * (t - s / w)), dir * (v0 + A / w * (1.0 - c)), dir * A * s};
  }
};

}  // namespace

TickBudget measureTickBudget(const TwinConfig& cfg, int max_ticks, double max_seconds) {
  TwinConfig c = cfg;
  c.service.clock = ClockMode::Input;  // one step per fed sample = one tick's model work
  TwinCore core(c, ClockMode::Input);
  TickBudget b;
  const ServiceConfig& s = c.service;
  b.period_us = 1e6 / s.rate;
  const LengthRange r = core.validRange();
  const double dir = c.shaft.l0 - r.lo < r.hi - c.shaft.l0 ? 1.0 : -1.0;
  // The winder's normal speed and acceleration, within what the input
  // validator accepts.
  const double v0 = std::min(c.forecast.vmax, 0.8 * s.max_speed);
  const double A = std::min(c.forecast.amax, 0.5 * s.max_accel);
  const MovingTrip trip{c.shaft.l0, dir, v0, A, 2.0 * M_PI};
  const double dt = 1.0 / s.rate;
  const double room = 0.8 * (dir > 0.0 ? r.hi - c.shaft.l0 : c.shaft.l0 - r.lo) - 1.0;  // [m] left to travel
  const auto dt_us = static_cast<std::int64_t>(std::llround(b.period_us));

  // The tick's publication work on preallocated messages, as ShaftOutputs.
  const int cage_div = divider(s.rate, s.cage_rate);
  const int shape_div = s.shape_rate > 0.0 ? divider(s.rate, s.shape_rate) : 0;
  hoist::cage_state_t cage_msg{};
  hoist::estimate_t estimate_msg{};
  hoist::guide_shape_t shape_msg{};
  const GuideRopeEnvelope& sh = core.shape();
  shape_msg.n = static_cast<int32_t>(sh.depths().size());
  shape_msg.x.assign(sh.depths().data(), sh.depths().data() + sh.depths().size());
  shape_msg.y1.assign(static_cast<std::size_t>(shape_msg.n), 0.0);
  shape_msg.y2.assign(static_cast<std::size_t>(shape_msg.n), 0.0);
  std::vector<std::uint8_t> cage_buf(static_cast<std::size_t>(cage_msg.getEncodedSize()) + 64);
  std::vector<std::uint8_t> estimate_buf(static_cast<std::size_t>(estimate_msg.getEncodedSize()) + 64);
  std::vector<std::uint8_t> shape_buf(static_cast<std::size_t>(shape_msg.getEncodedSize()) + 64);

  const auto start = Clock::now();
  double step_sum = 0.0, env_sum = 0.0, cage_sum = 0.0, shape_sum = 0.0;
  int counted = 0, shapes = 0;
  std::int64_t exact0 = 0, bounded0 = 0;
  for (int k = 0; k < max_ticks; ++k) {
    const double t = static_cast<double>(k) * dt;
    const Kinematics kin = trip.at(t);
    WinderSample w;
    w.utime = 1'000'000'000 + k * dt_us;
    w.seq = k;
    w.v = kin.v;
    w.a = kin.a;
    w.has_length = true;
    w.length = kin.l;
    const std::int64_t env0 = core.envelopeNanos();
    const auto t0 = Clock::now();
    core.onInput(w, t);
    const double step = usSince(t0);
    const double env = static_cast<double>(core.envelopeNanos() - env0) * 1e-3;
    // Publication: the cage (and estimate) message every tick here, the
    // shape every other tick (both amortized to their rates below), so that
    // a short measurement sees both even when they are rare.
    const auto p0 = Clock::now();
    toCageMessage(core.output(), cage_msg);
    cage_msg.encode(cage_buf.data(), 0, static_cast<int>(cage_buf.size()));
    if (const LoadEstimate* e = core.estimate()) {
      toEstimateMessage(*e, *core.estimatorCounters(), core.output().t, 0.0, 0.0, core.estimateGate(), core.modelTime(),
                        core.calibrating(), estimate_msg);
      estimate_msg.encode(estimate_buf.data(), 0, static_cast<int>(estimate_buf.size()));
    }
    const double cage = usSince(p0);
    double shape = -1.0;
    if (shape_div > 0 && k % 2 == 0) {
      const auto s0 = Clock::now();
      core.evaluateShape();
      shape_msg.t = core.output().t;
      shape_msg.l = core.output().kin.l;
      for (int i = 0; i < shape_msg.n; ++i) {
        shape_msg.y1[static_cast<std::size_t>(i)] = sh.y1()(i);
        shape_msg.y2[static_cast<std::size_t>(i)] = sh.y2()(i);
      }
      shape_msg.encode(shape_buf.data(), 0, static_cast<int>(shape_buf.size()));
      shape = usSince(s0);
    }
    if (k == 2) {
      exact0 = core.envelope().exactEvaluations();
      bounded0 = core.envelope().boundedEvaluations();
    }
    if (k >= 2) {  // the first ones initialize and warm the caches
      step_sum += step;
      env_sum += env;
      cage_sum += cage;
      if (shape >= 0.0) {
        shape_sum += shape;
        ++shapes;
      }
      ++counted;
      b.max_us = std::max(b.max_us, step);
    }
    b.ticks = k + 1;
    b.moved_m = std::fabs(kin.l - c.shaft.l0);
    if (b.moved_m > room && counted >= 3) break;  // a slow rate: the trip would leave the shaft before the time is up
    if (counted >= 3 && (shape_div == 0 || shapes > 0) &&
        std::chrono::duration<double>(Clock::now() - start).count() > max_seconds)
      break;
  }
  if (counted > 0) {
    b.step_us = step_sum / counted;
    b.envelope_us = env_sum / counted;
    b.cage_us = cage_sum / counted / cage_div;
  }
  if (shapes > 0) {
    b.shape_each_us = shape_sum / shapes;
    b.shape_us = b.shape_each_us / shape_div;
  }
  const auto exact = static_cast<double>(core.envelope().exactEvaluations() - exact0);
  const auto bounded = static_cast<double>(core.envelope().boundedEvaluations() - bounded0);
  b.envelope_exact = exact + bounded > 0.0 ? exact / (exact + bounded) : 0.0;
  // The exact envelope (a depths x n product per rope): the bound saves it
  // only while the state stays near the last exact evaluation, which a short
  // measurement from a settled start cannot show.  Measured on the moved
  // state (fastest of a few: it is the same work each time).
  GuideRopeEnvelope exact_env(core.solver().model(), s.envelope_points);
  const auto e_start = Clock::now();
  for (int i = 0; i < 5; ++i) {
    const auto e0 = Clock::now();
    exact_env.evaluate(core.solver());
    const double us = usSince(e0);
    b.exact_us = i == 0 ? us : std::min(b.exact_us, us);
    if (std::chrono::duration<double>(Clock::now() - e_start).count() > 0.05) break;
  }
  // Amortized: exact on kExactPerSecond of model time at least (the paper's
  // trip needs about 6 a second at any rate), every tick with
  // envelope_tolerance = 0.
  const double p = s.envelope_tolerance > 0.0 ? std::min(1.0, kExactPerSecond / s.rate) : 1.0;
  const double extra = std::max(0.0, p - b.envelope_exact) * b.exact_us;
  b.tick_us = b.step_us + extra + b.cage_us + b.shape_us;
  b.use = b.tick_us / b.period_us;
  // The slowest tick: one that needs the exact envelope and publishes the shape.
  // (The measured step's own envelope, bounded or exact, is replaced by an exact one.)
  b.worst_us = std::max(0.0, b.step_us - b.envelope_us) + b.exact_us + (shape_div > 0 ? b.shape_each_us : 0.0) +
               b.cage_us * cage_div;
  return b;
}

std::string describeBudget(const TickBudget& b, const TwinConfig& cfg) {
  const ServiceConfig& s = cfg.service;
  const int substeps = s.max_step > 0.0 ? static_cast<int>(std::ceil(1.0 / s.rate / s.max_step - 1e-9)) : 1;
  struct Part {
    double us;
    std::string text;
  };
  std::vector<Part> parts;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "model step %.0f us ([model] modes = %d, [service] rate = %g Hz, max_step = %g s: %d substep%s%s; "
                "of it the guide-rope envelope %.0f us: [service] envelope_points = %d, envelope_tolerance = %g, "
                "%.0f %% exact)",
                b.step_us, cfg.shaft.n, s.rate, s.max_step, substeps, substeps == 1 ? "" : "s",
                cfg.estimator.enabled ? ", [estimator] enabled" : "", b.envelope_us, s.envelope_points,
                s.envelope_tolerance, 100.0 * b.envelope_exact);
  parts.push_back({b.step_us, buf});
  std::snprintf(buf, sizeof buf,
                "the exact guide-rope envelope %.0f us each ([service] envelope_points = %d x [model] modes = %d; "
                "needed %s)",
                b.exact_us, s.envelope_points, cfg.shaft.n,
                s.envelope_tolerance > 0.0 ? "whenever the cage's state leaves the bound of envelope_tolerance, at "
                                             "least 10 times a second while it moves"
                                           : "every tick: envelope_tolerance = 0");
  parts.push_back({b.exact_us * (s.envelope_tolerance > 0.0 ? std::min(1.0, kExactPerSecond / s.rate) : 1.0), buf});
  if (s.shape_rate > 0.0) {
    std::snprintf(buf, sizeof buf,
                  "guide-rope shape %.0f us per tick (%.0f us each; [service] shape_rate = %g Hz, shape_points = %d)",
                  b.shape_us, b.shape_each_us, s.shape_rate, s.shape_points);
    parts.push_back({b.shape_us, buf});
  }
  std::snprintf(buf, sizeof buf, "cage message %.0f us per tick ([service] cage_rate = %g Hz%s)", b.cage_us,
                s.cage_rate > 0.0 ? s.cage_rate : s.rate, s.cage_rate > 0.0 ? "" : ", every tick");
  parts.push_back({b.cage_us, buf});
  std::stable_sort(parts.begin(), parts.end(), [](const Part& x, const Part& y) { return x.us > y.us; });
  std::string out;
  for (const Part& p : parts) out += (out.empty() ? "" : ", ") + p.text;
  return out;
}

}  // namespace hoist::service::lcm
