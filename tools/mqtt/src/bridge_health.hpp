// bridge_health.hpp -- the bridge's own health (hoist/_bridge/<client_id>/health):
// connection state and every room's counters, read through const views.
// Private to tools/mqtt; the map of the rooms is bridge.cpp.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "bridge_common.hpp"
#include "command_gate.hpp"
#include "hoist/mqtt/config.hpp"
#include "lcm_side.hpp"
#include "mqtt_link.hpp"
#include "shaft_data.hpp"
#include "shaft_directory.hpp"
#include "sparkplug_session.hpp"

namespace hoist::mqtt {

class BridgeHealth {
 public:
  /// Every reference must outlive this object; `sp` may be nullptr (JSON mode).
  BridgeHealth(const BridgeConfig& cfg, const std::string& client_id, const LcmSide& lcm, const ShaftDirectory& dir,
               const ShaftData& data, const MqttLink& link, const CommandGate& gate, const SparkplugSession* sp);

  /// The health document now: every counter, and "level" ("OK" or
  /// "WARNING") with "warnings" (why).
  nlohmann::json build() const;

  /// Watches the buffers for dropped alarm transitions (journal full, or the
  /// memory buffer's max_alarm_events): every drop is logged (at most one
  /// line per kDropLogS, with the count since the last line) and keeps the
  /// bridge's health at WARNING for kDropWarnS after the last one.  Call
  /// every loop.
  void watch(Clock::time_point now);
  static constexpr double kDropLogS = 10.0, kDropWarnS = 600.0;

 private:
  const BridgeConfig& cfg_;
  const std::string& client_id_;
  const LcmSide& lcm_;
  const ShaftDirectory& dir_;
  const ShaftData& data_;
  const MqttLink& link_;
  const CommandGate& gate_;
  const SparkplugSession* sp_;
  Clock::time_point started_ = Clock::now();
  std::uint64_t alarm_drops_seen_ = 0, alarm_drops_unlogged_ = 0;
  Clock::time_point last_drop_{}, last_drop_log_{};
  bool dropped_ever_ = false;
};

}  // namespace hoist::mqtt
