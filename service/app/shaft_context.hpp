// ShaftContext: what every room of one hosted shaft shares (the rooms:
// docs/architecture.md): the configuration, the names, the log, the model
// (TwinCore), the statistics and the shaft's wall clock.  Plain data plus
// two clock helpers; the rooms hold a reference to it.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

#include "hoist/bus/channels.hpp"
#include "hoist/rt/rt_log.hpp"
#include "hoist/service/config.hpp"
#include "hoist/service/twin_core.hpp"
#include "miss_record.hpp"
#include "shaft_stats.hpp"

namespace hoist::svc {

class OffsetKeeper;
class PreloadKeeper;
class TripRoom;

using rt::RtLog;

/// Operator names (alarm commands) are cut to this many printable
/// characters: the contract's rule (hoist/contract/alarm_command.hpp).
inline constexpr std::size_t kUserMax = contract::kMaxOperatorName;

/// Test-only fault injection (hidden command-line options, tests/hardening).
struct TestHooks {
  double inject_fault_at = -1.0;  ///< wall time [s] at which the model state is treated as non-finite once
  int fail_publish_every = 0;     ///< every N-th LCM publish is treated as failed (0 = never)
  /// Wall time [s] at which one tick of the first shaft busy-waits for
  /// slow_tick_ms inside its model step (a deadline miss on purpose: the
  /// miss record's test); < 0 = never.
  double slow_tick_at = -1.0;
  double slow_tick_ms = 0.0;
};

/// The last recorded trip's detectability (TripRoom's ConditionState, copied
/// by the loop; estimate_t.detect_trip, loss30_separation, loss30_visible).
struct TripDetectability {
  std::int64_t trip = 0;
  double loss30_separation = -1.0;
  bool loss30_visible = false;
};

struct ShaftContext {
  using Clock = std::chrono::steady_clock;

  ShaftContext(const TwinConfig& config, std::string shaft_label, RtLog& rt_log, TestHooks test_hooks,
               std::int64_t instance)
      : cfg(config),
        label(std::move(shaft_label)),
        tag(label.empty() ? std::string() : "[" + label + "] "),
        log(rt_log),
        hooks(test_hooks),
        instance_id(instance),
        ch(cfg.service.channel_prefix),
        core(cfg, cfg.service.clock) {
    if (cfg.forecast.enabled) cfg.forecast.validate(cfg.service.rate);
  }
  ShaftContext(const ShaftContext&) = delete;
  ShaftContext& operator=(const ShaftContext&) = delete;

  TwinConfig cfg;                 ///< this shaft's effective configuration
  std::string label;              ///< as given ("" for a daemon with one shaft)
  std::string tag;                ///< log-line prefix: "[label] " or ""
  RtLog& log;                     ///< the daemon's real-time log ring (never blocks)
  TestHooks hooks;                ///< test-only fault injection
  std::int64_t instance_id = 0;   ///< this process's random id (HOIST_CAGE/HOIST_HEALTH/HOIST_FORECAST)
  bus::Channels ch;               ///< channel names: prefix + HOIST_*
  TwinCore core;                  ///< the model, input validation, alarms (no I/O)
  ShaftStats stats;               ///< every counter and histogram of this shaft
  TripDetectability detect;       ///< the last recorded trip's detectability (loop thread)
  Clock::time_point start{};      ///< the loop's start: wall times are measured from it
  /// --clock input: wall time spent in synchronous forecasts, not counted as
  /// time passing for this shaft's staleness and health windows (the inputs
  /// wait in the socket meanwhile; they are not late).
  Clock::duration sync_pause{};
  /// The daemon's loop-time split (miss_record.hpp): the rooms add their
  /// phases' time to it (nullptr: not hosted by a Daemon).
  LoopSplit* split = nullptr;
  /// The daemon's miss record, for HOIST_HEALTH (nullptr: none).
  const MissLog* misses = nullptr;
  /// This shaft's kept accelerometer offset (offset_keeper.hpp): told after
  /// every stepped tick, so it sees a calibration end (nullptr: not kept).
  OffsetKeeper* offsets = nullptr;
  /// This shaft's adopted guide-rope preload (preload_keeper.hpp): takes
  /// the operator's adoptions, told after every tick (nullptr: not hosted
  /// by a Daemon).
  PreloadKeeper* preload = nullptr;
  /// This shaft's trip room (trip_room.hpp): every model step is copied
  /// into it (nullptr: [history] off).
  TripRoom* trips = nullptr;

  /// Wall time of `t` [s] on this shaft's clock.
  double wallAt(Clock::time_point t) const {
    return std::chrono::duration<double>(t - start - sync_pause).count();
  }
  /// Wall time now [s] on this shaft's clock.
  double wallNow() const { return wallAt(Clock::now()); }
};

}  // namespace hoist::svc
