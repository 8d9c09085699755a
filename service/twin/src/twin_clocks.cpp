// TwinCore's clocks (ClockPolicy, hoist/service/twin/twin_core.hpp): what model
// time is and how an input and a tick move the twin.  InputClock (--clock
// input): model time is the input's utime, one step per accepted input.
// WallClock (--clock wall): model time is the daemon's timer; inputs only
// update the latest sample.  makeClock() is called once by TwinCore's
// constructor; the policy lives as long as its TwinCore and is used on its
// thread only.  The rest of TwinCore is twin_core.cpp.
#include <algorithm>
#include <cmath>
#include <limits>

#include "hoist/service/twin/twin_core.hpp"

namespace hoist::service::inline twin {

// ---- clock policies -------------------------------------------------------------

/// Model time = the input's utime (relative to the stream's first): one step
/// and one output per accepted input.
class InputClock final : public ClockPolicy {
 public:
  ClockMode mode() const override { return ClockMode::Input; }

  InputResult onInput(TwinCore& c, const WinderSample& s, bool new_stream, double wall_now) override {
    InputResult res;
    double t;
    Kinematics k;
    const bool first = !c.started_;
    if (first) {
      t = 0.0;
      k = Kinematics{s.has_length ? s.length : c.cfg_.shaft.l0, s.v, s.a};
    } else {
      // A restarted stream continues model time one nominal period later.
      t = new_stream ? c.t_ + 1.0 / c.cfg_.service.rate : modelTime(s.utime);
      if (!(t > c.t_)) return reject(c, res, RejectReason::TimeBackwards);
      k = s.has_length ? Kinematics{s.length, s.v, s.a} : c.integrate(c.kin_, s.v, s.a, t - c.t_);
    }
    if (!c.lengthOk(k.l)) {
      c.setDomain(true, k.l);
      res.republish = c.started_;
      return reject(c, res, s.has_length ? RejectReason::LengthRange : RejectReason::ModelDomain);
    }
    if (first || new_stream) {
      utime_base_ = s.utime;
      t_base_ = t;
    }
    c.acceptSample(s, wall_now);
    c.setDomain(false, k.l);
    if (first) {
      c.initializeAt(t, k);
    } else if (new_stream && std::fabs(k.l - c.kin_.l) > c.cfg_.service.max_length_jump) {
      c.initializeAt(t, k);
      res.reinitialized = true;
    } else if (!c.advance(t, k)) {
      return reject(c, res, RejectReason::ModelDomain);
    }
    c.out_.input_utime = s.utime;
    res.stepped = true;
    res.accepted = true;
    return res;
  }

  TickResult tick(TwinCore&, double, double) override { return {}; }
  double staleTimeout(const TwinCore& c) const override { return c.cfg_.service.stale_timeout; }
  double sensorTime(const TwinCore& c, std::int64_t utime, double, std::int64_t, double& offset) const override {
    // The daemon's clock is the winder stream's: the sample's time on it.
    // Before the first winder input there is none: the sample is applied at
    // the first step (as hoist-estimate applies the first row's sensors).
    if (!c.started_ || !c.have_input_) {
      offset = 0.0;
      return -std::numeric_limits<double>::infinity();
    }
    offset = static_cast<double>(utime - c.last_.utime) * 1e-6;
    return modelTime(utime);
  }

 private:
  // The model time of a utime: one formula for the winder's samples and the
  // sensors', so that a sensor sample stamped with a winder sample's utime
  // lands exactly on that step (a division, not * 1e-6: the two differ in
  // the last bit for 30 % of the utimes; the sample was then aligned from
  // an instant one ulp before its step, and the estimate drifted from
  // hoist-estimate's by rounding).
  double modelTime(std::int64_t utime) const { return t_base_ + static_cast<double>(utime - utime_base_) / 1e6; }

  static InputResult reject(TwinCore& c, InputResult& res, RejectReason r) {
    c.counters_.reject(r);
    res.accepted = false;
    res.reason = r;
    return res;
  }
  std::int64_t utime_base_ = 0;  // utime at model time t_base_
  double t_base_ = 0.0;
};

/// Model time = the daemon's timer; inputs only update the latest sample.
class WallClock final : public ClockPolicy {
 public:
  ClockMode mode() const override { return ClockMode::Wall; }

