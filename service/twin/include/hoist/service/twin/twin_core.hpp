// hoist/service/twin/twin_core.hpp -- the twin's logic without any I/O: input
// validation, kinematics following, model stepping and fault recovery,
// clearance alarms.  hoist-twind wraps it with LCM and timers; tests drive
// it directly.
//
// Kinematics (docs/model.md: l = hoisting-rope length = depth of the cage's top
// sleeves, v = dl/dt > 0 descending, a = dv/dt):
//   * when a winder sample carries the encoder length the twin follows it;
//   * otherwise l is integrated from v, starting at the shaft config's
//     initial_length (or the first encoder length seen), with the model's
//     hoist::integrateLength (corrected trapezoid, exact for piecewise-cubic
//     l; its derivation and error bounds are in hoist/profile.hpp), the same
//     function HoistProfile::fromVelocity uses;
//   * substeps (service.max_step) interpolate with hoist::interpolate, the
//     profile's own Hermite interpolation, and count with
//     hoist::substepCount, as hoist::simulate does.
//   * the rope length must stay in the model's valid range
//     hoist::validLengthRange = [0.05 m, L - 2h - 0.05 m]; outside it the
//     input is rejected (length_range / model_domain), MODEL_DOMAIN is raised
//     naming the length and the limit, the model holds its last valid state
//     and every output is flagged degraded.
//
// Clocks (a policy object, ClockPolicy, chosen at construction; twin_clocks.cpp):
//   * InputClock -- onInput() steps the model exactly to each accepted
//     sample's time t = (utime - utime_first) / 1e6 s; one output per input.
//     Deterministic: the same input sequence gives bit-identical outputs.
//   * WallClock -- onInput() only stores the latest sample; tick(t) steps the
//     model to model time t (the daemon's timer).  Between samples the
//     encoder length is extrapolated with v for at most stale_timeout.
//     While the input is stale the twin holds l with v = a = 0.  A tick
//     integrates at most max_catchup_periods periods at full accuracy.
//
// Time origin: every published time (HOIST_CAGE.t, HOIST_ALARM.t,
// HOIST_HEALTH.t, HOIST_GUIDE_SHAPE.t) is publishedTime(model time): seconds
// since the trip start = the first accepted winder input.  Before the first
// input (the wall-clock twin idles at rest) it counts from the daemon's start.
// Every time-dependent alarm rule (delays, shelving, re-announce) runs on
// model time.  Staleness is judged on the caller's wall clock (`wall_now`,
// seconds, monotonic).
//
// Real time: after construction nothing here allocates (the solver's fast
// path, GuideRopeEnvelope and the fixed-size event buffer do not).
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>

#include "hoist/contract/alarm_command.hpp"
#include "hoist/service/core/alarms.hpp"
#include "hoist/service/core/config.hpp"
#include "hoist/service/twin/estimate_gate.hpp"
#include "hoist/service/twin/sensor_timing.hpp"
#include "hoist/service/twin/twin_model.hpp"
#include "hoist/service/core/input_validator.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/plausibility.hpp"
#include "hoist/guide_rope_envelope.hpp"
#include "hoist/solver.hpp"

