// hoist/service/core/config.hpp -- the daemon's configuration as plain structs:
// the shaft (ShaftParams) plus [service] and [alarms].  No parser here: the
// I/O-free TwinCore sees only these structs.  Reading them from TOML is
// hoist/service/cfg/config_file.hpp (target hoist_service_cfg, via hoist_io).
// Every key is optional; a missing key takes the default below (the shaft's
// defaults are the paper's values).  Unknown keys, wrong types, non-finite or
// out-of-range values are errors naming the file, line and dotted key.
#pragma once

#include <stdexcept>
#include <string>

#include "hoist/load_estimator.hpp"
#include "hoist/params.hpp"
#include "hoist/profile.hpp"
#include "hoist/service/core/alarms.hpp"

namespace hoist::service::inline core {

enum class ClockMode { Wall, Input };
/// Most substeps one model step may take (service.max_step is checked against it).
inline constexpr int kMaxSubsteps = 100000;
const char* toString(ClockMode c);

/// The [service] section.  Rates in Hz, times in seconds, lengths in metres.
struct ServiceConfig {
  double rate = 100.0;          ///< model step rate with --clock wall, [1, 1000] Hz
  double cage_rate = 0.0;       ///< HOIST_CAGE publish rate, 0 = every model step; <= rate
  double shape_rate = 5.0;      ///< HOIST_GUIDE_SHAPE publish rate, 0 = off; <= rate
  double health_rate = 1.0;     ///< HOIST_HEALTH publish rate, (0, 10]
  std::string channel_prefix;   ///< prepended to every channel name
  std::string lcm_url;          ///< used when neither --lcm-url nor LCM_DEFAULT_URL is set
  /// Outputs (HOIST_CAGE, _GUIDE_SHAPE, _ALARM, _HEALTH) go to this URL, so
  /// that the daemon's input socket does not receive its own publications;
  /// "" = the input URL.  Same syntax as lcm_url.
  std::string lcm_url_out;
  ClockMode clock = ClockMode::Wall;  ///< "wall" or "input"
  double max_speed = 20.0;      ///< input limit |v| [m/s]
  double max_accel = 10.0;      ///< input limit |a| [m/s^2]
  double max_length_jump = 0.5; ///< encoder length off its v-prediction by more -> reject [m]
  double max_time_step = 1.0;   ///< larger utime step within a stream -> reject [s]
  double stale_timeout = 0.5;   ///< no accepted input for this long -> INPUT_STALE [s] (upper bound)
  /// --clock wall: INPUT_STALE already after this many input periods without
  /// an accepted input (the period is estimated from the stream's utime
  /// steps), but never sooner than stale_min nor later than stale_timeout.
  /// 0 = off (stale_timeout only).  --clock input always uses stale_timeout.
  double stale_periods = 3.0;
  double stale_min = 0.02;      ///< floor of the period-relative timeout [s]
  double max_step = kDefaultMaxStep;  ///< largest integration step: longer ticks/input intervals are substepped [s]; 0 = off (same default as hoist-sim)
  int shape_points = 101;       ///< depth samples in HOIST_GUIDE_SHAPE, [2, 2001]
  int envelope_points = 401;    ///< depth samples for the guide-rope deflection alarm, [2, 20001]
  /// The deflection alarm's envelope may be a conservative bound at most
  /// this fraction of alarms.guide_rope_gap above the exact one (evaluated
  /// exactly only when the bound would drift further: cost per twin); 0 = exact
  /// every step, [0, 0.05].
  double envelope_tolerance = 0.01;
  int log_rate_limit = 5;       ///< log lines per second per rejection reason, [1, 1000]
  double fault_hold = 1.0;      ///< outputs flagged degraded after a model re-init [s]
  /// Cross-sample consistency (docs/service.md): within a stream, the change
  /// of v since a reference sample must match the integral of a, each
  /// interval allowed anything between its two a values, within
  /// velocity_tolerance + accel_tolerance x (time since the reference); the
  /// reference moves every consistency_window seconds.
  double accel_tolerance = 1.0;     ///< [m/s^2], (0, 100]
  double velocity_tolerance = 0.02; ///< [m/s], [0, 10]
  double consistency_window = 1.0;  ///< [s], (0, 60]
  /// Outputs beyond plausible_factor x the largest configured gap (at least
  /// 1 m; and the force bound of hoist/plausibility.hpp) are a MODEL_FAULT, [2, 1e6].
  double plausible_factor = 10.0;
  /// With --clock wall a tick integrates at most this many periods of model
  /// time at full accuracy; a longer gap (the loop was late) is crossed with
  /// proportionally longer substeps, counted and flagged degraded, [1, 1000].
  int max_catchup_periods = 4;
  /// Valid operator commands applied per tick; more are dropped and counted
  /// (undecodable and invalid ones never count against it), [1, 1000].
  int max_commands_per_tick = 4;
  /// --clock wall: twin starts (the static solve of a first input or of a
  /// new stream whose length jumped, tens of microseconds each) done per tick
  /// of the daemon's schedule; the others wait, reporting "starting"
  /// (HOIST_HEALTH.starting), for the next ticks.  Hundreds of twins whose
  /// first inputs arrive in the same period then start over a few ticks
  /// instead of breaking one deadline.  The daemon uses the smallest value
  /// among the shafts of a schedule; 0 = no budget (start at once, in the
  /// input handler), [0, 100000].
  int max_starts_per_tick = 8;
  /// --clock wall: exact guide-rope envelope evaluations (envelope_points x
  /// n per rope, about 20 us at n = 25) per tick of the daemon's schedule.
  /// Once they are spent, a twin whose bounded envelope has drifted past
  /// envelope_tolerance keeps that wider, still rigorous bound for a tick or
  /// more -- only while it lies below the GUIDE_ROPE WARNING alarm's clear
  /// level, so no alarm decides differently (EnvelopeBudget in hoist/service/twin/twin_core.hpp);
  /// near a threshold it is exact regardless.  Hundreds of twins in lockstep
  /// then refresh over a few ticks instead of in one.  The smallest value
  /// among a schedule's shafts; 0 = no budget, [0, 100000].
  int max_exact_envelopes_per_tick = 32;