  InputResult onInput(TwinCore& c, const WinderSample& s, bool new_stream, double wall_now) override {
    InputResult res;
    // Held at the end of the valid range: an input that keeps driving the
    // rope outward is rejected (model_domain); one that turns back resumes.
    if (c.domain_outside_ && !s.has_length && c.started_) {
      const bool at_top = c.kin_.l - c.range_.lo < c.range_.hi - c.kin_.l;
      if ((at_top && s.v < 0.0) || (!at_top && s.v > 0.0)) {
        c.counters_.reject(RejectReason::ModelDomain);
        res.reason = RejectReason::ModelDomain;
        return res;
      }
    }
    const bool first_input = !c.have_input_;
    c.acceptSample(s, wall_now);
    if (s.has_length || !c.domain_outside_) c.setDomain(false, s.has_length ? s.length : c.kin_.l);
    else c.setDomain(false, c.kin_.l);
    if (c.start_pending_) {
      // A deferred start waits: carry an encoder-less length forward with
      // this sample (the ticks would have integrated it likewise).
      if (!s.has_length) {
        const double dt = std::max(0.0, wall_now - c.pend_t_);
        c.pend_k_ = c.integrate(c.pend_k_, s.v, s.a, dt);
        c.pend_t_ = std::max(c.pend_t_, wall_now);
      }
    } else if (first_input) {
      // The twin idled at rest at l0 until now.  Start the trip here: the
      // model is re-initialized at this input's kinematics (consistent with
      // a winder already moving), and the published time counts from this
      // instant (trip time, comparable with hoist-sim for the same profile).
      const Kinematics k{s.has_length ? s.length : c.kin_.l, s.v, s.a};
      if (c.lengthOk(k.l) && c.defer_starts_) {
        res.reinitialized = s.has_length && std::fabs(s.length - c.kin_.l) > c.cfg_.service.max_length_jump;
        c.deferStart(wall_now, k, true);
      } else if (c.lengthOk(k.l)) {
        const auto resets = c.resets_;
        res.reinitialized = s.has_length && std::fabs(s.length - c.kin_.l) > c.cfg_.service.max_length_jump;
        // The trip starts when the input arrived (the daemon's wall clock
        // and its tick times share one time base), not at the last tick.
        const double t0 = std::max(c.t_, wall_now);
        c.t_pub_offset_ = t0;
        c.initializeAt(t0, k);
        c.resets_ = resets;
      }
    } else if (new_stream && s.has_length && std::fabs(s.length - c.kin_.l) > c.cfg_.service.max_length_jump) {
      if (c.defer_starts_) c.deferStart(wall_now, Kinematics{s.length, s.v, s.a}, false);
      else c.initializeAt(c.t_, Kinematics{s.length, s.v, s.a});
      res.reinitialized = true;
    }
    c.out_.degraded = c.degradedNow();
    res.accepted = true;
    return res;
  }

  TickResult tick(TwinCore& c, double t, double wall_now) override {
    TickResult res;
    if (!c.started_ || c.start_pending_ || !(t > c.t_)) return res;
    const double dt = t - c.t_;
    Kinematics k;
    if (!c.have_input_ || c.stale_) {
      k = Kinematics{c.kin_.l, 0.0, 0.0};
    } else if (c.last_.has_length) {
      const double tau = std::clamp(wall_now - c.last_input_wall_, 0.0, c.staleTimeout());
      k = Kinematics{c.last_.length + c.last_.v * tau, c.last_.v, c.last_.a};
    } else {
      k = c.integrate(c.kin_, c.last_.v, c.last_.a, dt);
    }
    if (!c.lengthOk(k.l)) {
      // The winder drove the rope length out of the valid range: hold.
      ++c.domain_errors_;
      res.domain_error = true;
      c.setDomain(true, k.l);
      k = Kinematics{c.kin_.l, 0.0, 0.0};
    }
    const auto faults0 = c.faults_, catchups0 = c.catchups_;
    if (!c.advance(t, k, c.cfg_.service.max_catchup_periods / c.cfg_.service.rate)) {
      res.domain_error = true;
      return res;
    }
    res.stepped = true;
    res.fault = c.faults_ != faults0;
    res.catchup_limited = c.catchups_ != catchups0;
    return res;
  }

  double staleTimeout(const TwinCore& c) const override { return c.periodStaleTimeout(); }
  double sensorTime(const TwinCore&, std::int64_t utime, double wall_now, std::int64_t wall_utime,
                    double& offset) const override {
    // Model time is the daemon's wall clock: the sample is `offset` from now.
    offset = static_cast<double>(utime - wall_utime) * 1e-6;
    return wall_now + offset;
  }
};

std::unique_ptr<ClockPolicy> makeClock(ClockMode mode) {
  if (mode == ClockMode::Input) return std::make_unique<InputClock>();
  return std::make_unique<WallClock>();
}

}  // namespace hoist::service::twin
