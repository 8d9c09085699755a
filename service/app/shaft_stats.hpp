// ShaftStats: every counter and histogram of one hosted shaft, in one plain
// struct.  Each room of the shaft (shaft_twin.hpp) increments the fields
// marked with its name; ShaftHealth (shaft_health.hpp) reads them all for
// HOIST_HEALTH, the final log lines and the run report.  No logic here.
#pragma once

#include <array>
#include <cstdint>

#include "hoist/service/forecast_rules.hpp"
#include "hoist/service/health.hpp"
#include "hoist/service/input_validator.hpp"
#include "hoist/service/sensor_sequence.hpp"

namespace hoist::svc {

/// HOIST_HEALTH's extra rejection reasons after the winder reasons (not in
/// rejected_total, which counts winder inputs): undecodable alarm commands,
/// exceptions caught in an input handler, then one per PlanReject.
inline constexpr int kExtraReasons = 2 + kPlanRejectReasons;

struct ShaftStats {
  // ---- the tick (ShaftTwin) ----
  std::int64_t ticks = 0;            ///< ticks run
  std::int64_t deadline_misses = 0;  ///< deadlines the schedule skipped
  std::int64_t ns_model = 0;         ///< steady-clock ns in the model (core tick + housekeeping)
  std::int64_t ns_publish = 0;       ///< steady-clock ns publishing from the tick (encode + send)
  std::int64_t ns_tick = 0;          ///< steady-clock ns in whole tick() calls
  LatencyHistogram step_hist;        ///< model step time [us], this health window
  LatencyHistogram late_hist;        ///< tick lateness [us], this health window
  LatencyHistogram step_total;       ///< model step time [us], whole run (windows merged at each health report)
  LatencyHistogram late_total;       ///< tick lateness [us], whole run

  // ---- starts and misses (ShaftTwin, the Daemon's miss record) ----
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

  // ---- inputs (ShaftInputs) ----
  std::int64_t command_decode_rejects = 0;  ///< undecodable alarm commands
  std::int64_t handler_exceptions = 0;      ///< exceptions caught in an input handler
  std::int64_t command_decodes_dropped = 0; ///< command datagrams beyond the tick's decode bound (not decoded)
  std::int64_t commands_dropped = 0;        ///< valid commands beyond max_commands_per_tick, plus decode-bound drops
  std::int64_t commands_invalid = 0;        ///< undecodable or invalid commands
  std::int64_t commands_applied = 0;        ///< effective commands (audited)
  std::int64_t reannounce_requests = 0;     ///< valid re-announce requests (alarm_ack_t ACTION_REANNOUNCE)
  std::int64_t reannounces = 0;             ///< ... honoured (at most one a second)
  std::int64_t reannounce_merged = 0;       ///< ... merged into a pending one (arrived within the interval)
  std::int64_t plans_accepted = 0;          ///< trip plans accepted
  std::int64_t sensor_accepted = 0;         ///< cage IMU and rope-load samples handed to the estimator
  std::int64_t sensor_rejected = 0;         ///< ... refused (undecodable, implausible, old seq)
  SensorSequence imu_seq, rope_seq;         ///< each sensor's sequence rule (hoist/service/sensor_sequence.hpp)
  double last_imu_wall = -1.0, last_rope_wall = -1.0;  ///< when (wall clock [s]; < 0: never)
  std::array<std::int64_t, kPlanRejectReasons> plan_rejects{};  ///< trip plans rejected, per reason

  // ---- outputs (ShaftOutputs) ----
  std::int64_t publish_failures = 0;   ///< publishes that failed (socket, encode, buffer size)
  std::int64_t nonfinite_blocked = 0;  ///< messages withheld because a field was not finite
  std::int64_t alarm_events = 0;       ///< HOIST_ALARM events published
  std::int64_t publish_attempts = 0;   ///< publishes tried (TestHooks::fail_publish_every counts them)

  // ---- forecasts (ForecastScheduler) ----
  std::int64_t forecasts = 0;          ///< forecasts done
  std::int64_t forecasts_dropped = 0;  ///< snapshots replaced before the worker took them
  std::int64_t forecasts_skipped = 0;  ///< forecast instants skipped (degraded state)
  std::int64_t forecasts_from_estimate = 0;  ///< forecasts started from the load estimate's state
  std::int64_t forecast_failures = 0;  ///< forecasts whose engine threw (nothing published)
  std::int64_t plan_unusable = 0;      ///< forecasts whose accepted plan no longer fit the motion
  LatencyHistogram forecast_hist;      ///< forecast compute time [us], this health window
  LatencyHistogram forecast_total;     ///< forecast compute time [us], whole run

  /// Trip plans rejected, all reasons.
  std::int64_t plansRejected() const {
    std::int64_t n = 0;
    for (auto v : plan_rejects) n += v;
    return n;
  }
};

}  // namespace hoist::svc
