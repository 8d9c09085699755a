// The twin's logic without I/O: see hoist/service/twin_core.hpp.
#include "hoist/service/twin_core.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hoist::svc {

namespace {

InputLimits limitsFrom(const TwinConfig& c) {
  InputLimits l;
  l.max_speed = c.service.max_speed;
  l.max_accel = c.service.max_accel;
  l.max_length_jump = c.service.max_length_jump;
  l.max_time_step = c.service.max_time_step;
  l.min_length = 0.0;
  l.max_length = c.shaft.maxRopeLength();
  return l;
}

std::unique_ptr<Solver> defaultSolver(const TwinConfig& c) {
  return makeSolver(Method::Fast, std::make_shared<const ShaftModel>(c.shaft));
}

bool allFinite(const CageOutput& o) {
  bool ok = std::isfinite(o.t) && std::isfinite(o.kin.l) && std::isfinite(o.kin.v) &&
            std::isfinite(o.kin.a) && std::isfinite(o.x_c) && std::isfinite(o.y_c) &&
            std::isfinite(o.theta);
  for (double v : o.lambda) ok = ok && std::isfinite(v);
  const Clearance& c = o.clearance;
  return ok && std::isfinite(c.y_top) && std::isfinite(c.y_bottom) &&
         std::isfinite(c.guide_deflection) && std::isfinite(c.min_clearance) &&
         std::isfinite(c.clearance_pos) && std::isfinite(c.clearance_neg) &&
         std::isfinite(c.clearance_guide);
}

}  // namespace

TwinCore::TwinCore(const TwinConfig& cfg, ClockMode clock, std::unique_ptr<Solver> solver)
    : cfg_(cfg),
      clock_(clock),
      solver_(solver ? std::move(solver) : defaultSolver(cfg)),
      envelope_(solver_->model(), cfg.service.envelope_points),
      shape_(solver_->model(), cfg.service.shape_points),
      validator_(limitsFrom(cfg)),
      alarms_(cfg.alarms),
      lmax_(cfg.shaft.maxRopeLength()) {
  cfg_.service.validate();
  if (clock_ == ClockMode::Wall) {
    // The wall-clock twin runs from start-up: at rest at the initial length
    // until the winder speaks.
    initializeAt(0.0, Kinematics{cfg_.shaft.l0, 0.0, 0.0});
    resets_ = 0;
  }
}

Kinematics TwinCore::integrate(const Kinematics& k0, double v1, double a1, double dt) const {
  Kinematics k;
  k.l = k0.l + dt * 0.5 * (k0.v + v1);
  k.v = v1;
  k.a = a1;
  return k;
}

void TwinCore::initializeAt(double t, const Kinematics& k) {
  if (started_) ++resets_;
  solver_->initialize(t, k);
  t_ = t;
  kin_ = k;
  started_ = true;
  finishStep(t);
}

bool TwinCore::advance(double t, const Kinematics& k) {
  const int n = (cfg_.service.max_step > 0.0 && t > t_)
                    ? std::clamp(static_cast<int>(std::ceil((t - t_) / cfg_.service.max_step - 1e-9)), 1, 100000)
                    : 1;
  const double t0 = t_, h = t - t_;
  const Kinematics k0 = kin_;
  try {
    for (int j = 1; j < n; ++j) {
      // Cubic Hermite in l (consistent with v at both ends), linear v and a.
      const double s = static_cast<double>(j) / n;
      const double s2 = s * s, s3 = s2 * s;
      Kinematics ks;
      ks.l = (2 * s3 - 3 * s2 + 1) * k0.l + (s3 - 2 * s2 + s) * h * k0.v + (-2 * s3 + 3 * s2) * k.l +
             (s3 - s2) * h * k.v;
      ks.v = k0.v + s * (k.v - k0.v);
      ks.a = k0.a + s * (k.a - k0.a);
      solver_->step(t0 + s * h, ks);
    }
    solver_->step(t, k);
  } catch (const std::domain_error&) {
    ++domain_errors_;
    return false;
  }
  ++steps_;
  t_ = t;
  kin_ = k;
  finishStep(t);
  return true;
}