namespace hoist::service::inline twin {

/// One published cage state (see msgs/cage_state_t.lcm).
struct CageOutput {
  double t = 0.0;
  Kinematics kin;
  double x_c = 0.0, y_c = 0.0, theta = 0.0;
  std::array<double, 5> lambda{};
  Clearance clearance;
  bool degraded = true;
  std::int64_t input_seq = -1;
  std::int64_t input_utime = 0;  ///< utime of the input the state answers (input clock)
  AlarmLevel alarm_level = AlarmLevel::None;
  /// ROPE_SLACK / ROPE_OVERLOAD thresholds in force [N] (fractions of the
  /// static rope force at kin.l); 0 before the first step.
  double rope_slack_threshold = 0.0;
  double rope_overload_threshold = 0.0;
};

/// What onInput()/tick() did.
struct InputResult {
  bool accepted = false;
  RejectReason reason = RejectReason::Decode;  ///< valid when !accepted
  bool stepped = false;        ///< a new output is ready (input clock)
  bool republish = false;      ///< input clock, rejected for the model's domain: publish the held state (degraded)
  bool reinitialized = false;  ///< the model was re-initialized (new stream, fault)
};

struct TickResult {
  bool stepped = false;
  bool fault = false;          ///< non-finite or implausible state; model re-initialized
  bool domain_error = false;   ///< the kinematics left the valid range; state held
  bool catchup_limited = false;  ///< the gap exceeded max_catchup_periods: crossed with longer substeps
};

class TwinCore;

/// How model time follows inputs and ticks (the daemon's clock mode), as a
/// policy object: Drake's LcmDrivenLoop takes a time converter likewise.
/// Implementations (twin_core.cpp): InputClock, WallClock.
class ClockPolicy {
 public:
  virtual ~ClockPolicy() = default;
  virtual ClockMode mode() const = 0;
  /// A validated input (new_stream: the validator had no reference): step
  /// the model (input clock) or store it (wall clock).
  virtual InputResult onInput(TwinCore& core, const WinderSample& s, bool new_stream, double wall_now) = 0;
  /// The timer's tick at model time t (wall clock); no-op for the input clock.
  virtual TickResult tick(TwinCore& core, double t, double wall_now) = 0;
  /// The staleness timeout in force [s].
  virtual double staleTimeout(const TwinCore& core) const = 0;
  /// Model time of a sensor sample stamped `utime` that arrived at
  /// `wall_now` (the wall clock then: `wall_utime`); `offset`: utime minus
  /// the daemon's clock [s] (wall: the wall clock; input: the latest winder
  /// utime).  NaN when there is no model time yet (input clock before the
  /// first winder input).
  virtual double sensorTime(const TwinCore& core, std::int64_t utime, double wall_now, std::int64_t wall_utime,
                            double& offset) const = 0;
};
std::unique_ptr<ClockPolicy> makeClock(ClockMode mode);

// Operator commands (alarm_ack_t) and their validation are the contract with
// the daemon's clients: hoist/contract/alarm_command.hpp.
using contract::AlarmAction;
using contract::AlarmCommand;
using contract::CommandError;
using contract::kCommandErrors;
using contract::printable;
using contract::validateAlarmCommand;

class TwinCore {
 public:
  /// `solver` may be injected (tests); by default makeSolver(Method::Fast).
  /// Throws ParamError / std::invalid_argument for a bad configuration.
  TwinCore(const TwinConfig& cfg, ClockMode clock, std::unique_ptr<Solver> solver = nullptr);

  /// A winder sample received at wall time `wall_now` [s].  `envelope_budget`:
  /// the caller's budget of exact envelope evaluations for this call (see
  /// EnvelopeBudget below; nullptr, the default: none).
  InputResult onInput(const WinderSample& s, double wall_now, int* envelope_budget = nullptr);
  /// An undecodable message (garbage, truncated, wrong fingerprint).
  void rejectUndecodable() {
    counters_.reject(RejectReason::Decode);
    lostMotion(RejectReason::Decode);
  }
  /// Without an encoder the rope length is integrated from v and a: after a
  /// rejected input that may have carried motion, the length is no longer
  /// known to match the winder's, and the outputs are flagged degraded until
  /// an accepted input carries an encoder length again.
  bool lengthUnverified() const { return length_unverified_; }
  /// Test hook (fault injection): the state after the next model step or
  /// initialization is treated as non-finite, exercising the MODEL_FAULT
  /// path (alarm, re-initialization, degraded outputs) end to end.
  void injectFault() { inject_fault_ = true; }
  /// Wall clock: step the model to model time t (> current).  Input clock: no-op.
  /// While a deferred start is pending (see deferStarts) it does not step.
  /// `envelope_budget`: as for onInput().
  TickResult tick(double t, double wall_now, int* envelope_budget = nullptr);

