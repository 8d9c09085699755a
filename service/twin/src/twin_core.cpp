// The twin's logic without I/O: see hoist/service/twin/twin_core.hpp.
#include "hoist/service/twin/twin_core.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hoist::service::inline twin {

namespace {

InputLimits limitsFrom(const TwinConfig& c) {
  const LengthRange r = validLengthRange(c.shaft);
  InputLimits l;
  l.max_speed = c.service.max_speed;
  l.max_accel = c.service.max_accel;
  l.max_length_jump = c.service.max_length_jump;
  l.max_time_step = c.service.max_time_step;
  // The validator's bounds are exclusive: [lo, hi] up to rounding.
  l.min_length = std::nextafter(r.lo, -1.0);
  l.max_length = std::nextafter(r.hi, 1e300);
  l.accel_tolerance = c.service.accel_tolerance;
  l.velocity_tolerance = c.service.velocity_tolerance;
  l.consistency_window = c.service.consistency_window;
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

// ---- TwinCore -------------------------------------------------------------------

TwinCore::TwinCore(const TwinConfig& cfg, ClockMode clock, std::unique_ptr<Solver> solver)
    : cfg_(cfg),
      clock_(makeClock(clock)),
      solver_(solver ? std::move(solver) : defaultSolver(cfg)),
      envelope_(solver_->model(), cfg.service.envelope_points),
      envelope_tol_(cfg.service.envelope_tolerance * cfg.alarms.guide_rope_gap),
      shape_(solver_->model(), cfg.service.shape_points),
      validator_(limitsFrom(cfg)),
      alarms_(cfg.alarms),
      range_(validLengthRange(cfg.shaft)),
      bounds_(twinPlausibilityBounds(cfg, cfg.shaft)),
      // The predictions kept cover max_clock_offset at the step rate, and more.
      timing_(cfg.estimator.max_clock_offset,
              std::max<std::size_t>(64, static_cast<std::size_t>(std::ceil(1.5 * cfg.estimator.max_clock_offset *
                                                                             cfg.service.rate)) + 16)),
      gate_(cfg.alarms, cfg.estimator.clear_hold) {
  cfg_.service.validate();
  cfg_.estimator.validate();
  // Envelope evaluations may be deferred below the GUIDE_ROPE WARNING
  // alarm's clear level: taken from that alarm's own settings.
  const AlarmSettings& gw = alarms_.find(AlarmKind::GuideRope, AlarmLevel::Warning)->settings();
  envelope_defer_below_ = gw.threshold - gw.deadband;
  if (!range_.contains(cfg_.shaft.l0))
    throw std::invalid_argument("hoisting_rope.initial_length: " + std::to_string(cfg_.shaft.l0) +
                                " m is outside the model's valid range [" + std::to_string(range_.lo) + ", " +
                                std::to_string(range_.hi) + "] m (0.05 m from either end)");
  if (cfg_.estimator.enabled) {
    if (solver_->method() != Method::Fast)
      throw std::invalid_argument("estimator.enabled: the load estimator needs the fast solver (method fast)");
    est_ = std::make_unique<LoadEstimator>(cfg_.shaft, cfg_.estimator.settings);
  }
  if (clock == ClockMode::Wall) {
    // The wall-clock twin runs from start-up: at rest at the initial length
    // until the winder speaks.
    initializeAt(0.0, Kinematics{cfg_.shaft.l0, 0.0, 0.0});
    resets_ = 0;
  }
}

void TwinCore::adoptModel(std::unique_ptr<TwinModel>& m) {
  if (!m || !m->solver || m->solver->method() != solver_->method() ||
      m->solver->model().n() != solver_->model().n() || (est_ && !m->estimator.sens))
    throw std::invalid_argument("TwinCore::adoptModel: a model of the same method and n (with the estimator's "
                                "solvers when it is enabled) is needed");
  if (est_) est_->swapModel(m->estimator);
  m->envelope.carryCountsFrom(envelope_);
  std::swap(solver_, m->solver);
  std::swap(envelope_, m->envelope);
  std::swap(shape_, m->shape);
  std::swap(bounds_, m->bounds);
  std::swap(cfg_.shaft, m->shaft);
  std::swap(preload_scale_, m->preload_scale);
  preload_mismatch_ = false;  // the trip-end verdict judged the old preload
  if (!started_) return;  // the first start initializes the new model
  // The new model's equilibrium at the current kinematics (the caller swaps
  // at rest, where the state is static); the estimator's loads carry over.
  solver_->initialize(t_, kin_);
  if (est_) {
    est_->restart(t_, kin_);
    est_synced_ = true;
    timing_.reset(true);  // the queued samples were predicted by the old model
  }
  finishStep(t_);
}

Kinematics TwinCore::integrate(const Kinematics& k0, double v1, double a1, double dt) const {
  return Kinematics{integrateLength(k0.l, k0.v, k0.a, v1, a1, dt), v1, a1};
}

void TwinCore::acceptSample(const WinderSample& s, double wall_now) {
  validator_.accept(s);
  last_ = s;
  if (s.has_length) length_unverified_ = false;  // the encoder anchors the length again
  last_input_wall_ = wall_now;
  have_input_ = true;
  stream_ = true;
  if (stale_) setStale(false);
}

void TwinCore::initializeAt(double t, const Kinematics& k) {
  if (started_) ++resets_;
  solver_->initialize(t, k);
  if (est_) {
    // The first start takes the configured load as the prior; a restart
    // (new stream, fault) keeps what the sensors taught.
    if (started_) est_->restart(t, k);
    else est_->initialize(t, k);
    est_synced_ = true;
    timing_.reset(started_);  // a restart: the queued samples are of the old stream
    gate_.reset();
  }
  t_ = t;
  kin_ = k;
  started_ = true;
  finishStep(t);
}

bool TwinCore::advance(double t, const Kinematics& k, double max_interval) {
  const double t0 = t_, h = t - t_;
  int n = 1;
  try {
    if (max_interval > 0.0 && h > max_interval * (1.0 + 1e-9)) {
      // The loop was late by more than the catch-up bound: cross the gap
      // with the substeps of max_interval (longer ones), flag and count it.
      n = substepCount(max_interval, cfg_.service.max_step, kMaxSubsteps);
      ++catchups_;
      catchup_until_ = t;
    } else if (h > 0.0) {
      n = substepCount(h, cfg_.service.max_step, kMaxSubsteps);
    }
  } catch (const std::invalid_argument&) {
    n = kMaxSubsteps;  // unreachable: ServiceConfig::validate() bounds max_step
  }
  const Kinematics k0 = kin_;
  try {
    for (int j = 1; j < n; ++j) {
      const double u = static_cast<double>(j) / n;
      solver_->step(t0 + u * h, interpolate(k0, k, h, u));
    }
    solver_->step(t, k);
  } catch (const std::domain_error&) {
    ++domain_errors_;
    est_synced_ = false;  // until the next initialization
    return false;
  }
  if (est_ && est_synced_) {
    try {
      est_->advance(t, k, n);
    } catch (const std::exception&) {
      est_synced_ = false;
    }
  }
  ++steps_;
  t_ = t;
  kin_ = k;
  finishStep(t);
  return true;
}

void TwinCore::setDomain(bool outside, double l) {
  if (outside == domain_outside_ && !outside) return;
  domain_outside_ = outside;
  const double limit = l < range_.lo ? range_.lo : range_.hi;
  alarms_.setModelDomain(t_, outside, l, limit, events_);
  out_.degraded = degradedNow();
  out_.alarm_level = alarms_.highestActive();
}

void TwinCore::setDuplicatePublisher(bool seen, double other_id) {
  alarms_.setDuplicatePublisher(t_, seen, other_id, events_);
  out_.alarm_level = alarms_.highestActive();
}

void TwinCore::setPredictions(bool clearance, double clearance_s, bool slack, double slack_s, double horizon,
                              bool from_estimate) {
  const std::size_t first = events_.size();
  alarms_.setPredictedClearance(t_, clearance, clearance_s, horizon, events_);
  alarms_.setPredictedSlack(t_, slack, slack_s, horizon, events_);
  if (from_estimate) events_.markFromEstimate(first);
  out_.alarm_level = alarms_.highestActive();
}

void TwinCore::setCondition(AlarmLevel preload, double upper95, double warning, double critical, bool fingerprint,
                            double z, double z_limit) {
  alarms_.setGuidePreloadLow(t_, preload, upper95, warning, critical, events_);
  alarms_.setShaftFingerprint(t_, fingerprint, z, z_limit, events_);
  out_.alarm_level = alarms_.highestActive();
}

bool TwinCore::finishStep(double t, bool allow_fault_check) {
  (void)allow_fault_check;
  const double h = cfg_.shaft.h;
  for (int attempt = 0; attempt < 2; ++attempt) {
    bool ok = solver_->finite() && !inject_fault_;
    inject_fault_ = false;
    const char* what_now = "non-finite";
    double value_now = 1.0, limit_now = 0.0;
    if (ok) {
      const CageResponse& r = solver_->response();
      // Finite is not enough: a state beyond the plausibility bound
      // (hoist/plausibility.hpp) is a model fault too.
      double value = 0.0, limit = 0.0;
      if (const char* what = implausible(r, h, bounds_, value, limit)) {
        ok = false;
        what_now = what;
        value_now = std::isfinite(value) ? value : 0.0;
        limit_now = limit;
        counters_.reject(RejectReason::Implausible);
      }
    }
    if (ok) {
      const CageResponse& r = solver_->response();
      // The deflection alarm's envelope: exact, or a conservative bound
      // within envelope_tol_ of it (service.envelope_tolerance), or -- with
      // the caller's budget of exact evaluations spent -- a wider bound that
      // no GUIDE_ROPE alarm can tell from the exact one (EnvelopeBudget in
      // twin_core.hpp).
      const auto e0 = std::chrono::steady_clock::now();
      const bool defer = envelope_budget_ && *envelope_budget_ <= 0;
      double gdef = envelope_.evaluateBounded(*solver_, envelope_tol_,
                                              defer ? envelope_defer_below_ : -std::numeric_limits<double>::infinity());
      // Never fault on a bound: look exactly first.
      if (!(gdef <= bounds_.lateral) && !envelope_.lastExact()) gdef = envelope_.evaluate(*solver_);
      if (envelope_budget_ && envelope_.lastExact()) --*envelope_budget_;
      envelope_ns_ += std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - e0).count();
      out_.t = publishedTime(t);
      out_.kin = r.kin;
      out_.x_c = r.x_c;
      out_.y_c = r.y_c;
      out_.theta = r.theta;
      out_.lambda = r.lambda;
      out_.clearance = computeClearance(r.y_c, r.theta, h, gdef, cfg_.alarms);
      ok = allFinite(out_);
      if (ok && !(gdef <= bounds_.lateral)) {
        ok = false;
        what_now = "guide_deflection";
        value_now = gdef;
        limit_now = bounds_.lateral;
        counters_.reject(RejectReason::Implausible);
      }
    }
    if (ok) {
      alarms_.setModelFault(t, false, events_);
      // With the load estimator healthy, the clearance and rope-force alarms
      // judge the state the estimated load implies (the guide-rope envelope
      // stays the twin's); HOIST_CAGE keeps the open-loop state.  Which one,
      // and the hold after a switch or a load change: EstimateGate.
      const Judgement open{out_.clearance, out_.lambda[0], out_.lambda[0]};
      const Judgement* judged = &open;
      est_in_use_ = false;
      if (est_ && est_synced_) {
        estimatorStep(solver_->response());
        const LoadEstimate& e = est_->estimate();
        const unsigned not_used = estimateNotUsed(e);
        Judgement est = open;
        if (!(not_used & (kNotUsedNonFinite | kNotUsedImplausible))) {
          est.clearance = computeClearance(e.y_c, e.theta, h, out_.clearance.guide_deflection, cfg_.alarms);
          est.lambda0_slack = est.lambda0_overload = e.lambda[0];
        }
        judged = &gate_.step(t, not_used == 0, not_used, est, open, est_->counters().load_changes, e.Fa, e.moment);
        est_in_use_ = gate_.inUse();
        if (e.mismatch)
          alarms_.setModelMismatch(t, true, e.nis_exceeded ? e.nis_window : e.drift,
                                   e.nis_exceeded ? e.nis_bound : est_->settings().drift_sigma, events_);
        else  // the trip-end preload test, or neither
          alarms_.setModelMismatch(t, preload_mismatch_, std::abs(preload_z_), preload_limit_, events_);
      }
      alarms_.setSensorFault(t, t < sensor_fault_until_, sensor_fault_.value, sensor_fault_.limit, events_);
      out_.clearance = judged->clearance;
      const std::size_t first = events_.size();
      alarms_.updateClearance(t, out_.clearance, events_);
      // Rope force against the static force at this length.
      alarms_.updateRopeForce(t, judged->lambda0_slack, judged->lambda0_overload,
                              solver_->model().staticRopeForce(out_.kin.l), events_);
      if (est_in_use_) events_.markFromEstimate(first);
      out_.rope_slack_threshold = alarms_.ropeSlackThreshold();
      out_.rope_overload_threshold = alarms_.ropeOverloadThreshold();
      out_.alarm_level = alarms_.highestActive();
      out_.degraded = degradedNow();
      out_.input_seq = have_input_ ? last_.seq : -1;
      return true;
    }
    // Non-finite or implausible state: raise MODEL_FAULT and restart from
    // static equilibrium at the current kinematics (or the initial length if
    // those are bad too).
    ++faults_;
    ++resets_;
    fault_what_ = what_now;
    fault_value_ = value_now;
    fault_limit_ = limit_now;
    alarms_.setModelFaultDetail(fault_value_, fault_limit_);
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
  return !have_input_ || stale_ || t_ < fault_until_ || domain_outside_ || t_ <= catchup_until_ ||
         length_unverified_;
}

void TwinCore::lostMotion(RejectReason r) {
  // A replayed sample (duplicate or older) carries no motion the twin lacks;
  // any other rejected input of a stream without an encoder might have.
  if (!started_ || !have_input_ || last_.has_length) return;
  if (r == RejectReason::DuplicateSeq || r == RejectReason::TimeBackwards) return;
  length_unverified_ = true;
  out_.degraded = true;
}

double TwinCore::periodStaleTimeout() const {
  const ServiceConfig& s = cfg_.service;
  if (!(s.stale_periods > 0.0) || !(period_est_ > 0.0)) return s.stale_timeout;
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

namespace {
/// The caller's envelope budget, held by the core for one call only.
class BudgetScope {
 public:
  BudgetScope(int*& slot, int* budget) : slot_(slot) { slot_ = budget; }
  ~BudgetScope() { slot_ = nullptr; }
  BudgetScope(const BudgetScope&) = delete;
  BudgetScope& operator=(const BudgetScope&) = delete;

 private:
  int*& slot_;
};
}  // namespace

InputResult TwinCore::onInput(const WinderSample& s, double wall_now, int* envelope_budget) {
  const BudgetScope budget(envelope_budget_, envelope_budget);
  if (start_wall_ < 0.0) start_wall_ = wall_now;
  const Verdict v = validator_.check(s);
  if (!v.ok) {
    counters_.reject(v.reason);
    if (!s.has_length) lostMotion(v.reason);
    // An encoder length outside the valid range is the MODEL_DOMAIN condition.
    if (v.reason == RejectReason::LengthRange) setDomain(true, s.length);
    InputResult res;
    res.reason = v.reason;
    res.republish = v.reason == RejectReason::LengthRange && clock_->mode() == ClockMode::Input && started_;
    return res;
  }
  const bool new_stream = !validator_.hasReference();
  // Input period of this stream, from the sender's time stamps (immune to
  // network jitter); lost messages only make the estimate more lenient.
  const double period = new_stream ? 0.0 : static_cast<double>(s.utime - validator_.last().utime) * 1e-6;
  InputResult res = clock_->onInput(*this, s, new_stream, wall_now);
  if (!res.accepted) {
    if (!s.has_length) lostMotion(res.reason);
    return res;
  }
  if (new_stream) period_est_ = 0.0;
  else if (period > 0.0) period_est_ = period_est_ > 0.0 ? 0.9 * period_est_ + 0.1 * period : period;
  ++counters_.accepted;
  counters_.seq_gaps += v.skipped;
  return res;
}

TickResult TwinCore::tick(double t, double wall_now, int* envelope_budget) {
  const BudgetScope budget(envelope_budget_, envelope_budget);
  return clock_->tick(*this, t, wall_now);
}

void TwinCore::deferStart(double wall_now, const Kinematics& k, bool first) {
  start_pending_ = true;
  if (first && !pending_first_) pend_trip_t_ = std::max(t_, wall_now);
  pending_first_ = pending_first_ || first;
  pend_t_ = wall_now;
  pend_k_ = k;
  ++starts_deferred_;
}

void TwinCore::completeStart(double t_prev, double wall_now, int* envelope_budget) {
  if (!start_pending_) return;
  const BudgetScope budget(envelope_budget_, envelope_budget);
  start_pending_ = false;
  // At the previous tick's model time, so that the coming tick steps one
  // ordinary period (no catch-up across the ticks the start waited), but
  // never before the input that asked for it nor before the model's time.
  const double t0 = std::max({t_, pend_t_, t_prev});
  Kinematics k;
  if (last_.has_length) {
    const double tau = std::clamp(t0 - last_input_wall_, 0.0, staleTimeout());
    k = Kinematics{last_.length + last_.v * tau, last_.v, last_.a};
  } else {
    k = integrate(pend_k_, last_.v, last_.a, std::max(0.0, t0 - pend_t_));
  }
  (void)wall_now;
  if (!lengthOk(k.l)) {
    // The winder left the valid range meanwhile: the tick holds and raises
    // MODEL_DOMAIN as for any input (the start is not retried).
    pending_first_ = false;
    return;
  }
  const bool first = pending_first_;
  pending_first_ = false;
  const auto resets = resets_;
  if (first) t_pub_offset_ = pend_trip_t_;
  initializeAt(t0, k);
  if (first) resets_ = resets;
}

void TwinCore::housekeeping(double wall_now) {
  if (start_wall_ < 0.0) start_wall_ = wall_now;
  bool stale_now;
  if (have_input_)
    stale_now = wall_now - last_input_wall_ > staleTimeout();
  else
    stale_now = clock_->mode() == ClockMode::Wall && wall_now - start_wall_ > cfg_.service.stale_timeout;
  if (stale_now && !stale_) setStale(true);
  if (est_) alarms_.setSensorFault(t_, t_ < sensor_fault_until_, sensor_fault_.value, sensor_fault_.limit, events_);
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
    case AlarmAction::Reannounce: n = alarms_.reannounce(t_, kind, level, events_); break;
    case AlarmAction::Calibrate: break;     // not an alarm command: calibrate()
    case AlarmAction::AdoptPreload: break;  // not an alarm command: adoptModel() (the daemon's PreloadKeeper)
  }
  out_.alarm_level = alarms_.highestActive();
  out_.degraded = degradedNow();
  return n;
}

}  // namespace hoist::service::twin