bool TwinCore::finishStep(double t, bool allow_fault_check) {
  (void)allow_fault_check;
  const double h = cfg_.shaft.h;
  for (int attempt = 0; attempt < 2; ++attempt) {
    bool ok = solver_->finite() && !inject_fault_;
    inject_fault_ = false;
    if (ok) {
      const CageResponse& r = solver_->response();
      const double gdef = envelope_.evaluate(*solver_);
      out_.t = t - t_pub_offset_;
      out_.kin = r.kin;
      out_.x_c = r.x_c;
      out_.y_c = r.y_c;
      out_.theta = r.theta;
      out_.lambda = r.lambda;
      out_.clearance = computeClearance(r.y_c, r.theta, h, gdef, cfg_.alarms);
      ok = allFinite(out_);
    }
    if (ok) {
      alarms_.setModelFault(t, false, events_);
      alarms_.updateClearance(t, out_.clearance, events_);
      out_.alarm_level = alarms_.highestActive();
      out_.degraded = degradedNow();
      out_.input_seq = have_input_ ? last_.seq : -1;
      return true;
    }
    // Non-finite state: raise MODEL_FAULT and restart from static equilibrium
    // at the current kinematics (or the initial length if those are bad too).
    ++faults_;
    ++resets_;
    alarms_.setModelFault(t, true, events_);
    fault_until_ = t + cfg_.service.fault_hold;
    Kinematics k = kin_;
    if (!std::isfinite(k.l) || !lengthOk(k.l)) k.l = cfg_.shaft.l0;
    if (!std::isfinite(k.v) || !std::isfinite(k.a)) k.v = k.a = 0.0;
    kin_ = k;
    solver_->initialize(t, k, InitialState::Static);
  }
  // Still not finite: publish nothing trustworthy.
  out_.degraded = true;
  return false;
}

bool TwinCore::degradedNow() const {
  return !have_input_ || stale_ || t_ < fault_until_;
}

double TwinCore::staleTimeout() const {
  const ServiceConfig& s = cfg_.service;
  if (clock_ != ClockMode::Wall || !(s.stale_periods > 0.0) || !(period_est_ > 0.0)) return s.stale_timeout;
  return std::min(s.stale_timeout, std::max(s.stale_min, s.stale_periods * period_est_));
}

void TwinCore::setStale(bool stale) {
  stale_ = stale;
  alarms_.setInputStale(t_, stale, events_);
  if (stale) {
    validator_.resync();
    stream_ = false;
  }
  out_.degraded = degradedNow();
  out_.alarm_level = alarms_.highestActive();
}