  // ---- deferred starts (wall clock; the daemon's start budget) ---------------
  /// With --clock wall, the first input (and a new stream whose encoder
  /// length jumped) re-initializes the model: a static solve, tens of
  /// microseconds at the converged n.  Hundreds of twins that see their
  /// first input in the same period would do hundreds of them in one tick.
  /// With deferStarts(true) onInput() only accepts the sample and marks the
  /// start pending; the daemon calls completeStart() from a tick within its
  /// per-tick start budget ([service] max_starts_per_tick).  Meanwhile the
  /// twin is "starting": tick() does not step it, it has no trip state to
  /// publish (hasOutput() is false), its outputs are not flagged degraded
  /// for it.  Off by default (TwinCore used directly starts at once).
  void deferStarts(bool on) { defer_starts_ = on; }
  /// A start (or re-initialization) waits for completeStart().
  bool startPending() const { return start_pending_; }
  /// The pending start now, at the model time of the previous tick `t_prev`
  /// (so that the next tick(t) steps one ordinary period) but never before
  /// the input that asked for it; the kinematics are the stream's latest,
  /// carried forward to that time.  No-op without a pending start.
  /// `envelope_budget`: as for onInput().
  void completeStart(double t_prev, double wall_now, int* envelope_budget = nullptr);
  /// Starts (first inputs and new streams) deferred since construction.
  std::int64_t startsDeferred() const { return starts_deferred_; }
  /// Staleness, shelve expiry and re-announcement; call at least a few times
  /// per second (the daemon calls it every tick).
  void housekeeping(double wall_now);
  /// Operator command; returns the number of alarms affected (Reannounce:
  /// the number of alarms whose state was re-announced; the daemon rate-limits it).
  int command(AlarmAction action, std::optional<AlarmKind> kind, AlarmLevel level,
              double shelve_duration);

  const CageOutput& output() const { return out_; }
  /// Model time -> published time (seconds since the trip start; see above).
  /// Round-off below a nanosecond is shown as 0 (never "-0.00 s" in logs and messages).
  double publishedTime(double model_t) const {
    const double t = model_t - t_pub_offset_;
    return std::abs(t) < 1e-9 ? 0.0 : t;
  }
  /// Why the last MODEL_FAULT was raised: "non-finite" or the implausible
  /// quantity ("y_c", "lambda_1", ...), with its value and bound.
  const char* lastFaultWhat() const { return fault_what_; }
  double lastFaultValue() const { return fault_value_; }
  double lastFaultLimit() const { return fault_limit_; }
  /// The model's valid range of rope length.
  const LengthRange& validRange() const { return range_; }
  /// MODEL_DOMAIN condition (requested length outside the valid range).
  bool outsideDomain() const { return domain_outside_; }
  /// Ticks whose gap exceeded max_catchup_periods (wall clock).
  std::int64_t catchupLimited() const { return catchups_; }
  /// Another publisher on the output channels (from the daemon).
  void setDuplicatePublisher(bool seen, double other_id);
  /// The latest look-ahead forecast's verdicts: PREDICTED_CLEARANCE
  /// and PREDICTED_SLACK (seconds to the crossing, horizon), at model time now.
  void setPredictions(bool clearance, double clearance_s, bool slack, double slack_s, double horizon,
                      bool from_estimate = false);
  /// The shaft's memory's verdicts over its recorded trips (the daemon's
  /// trip room, after each trip and once at start): GUIDE_PRELOAD_LOW at
  /// `preload` (the combined scale's 95 % upper bound `upper95` against the
  /// `warning` / `critical` limits) and SHAFT_FINGERPRINT (`z` against
  /// `z_limit`), at model time now.  Allocation-free.
  void setCondition(AlarmLevel preload, double upper95, double warning, double critical, bool fingerprint,
                    double z, double z_limit);
  /// MODEL_MISMATCH's trip-end preload test (hoist/preload_verdict.hpp; the
  /// daemon's trip room, after each trip that identified the preload):
  /// `mismatch` when the trip's preload scale lies |z| > `limit` of its
  /// sigmas from preloadScale().  It holds until the next verdict, or until
  /// adoptModel() drops it (the twin's preload changed; the next trip judges
  /// the new one).  While it holds, MODEL_MISMATCH is active and the estimate
  /// does not judge the alarms, as with the estimator's own tests (applied at
  /// the next step).  Allocation-free.
  void setPreloadVerdict(bool mismatch, double z, double limit) {
    preload_mismatch_ = mismatch;
    preload_z_ = z;
    preload_limit_ = limit;
  }
  bool preloadMismatch() const { return preload_mismatch_; }
  /// Alarm events since the last clearEvents() (the caller publishes them).
  const AlarmEvents& events() const { return events_; }
  void clearEvents() { events_.clear(); }