  void validate() const;  ///< throws std::invalid_argument "service.<key>: why" (the reader adds file:line)
};

/// The [forecast] section: look-ahead forecasts (docs/lookahead.md).
/// On by default: the economical forecast (hoist::economicalForecast: a
/// reduced model of `modes` modes per rope started from the twin's projected
/// state, 10-ms steps without substeps, a bounded envelope) costs about 7 ms
/// of CPU per second per shaft with the defaults below (both scenarios,
/// 20-s horizon, 1 Hz), off the real-time thread, and stays within 2 % of
/// the gap and of the static rope force of the exact forecast
/// (tests/model/forecast_fidelity_test.cpp).  `exact = true` steps the
/// twin's own model and step instead (about 8x the CPU).
struct ForecastConfig {
  bool enabled = true;        ///< run forecasts and publish HOIST_FORECAST
  /// Step the twin's model exactly as the twin does ([model] modes, the
  /// tick in [service] max_step substeps, [service] envelope_points at every
  /// step): what hoist-sim --estop-at runs.  false: the economical forecast.
  bool exact = false;
  /// Modes per rope of the economical forecast (at most [model] modes are
  /// used), [1, 1000]; ignored when exact.
  int modes = 10;
  double rate = 1.0;          ///< forecasts per second, (0, 10] Hz and <= service.rate
  double horizon = 20.0;      ///< how far ahead each scenario is integrated [s], [1/service.rate, 600]
  double estop_decel = 3.0;   ///< emergency-stop deceleration of the winder [m/s^2], (0, 50]
  double estop_jerk = 10.0;   ///< rate at which the e-stop deceleration builds up [m/s^3], (0, 1000]
  double vmax = 5.0;          ///< the winder's normal speed limit (no-plan rule) [m/s], (0, 100]
  double amax = 1.0;          ///< the winder's normal acceleration limit (no-plan rule) [m/s^2], (0, 50]
  /// The winder's jerk limit [m/s^3], (0, 1000].  With vmax and amax it is
  /// the physical bound of a trip plan: a plan whose vmax, amax or jerk
  /// exceeds it is refused (plan_above_limits), never forecast from.
  double jerk = 100.0;
  /// A trip plan not renewed for this long [s of model time] expires; the
  /// forecasts fall back to the no-plan rule and any sequence number is
  /// accepted again (a sender that restarts, or a forged seq = INT64_MAX,
  /// locks nothing out for longer), (0, 3600].
  double plan_timeout = 10.0;
  int workers = 1;            ///< forecast threads per process, shared by all shafts, [1, 16]
  int series_points = 50;     ///< points of the decimated series in forecast_t, [1, 64]

  /// Throws std::invalid_argument "forecast.<key>: why"; `service_rate` is
  /// the shaft's [service] rate (the forecast's output step is 1 / it).
  void validate(double service_rate) const;
};

/// [sensors] + [estimator]: the load estimator (hoist/load_estimator.hpp,
/// docs/estimation.md).  Off by default: the twin then runs open loop.
struct EstimatorConfig {
  bool enabled = false;
  EstimatorSettings settings;  ///< validated by EstimatorSettings::validate()
  /// [sensors] max_clock_offset: a sensor sample whose utime is further than
  /// this from the daemon's clock (--clock wall: the wall clock at arrival;
  /// --clock input: the latest winder utime) is refused, counted and raises
  /// SENSOR_FAULT; within it each sample is applied at its own time
  /// (hoist/sensor_alignment.hpp), (0, 10] s.
  double max_clock_offset = 0.5;
  /// [estimator] clear_hold: after the alarms switch between the estimate
  /// and the open-loop twin, or after a load change, an active alarm clears
  /// only once the new estimate has held this long (model time; meanwhile
  /// the alarms judge the more alarming of the new state and the one judged
  /// before), [0, 60] s.
  double clear_hold = 2.0;

  /// Throws std::invalid_argument "sensors.max_clock_offset: ..." /
  /// "estimator.clear_hold: ..." (the daemon's own keys of these sections).
  void validate() const;
};

struct TwinConfig {
  ShaftParams shaft;
  ServiceConfig service;
  AlarmConfig alarms;
  ForecastConfig forecast;
  EstimatorConfig estimator;
};

}  // namespace hoist::service::core
