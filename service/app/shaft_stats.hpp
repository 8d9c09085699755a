// The statistics of one hosted shaft, as one slice per room that writes
// them: the tick (ShaftTwin), the inputs (ShaftInputs), the outputs
// (ShaftOutputs) and the forecasts (ForecastScheduler).  ShaftTwin holds
// the slices; each room gets its own slice writable and the others', where
// it reads them, const (ShaftHealth reads them all for HOIST_HEALTH and the
// final log lines; the run report and the tests read them through
// ShaftTwin).  Each counter has one writer.  Plain data: no logic but the
// window's end, which the owner calls (ShaftTwin::publishHealth).
//
// The counters HOIST_HEALTH carries as they are come from health_t.lcm: a
// slice derives from the generated group of its room (`@group tick`, ...:
// hoist::msg::groups::health_t::Tick, ...), which holds them under
// health_t's names and copies them into the message (fillInto, called by
// ShaftHealth::fill).  A new such counter is its line in health_t.lcm and
// its increment.
#pragma once

#include <array>
#include <cstdint>

#include "hoist/msg/groups.hpp"
#include "hoist/service/core/forecast_rules.hpp"
#include "hoist/service/core/health.hpp"
#include "hoist/service/core/input_validator.hpp"
#include "hoist/service/core/sensor_sequence.hpp"

namespace hoist::service::inline app {

/// HOIST_HEALTH's extra rejection reasons after the winder reasons (not in
/// rejected_total, which counts winder inputs): undecodable alarm commands,
/// exceptions caught in an input handler, then one per PlanReject.
inline constexpr int kExtraReasons = 2 + kPlanRejectReasons;

/// A figure measured per health window and over the whole run: samples go
/// into `window`; at the window's end it is merged into `total` and reset.
struct WindowedHistogram {
  LatencyHistogram window;  ///< this health window
  LatencyHistogram total;   ///< the whole run, up to the last window's end
  void add(double us) { window.add(us); }
  /// (The whole-run histogram takes each window at its end: one add per
  /// value instead of two; with hundreds of shafts every bin touched is a
  /// cache miss.)
  void endWindow() {
    total.merge(window);
    window.reset();
  }
};

/// The tick's (ShaftTwin): --clock wall steps, lateness, starts, misses;
/// ticks and deadline_misses from health_t's `@group tick`.
struct TickStats : msg::groups::health_t::Tick {
  std::int64_t ns_model = 0;         ///< steady-clock ns in the model (core tick + housekeeping)
  std::int64_t ns_publish = 0;       ///< steady-clock ns publishing from the tick (encode + send)
  std::int64_t ns_tick = 0;          ///< steady-clock ns in whole tick() calls
  WindowedHistogram step;            ///< model step time [us] (--clock wall)
  WindowedHistogram late;            ///< tick lateness [us]
  double last_late_us = 0.0;         ///< this tick's lateness [us] (the miss record reads it)
  std::int64_t starts = 0;           ///< deferred starts completed in a tick (within the start budget)
  std::int64_t start_tick = -1;      ///< `ticks` at the latest deferred start (-1: none yet)
  double start_wall = -1.0;          ///< its wall time [s] (-1: none yet)
  std::int64_t ns_start = 0;         ///< steady-clock ns in deferred starts (also in ns_model)
  /// The latest misses this shaft took part in: the miss record's seq and
  /// this shaft's lateness in that tick, a ring of kMissesNoted.
  static constexpr int kMissesNoted = 8;
  std::array<std::int64_t, kMissesNoted> miss_seq{};
  std::array<double, kMissesNoted> miss_late_us{};
  std::int64_t misses_noted = 0;
  void noteMiss(std::int64_t seq, double late_us) {
    const auto j = static_cast<std::size_t>(misses_noted % kMissesNoted);
    miss_seq[j] = seq;
    miss_late_us[j] = late_us;
    ++misses_noted;
  }
  void endWindow() {
    step.endWindow();
    late.endWindow();
  }
};

/// The inputs' (ShaftInputs): commands, trip plans, sensors, --clock input
/// steps; commands_dropped (valid commands beyond max_commands_per_tick,
/// plus decode-bound drops), commands_invalid, plans_accepted,
/// sensor_accepted (handed to the estimator) and sensor_rejected from
/// health_t's `@group inputs`.
struct InputStats : msg::groups::health_t::Inputs {
  std::int64_t command_decode_rejects = 0;  ///< undecodable alarm commands
  std::int64_t handler_exceptions = 0;      ///< exceptions caught in an input handler
  std::int64_t command_decodes_dropped = 0; ///< command datagrams beyond the tick's decode bound (not decoded)
  std::int64_t commands_applied = 0;        ///< effective commands (audited)
  std::int64_t reannounce_requests = 0;     ///< valid re-announce requests (alarm_ack_t ACTION_REANNOUNCE)
  std::int64_t reannounces = 0;             ///< ... honoured (at most one a second)
  std::int64_t reannounce_merged = 0;       ///< ... merged into a pending one (arrived within the interval)
  std::array<std::int64_t, kPlanRejectReasons> plan_rejects{};  ///< trip plans rejected, per reason
  SensorSequence imu_seq, rope_seq;         ///< each sensor's sequence rule (hoist/service/core/sensor_sequence.hpp)
  double last_imu_wall = -1.0, last_rope_wall = -1.0;  ///< when (wall clock [s]; < 0: never)
  WindowedHistogram step;                   ///< model step time [us] (--clock input: the inputs step the model)

  /// Trip plans rejected, all reasons.
  std::int64_t plansRejected() const {
    std::int64_t n = 0;
    for (auto v : plan_rejects) n += v;
    return n;
  }
  void endWindow() { step.endWindow(); }
};

/// The outputs' (ShaftOutputs); publish_failures (socket, encode, buffer
/// size), nonfinite_blocked and alarm_events from health_t's `@group outputs`.
struct OutputStats : msg::groups::health_t::Outputs {
  std::int64_t publish_attempts = 0;   ///< publishes tried (TestHooks::fail_publish_every counts them)
};

/// The forecasts' (ForecastScheduler; all zero without [forecast] enabled);
/// forecasts, forecasts_dropped and forecasts_skipped from health_t's
/// `@group forecasts`.
struct ForecastStats : msg::groups::health_t::Forecasts {
  std::int64_t forecasts_from_estimate = 0;  ///< forecasts started from the load estimate's state
  std::int64_t forecast_failures = 0;  ///< forecasts whose engine threw (nothing published)
  std::int64_t plan_unusable = 0;      ///< forecasts whose accepted plan no longer fit the motion
  WindowedHistogram compute;           ///< forecast compute time [us]
  void endWindow() { compute.endWindow(); }
};

/// Every slice of one shaft, read-only (ShaftHealth, the run report, tests).
struct ShaftStatsView {
  const TickStats& tick;
  const InputStats& in;
  const OutputStats& out;
  const ForecastStats& forecast;
  /// Model step time [us] this window: the tick's (--clock wall) or the
  /// inputs' (--clock input); one of them is empty.
  const LatencyHistogram& stepWindow() const { return in.step.window.count() > 0 ? in.step.window : tick.step.window; }
  /// Model step time [us] over the whole run: both merged (a copy: at stop,
  /// for the final log line and the run report, never in the loop).
  LatencyHistogram stepTotal() const {
    LatencyHistogram h = tick.step.total;
    h.merge(in.step.total);
    return h;
  }
};

}  // namespace hoist::service::app