  /// Evaluate the guide-rope shape on the shape grid (allocation-free);
  /// read it from shape().depths()/y1()/y2().
  void evaluateShape() { shape_.evaluate(*solver_); }
  const GuideRopeEnvelope& shape() const { return shape_; }
  /// The deflection alarm's envelope (service.envelope_tolerance: exact or
  /// bounded evaluations, GuideRopeEnvelope::evaluateBounded).
  const GuideRopeEnvelope& envelope() const { return envelope_; }
  /// EnvelopeBudget: the `envelope_budget` of onInput(), tick() and
  /// completeStart() is the caller's budget of exact envelope evaluations
  /// (the daemon's per-tick [service] max_exact_envelopes_per_tick across a
  /// schedule's shafts), or null: no budget.  Each exact evaluation decrements
  /// *left; while *left <= 0 an evaluation whose bound has grown wider than
  /// envelope_tolerance is deferred (GuideRopeEnvelope::evaluateBounded with
  /// defer_below) if that wider bound is below envelopeDeferBelow(): the
  /// GUIDE_ROPE alarms then decide exactly as with the exact envelope (both
  /// values are under the WARNING alarm's clear level), and the published
  /// guide_deflection is still never below the exact envelope, only looser
  /// than the tolerance for those steps.  Anything else is exact regardless.
  /// The core holds the pointer only within that call.
  /// The deflection below which an envelope evaluation may be deferred [m]:
  /// (alarms.warning_fraction - alarms.deadband) x alarms.guide_rope_gap, the
  /// GUIDE_ROPE WARNING alarm's clear level (below it neither GUIDE_ROPE
  /// alarm can change state, pend or stay raised).
  double envelopeDeferBelow() const { return envelope_defer_below_; }
  /// Time spent in the envelope (exact or bounded) since construction [ns]
  /// (steady clock around each evaluation: the daemon's cost split).
  std::int64_t envelopeNanos() const { return envelope_ns_; }

  const InputCounters& counters() const { return counters_; }
  const AlarmEngine& alarms() const { return alarms_; }
  const TwinConfig& config() const { return cfg_; }
  ClockMode clock() const { return clock_->mode(); }
  double modelTime() const { return t_; }
  bool started() const { return started_; }
  bool stale() const { return stale_; }
  bool degraded() const { return out_.degraded; }
  /// Seconds since the last accepted input (-1 if none yet).
  double inputAge(double wall_now) const { return have_input_ ? wall_now - last_input_wall_ : -1.0; }
  /// Any input accepted since start (the wall-clock twin publishes cage
  /// output only from its first input on: before that it has no trip).
  bool hasInput() const { return have_input_; }
  /// The twin has a trip state to publish: an input accepted and no start
  /// pending (the wall-clock daemon publishes HOIST_CAGE only then).
  bool hasOutput() const { return have_input_ && !start_pending_; }
  /// The staleness timeout in force [s]: stale_timeout, or with --clock wall
  /// stale_periods input periods (clamped to [stale_min, stale_timeout]) once
  /// the current stream's period is known.
  double staleTimeout() const { return clock_->staleTimeout(*this); }
  /// Estimated input period of the current stream [s] (0 until known).
  double inputPeriod() const { return period_est_; }
  std::int64_t steps() const { return steps_; }
  std::int64_t modelFaults() const { return faults_; }
  std::int64_t modelResets() const { return resets_; }
  std::int64_t domainErrors() const { return domain_errors_; }
  const Solver& solver() const { return *solver_; }

  // ---- the model ---------------------------------------------------------
  /// Run `m` from now on (an operator adopted a guide-rope preload;
  /// hoist/service/twin/twin_model.hpp): the solver, the envelopes, the
  /// plausibility bounds and the estimator's solvers are swapped, and `m`
  /// receives the old ones (release them off the loop).  A started twin is
  /// re-initialized in the new model's equilibrium at the current
  /// kinematics -- call it at rest -- and the estimator keeps its loads,
  /// their covariance and the accelerometer's offset (its model check
  /// starts afresh).  Not a reset: no MODEL_FAULT, no degraded output, no
  /// count.  Allocation-free.  Throws std::invalid_argument (nothing
  /// changed) for a model of another method or n.
  void adoptModel(std::unique_ptr<TwinModel>& m);
  /// The guide-rope preload scale of the model in use (1: the config's).
  double preloadScale() const { return preload_scale_; }