InputResult TwinCore::onInput(const WinderSample& s, double wall_now) {
  if (start_wall_ < 0.0) start_wall_ = wall_now;
  InputResult res;
  const Verdict v = validator_.check(s);
  auto reject = [&](RejectReason r) {
    counters_.reject(r);
    res.accepted = false;
    res.reason = r;
    return res;
  };
  if (!v.ok) return reject(v.reason);
  const bool new_stream = !validator_.hasReference();
  // Input period of this stream, from the sender's time stamps (immune to
  // network jitter); lost messages only make the estimate more lenient.
  const double period = new_stream ? 0.0 : static_cast<double>(s.utime - validator_.last().utime) * 1e-6;

  if (clock_ == ClockMode::Input) {
    double t;
    Kinematics k;
    const bool first = !started_;
    if (first) {
      t = 0.0;
      k = Kinematics{s.has_length ? s.length : cfg_.shaft.l0, s.v, s.a};
    } else {
      if (new_stream) {
        // A restarted stream continues model time one nominal period later.
        t = t_ + 1.0 / cfg_.service.rate;
      } else {
        t = t_base_ + static_cast<double>(s.utime - utime_base_) / 1e6;
      }
      if (!(t > t_)) return reject(RejectReason::TimeBackwards);
      k = s.has_length ? Kinematics{s.length, s.v, s.a} : integrate(kin_, s.v, s.a, t - t_);
    }
    if (!lengthOk(k.l)) return reject(RejectReason::LengthRange);
    if (first || new_stream) {
      utime_base_ = s.utime;
      t_base_ = t;
    }
    // Accept before stepping so the output reflects the new input state.
    validator_.accept(s);
    last_ = s;
    last_input_wall_ = wall_now;
    have_input_ = true;
    stream_ = true;
    if (stale_) setStale(false);
    if (first) {
      initializeAt(t, k);
    } else if (new_stream && std::fabs(k.l - kin_.l) > cfg_.service.max_length_jump) {
      initializeAt(t, k);
      res.reinitialized = true;
    } else if (!advance(t, k)) {
      return reject(RejectReason::ModelDomain);
    }
    out_.input_utime = s.utime;
    res.stepped = true;
  } else {
    validator_.accept(s);
    last_ = s;
    last_input_wall_ = wall_now;
    const bool first_input = !have_input_;
    have_input_ = true;
    stream_ = true;
    if (stale_) setStale(false);
    if (first_input) {
      // The twin idled at rest at l0 until now.  Start the trip here: the
      // model is re-initialized at this input's kinematics (consistent with
      // a winder already moving), and the published time t counts from this
      // instant, so HOIST_CAGE.t is trip time, comparable with hoist-sim for
      // the same profile.
      const Kinematics k{s.has_length ? s.length : kin_.l, s.v, s.a};
      if (lengthOk(k.l)) {
        const auto resets = resets_;
        res.reinitialized = s.has_length && std::fabs(s.length - kin_.l) > cfg_.service.max_length_jump;
        // The trip starts when the input arrived (the daemon's wall clock
        // and its tick times share one time base), not at the last tick.
        const double t0 = std::max(t_, wall_now);
        t_pub_offset_ = t0;
        initializeAt(t0, k);
        resets_ = resets;
      }
    } else if (new_stream && s.has_length && std::fabs(s.length - kin_.l) > cfg_.service.max_length_jump) {
      initializeAt(t_, Kinematics{s.length, s.v, s.a});
      res.reinitialized = true;
    }
    out_.degraded = degradedNow();
  }
  if (new_stream) period_est_ = 0.0;
  else if (period > 0.0) period_est_ = period_est_ > 0.0 ? 0.9 * period_est_ + 0.1 * period : period;
  ++counters_.accepted;
  counters_.seq_gaps += v.skipped;
  res.accepted = true;
  return res;
}

TickResult TwinCore::tick(double t, double wall_now) {
  TickResult res;
  if (clock_ != ClockMode::Wall || !started_ || !(t > t_)) return res;
  const double dt = t - t_;
  Kinematics k;
  if (!have_input_ || stale_) {
    k = Kinematics{kin_.l, 0.0, 0.0};
  } else if (last_.has_length) {
    const double tau = std::clamp(wall_now - last_input_wall_, 0.0, staleTimeout());
    k = Kinematics{last_.length + last_.v * tau, last_.v, last_.a};
  } else {
    k = integrate(kin_, last_.v, last_.a, dt);
  }
  if (!lengthOk(k.l)) {
    // The winder drove the integrated length out of the shaft: hold.
    ++domain_errors_;
    res.domain_error = true;
    k = Kinematics{kin_.l, 0.0, 0.0};
  }
  const auto faults0 = faults_;
  if (!advance(t, k)) {
    res.domain_error = true;
    return res;
  }
  res.stepped = true;
  res.fault = faults_ != faults0;
  return res;
}

void TwinCore::housekeeping(double wall_now) {
  if (start_wall_ < 0.0) start_wall_ = wall_now;
  bool stale_now;
  if (have_input_)
    stale_now = wall_now - last_input_wall_ > staleTimeout();
  else
    stale_now = clock_ == ClockMode::Wall && wall_now - start_wall_ > cfg_.service.stale_timeout;
  if (stale_now && !stale_) setStale(true);
  alarms_.poll(t_, events_);
  out_.alarm_level = alarms_.highestActive();
  out_.degraded = degradedNow();
}

int TwinCore::command(AlarmAction action, std::optional<AlarmKind> kind, AlarmLevel level,
                      double shelve_duration) {
  int n = 0;
  switch (action) {
    case AlarmAction::Ack: n = alarms_.acknowledge(t_, kind, level, events_); break;
    case AlarmAction::Shelve: n = alarms_.shelve(t_, kind, level, shelve_duration, events_); break;
    case AlarmAction::Unshelve: n = alarms_.unshelve(t_, kind, level, events_); break;
  }
  out_.alarm_level = alarms_.highestActive();
  return n;
}

}  // namespace hoist::svc
