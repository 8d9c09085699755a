// ShaftContext: what every room of one hosted shaft shares, read-only (the
// rooms: docs/architecture.md): the configuration, the names, the log, the
// model (TwinCore) and the shaft's wall clock.  Each room's own state is
// the room's (its statistics: shaft_stats.hpp).
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

#include "hoist/bus/channels.hpp"
#include "hoist/rt/rt_log.hpp"
#include "hoist/service/core/config.hpp"
#include "hoist/service/twin/twin_core.hpp"

namespace hoist::service::inline app {

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

class OffsetKeeper;
class PreloadKeeper;
class TripRoom;

/// The optional rooms of a shaft (nullptr: not hosted), set by ShaftTwin as
/// they are enabled (before the loop starts).  The rooms that hand them
/// work hold a const reference: they call the rooms, never re-seat them.
struct ShaftPeers {
  OffsetKeeper* offsets = nullptr;  ///< the kept accelerometer offset (offset_keeper.hpp)
  PreloadKeeper* preload = nullptr; ///< the adopted guide-rope preload (preload_keeper.hpp)
  TripRoom* trips = nullptr;        ///< the shaft's memory ([history]; trip_room.hpp)
};

/// One shaft's wall clock: seconds since the loop started, less the time
/// spent in synchronous forecasts (--clock input: the inputs wait in the
/// socket meanwhile; they are not late).  ShaftTwin starts it; the
/// ForecastScheduler pauses it; every room reads it.
class ShaftClock {
 public:
  using Clock = std::chrono::steady_clock;
  /// The loop's start (ShaftTwin::start, rebase).
  void start(Clock::time_point t) { start_ = t; }
  /// `d` of wall time that does not count (ForecastScheduler).
  void pause(Clock::duration d) { paused_ += d; }
  /// Wall time of `t` [s].
  double wallAt(Clock::time_point t) const { return std::chrono::duration<double>(t - start_ - paused_).count(); }
  /// Wall time now [s].
  double wallNow() const { return wallAt(Clock::now()); }

 private:
  Clock::time_point start_{};
  Clock::duration paused_{};
};

/// What the rooms of one shaft share, read-only: the configuration, the
/// names, the log, the clock and the model.  ShaftTwin owns it and hands
/// each room a const reference (for as long as the ShaftTwin lives); a room
/// that writes the model or the clock is given that part by reference of
/// its own (see the rooms' constructors), so what a room may change is in
/// its constructor's signature.
struct ShaftContext {
  using Clock = ShaftClock::Clock;

  ShaftContext(const TwinConfig& config, std::string shaft_label, RtLog& rt_log, TestHooks test_hooks,
               std::int64_t instance)
      : cfg(validated(config)),
        label(std::move(shaft_label)),
        tag(label.empty() ? std::string() : "[" + label + "] "),
        log(rt_log),
        hooks(test_hooks),
        instance_id(instance),
        ch(cfg.service.channel_prefix),
        core(cfg, cfg.service.clock) {}
  ShaftContext(const ShaftContext&) = delete;
  ShaftContext& operator=(const ShaftContext&) = delete;

  const TwinConfig cfg;           ///< this shaft's effective configuration
  const std::string label;        ///< as given ("" for a daemon with one shaft)
  const std::string tag;          ///< log-line prefix: "[label] " or ""
  RtLog& log;                     ///< the daemon's real-time log ring (never blocks; a sink every room writes)
  const TestHooks hooks;          ///< test-only fault injection
  const std::int64_t instance_id = 0;  ///< this process's random id (HOIST_CAGE/HOIST_HEALTH/HOIST_FORECAST)
  const bus::Channels ch;         ///< channel names: prefix + HOIST_*
  TwinCore core;                  ///< the model, input validation, alarms (no I/O): the model room
  ShaftClock clock;               ///< the shaft's wall clock

  /// Wall time of `t` [s] on this shaft's clock.
  double wallAt(Clock::time_point t) const { return clock.wallAt(t); }
  /// Wall time now [s] on this shaft's clock.
  double wallNow() const { return clock.wallNow(); }

 private:
  static const TwinConfig& validated(const TwinConfig& c) {
    if (c.forecast.enabled) c.forecast.validate(c.service.rate);
    return c;
  }
};

}  // namespace hoist::service::app