  // ---- load estimator ([estimator], hoist/load_estimator.hpp) ---------------
  /// A validated cage IMU sample (f_y [m/s^2], omega [rad/s]; NaN = that
  /// channel absent) stamped `utime` [us], arriving at `wall_now` [s] when the
  /// wall clock reads `wall_utime` [us]: applied at its own time
  /// (hoist/service/twin/sensor_timing.hpp) at the first model step at or after
  /// it.  A clock further off than [sensors] max_clock_offset or a utime
  /// going back is refused, counted and raises SENSOR_FAULT.  Disabled: NoClock.
  SensorVerdict onCageImu(std::int64_t utime, double f_y, double omega, double wall_now, std::int64_t wall_utime);
  /// A validated rope-load sample [N], likewise.
  SensorVerdict onRopeLoad(std::int64_t utime, double force, double wall_now, std::int64_t wall_utime);
  /// The live calibration (alarm_ack_t ACTION_CALIBRATE): the load is known
  /// -- force Fa [N] at offset b [m] -- from now for `duration` seconds of
  /// model time; the estimator learns the accelerometer's offset from it.
  /// false (nothing changes): no estimator, or Fa < 0.  A new declaration
  /// replaces one in force.  The learned offset: estimate().accel_offset.
  bool calibrate(double Fa, double b, double duration);
  /// Start the estimator from a learned accelerometer offset [m/s^2] and its
  /// sigma (a calibration kept across restarts: LoadEstimator::setAccelOffset).
  /// false (nothing changes): no estimator, or a value it refuses.
  bool setAccelOffset(double offset, double sigma);
  /// A declared known load is in force at the current model time.
  bool calibrating() const { return est_ && t_ < known_until_; }
  /// The clock offset of the last offered sensor sample [s] (for the log).
  double lastSensorOffset() const { return sensor_offset_; }
  /// The last SENSOR_FAULT cause: which sensor, why, the value and its limit.
  struct SensorFaultInfo {
    SensorId sensor = SensorId::CageImu;
    SensorFaultReason reason = SensorFaultReason::ClockOffset;
    double value = 0.0, limit = 0.0;
  };
  const SensorFaultInfo& lastSensorFault() const { return sensor_fault_; }
  /// SENSOR_FAULT stays raised this long after its last cause [s of model time].
  static constexpr double kSensorFaultHold = 5.0;
  const SensorTimingCounters& sensorTiming() const { return timing_.counters(); }
  /// The alarms' source (estimate or open loop), its hold, and the switch
  /// and load-change events (estimate_gate.hpp).
  const EstimateGate& estimateGate() const { return gate_; }
  bool estimatorEnabled() const { return est_ != nullptr; }
  /// The estimate after the last step (null when disabled or not yet started).
  const LoadEstimate* estimate() const { return est_ && est_synced_ ? &est_->estimate() : nullptr; }
  /// The sensor values applied at the last estimator step (t, z, present;
  /// present = 0 when none was due; the kinematics are left to the caller:
  /// output().kin).  The daemon's trip room copies it every tick (issue 32).
  const MeasurementSample& lastMeasurement() const { return meas_; }
  const EstimatorCounters* estimatorCounters() const { return est_ ? &est_->counters() : nullptr; }
  /// The last step's clearance and rope-force alarms were judged on the
  /// estimate (it has sensors in use and no MODEL_MISMATCH).
  bool estimateInUse() const { return est_in_use_; }
  /// The estimator's unit-load solver, stepped with the twin (null when the
  /// estimator is disabled): with estimate() it gives the state the estimated
  /// load implies (hoist::addLoadResponse), the forecasts' start.
  const FastSolver* loadSensitivity() const { return est_ ? &est_->sensitivitySolver() : nullptr; }

 private:
  friend class InputClock;
  friend class WallClock;
  bool lengthOk(double l) const { return range_.contains(l); }
  Kinematics integrate(const Kinematics& k0, double v1, double a1, double dt) const;
  void initializeAt(double t, const Kinematics& k);
  /// Step to (t, k) with substeps (at most `max_interval` of model time at
  /// full accuracy); false if the model refused (domain_error).
  bool advance(double t, const Kinematics& k, double max_interval = 0.0);
  /// Set or clear the MODEL_DOMAIN condition for a requested length l.
  void setDomain(bool outside, double l);
  /// Make `s` the stream's latest accepted sample.
  void acceptSample(const WinderSample& s, double wall_now);
  void lostMotion(RejectReason r);  ///< a rejected input: see lengthUnverified()
  /// The period-based staleness timeout (wall clock).
  double periodStaleTimeout() const;
  /// After a step or init: fault check, clearance, alarms, output.
  bool finishStep(double t, bool allow_fault_check = true);
  void setStale(bool stale);
  bool degradedNow() const;

  TwinConfig cfg_;
  std::unique_ptr<ClockPolicy> clock_;
  std::unique_ptr<Solver> solver_;
  GuideRopeEnvelope envelope_;
  double envelope_tol_ = 0.0;  // [m]: service.envelope_tolerance x alarms.guide_rope_gap
  double envelope_defer_below_ = 0.0;  // [m]: envelopeDeferBelow()
  int* envelope_budget_ = nullptr;     // the envelope_budget of the onInput()/tick()/completeStart() under way
  std::int64_t envelope_ns_ = 0;
  GuideRopeEnvelope shape_;
  InputValidator validator_;
  AlarmEngine alarms_;
  AlarmEvents events_;
  InputCounters counters_;
  CageOutput out_;
  LengthRange range_;
  PlausibilityBounds bounds_;
  double preload_scale_ = 1.0;  // adoptModel()
  bool preload_mismatch_ = false;  // setPreloadVerdict()
  double preload_z_ = 0.0, preload_limit_ = 4.0;

  bool started_ = false;        // model initialized
  double t_ = 0.0;              // model time [s]
  Kinematics kin_;              // kinematics of the current model state
  // input stream
  bool have_input_ = false;     // any input accepted since start
  bool stream_ = false;         // validator has a reference (not stale)
  WinderSample last_;           // last accepted sample
  double last_input_wall_ = 0.0;
  double period_est_ = 0.0;     // input period estimate (EWMA of utime steps) [s]
  double t_pub_offset_ = 0.0;   // wall clock: model time of the first input (published t counts from it)
  bool stale_ = false;
  bool length_unverified_ = false;  // integrated length after lost input, no encoder since (degraded)
  double start_wall_ = -1.0;
  double fault_until_ = -1.0;   // degraded until this model time after a re-init
  bool fault_pending_clear_ = false;
  bool inject_fault_ = false;
  std::int64_t steps_ = 0, faults_ = 0, resets_ = 0, domain_errors_ = 0, catchups_ = 0;
  // load estimator ([estimator] enabled; docs/estimation.md)
  std::unique_ptr<LoadEstimator> est_;  // null when disabled
  MeasurementSample meas_;      // the sensors applied at the last estimator step (lastMeasurement)
  bool est_synced_ = false;     // its sensitivities stepped exactly as the solver (false after a refused step)
  bool est_in_use_ = false;     // the last step's alarms used the estimate (sensors in use, no mismatch)
  SensorTiming timing_;         // the sensor samples, queued to their own time
  EstimateGate gate_;           // which state the alarms judge; the clear hold
  double sensor_offset_ = 0.0;  // clock offset of the last offered sample [s]
  SensorFaultInfo sensor_fault_;
  double sensor_fault_until_ = -1.0;  // SENSOR_FAULT condition until this model time
  double known_Fa_ = 0.0, known_b_ = 0.0, known_until_ = -1.0;  // calibrate(): the declared load, until when
  void noteSensorFault(SensorId s, SensorFaultReason r, double value, double limit);
  SensorVerdict offerSensor(SensorId s, std::int64_t utime, double a, double b, double wall_now,
                            std::int64_t wall_utime);
  void estimatorStep(const CageResponse& r);  // predict, apply the due samples, finish
  /// Why the estimate may not judge the alarms (NotUsedBits; 0: usable).
  unsigned estimateNotUsed(const LoadEstimate& e);
  double catchup_until_ = -1.0;   // degraded through this model time after a limited catch-up
  // deferred starts (deferStarts)
  bool defer_starts_ = false;     // first inputs / new streams wait for completeStart()
  bool start_pending_ = false;    // a start waits
  bool pending_first_ = false;    // ... and it is the first start (the trip starts; not counted as a reset)
  double pend_t_ = 0.0;           // wall time of the input that asked for it [s]
  double pend_trip_t_ = 0.0;      // the first start: when the trip started (published time counts from it) [s]
  Kinematics pend_k_;             // kinematics at pend_t_, carried forward by later inputs without an encoder
  std::int64_t starts_deferred_ = 0;
  void deferStart(double wall_now, const Kinematics& k, bool first);
  bool domain_outside_ = false;
  const char* fault_what_ = "";
  double fault_value_ = 0.0, fault_limit_ = 0.0;
};

}  // namespace hoist::service::twin
