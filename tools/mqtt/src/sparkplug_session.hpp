// sparkplug_session.hpp -- the bridge's Sparkplug B session ([sparkplug]
// enabled): the edge node (hoist/mqtt/sparkplug_node.hpp: metrics, births,
// seq, bdSeq), the primary host's STATE, rebirths, and the DCMD/NCMD
// commands handed to the command gate.  Private to tools/mqtt; the map of
// the rooms is bridge.cpp.
//
// Writes only its own state (the node and its counters); whether the
// session is open is the MQTT link's (MqttLink::openSession), the one place
// that decides what may be sent.
#pragma once

#include <mosquitto.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "bridge_common.hpp"
#include "command_gate.hpp"
#include "hoist/mqtt/config.hpp"
#include "hoist/mqtt/sparkplug_node.hpp"
#include "mqtt_link.hpp"
#include "shaft_directory.hpp"

namespace hoist::mqtt {

class SparkplugSession {
 public:
  /// Every reference must outlive the session; `counters` gives the node's
  /// Bridge/* metrics when called.  Throws std::runtime_error if this
  /// hoist-mqtt has no Sparkplug (built without nanopb).
  SparkplugSession(const BridgeConfig& cfg, MqttLink& link, const ShaftDirectory& dir, CommandGate& gate,
                   LogBudget& log, std::function<sparkplug::NodeCounters()> counters);
  SparkplugSession(const SparkplugSession&) = delete;
  SparkplugSession& operator=(const SparkplugSession&) = delete;

  static std::string missing();

  // ---- for the link ----
  OutMsg nextWill() { return node_->nextWill(); }
  std::uint8_t nextSeq() { return node_->nextSeq(); }

  // ---- for the data path ----
  sparkplug::DeviceMetrics& metrics(const std::string& shaft) { return node_->device(shaft); }
  /// DDATA with the device's metrics of `src` that changed (report by exception).
  void sendData(const std::string& shaft, sparkplug::Source src, MsgClass cls);

  // ---- shafts ----
  /// A device added after the NBIRTH: its DBIRTH now.
  void deviceBound(const std::string& shaft);
  /// DDEATH (if the session is open), and the device is retired.
  void deviceGone(const std::string& shaft);

  // ---- connection ----
  /// Subscribes (NCMD, DCMD, STATE); births unless waiting for the primary host.
  void onConnected();
  void onMessage(const struct mosquitto_message* m);
  /// NDEATH before an intended disconnect (MQTT 3.1.1: no will then), disconnect.
  void end();
  /// A held Rebirth when due; NDATA and the settled alarms every health period.
  void tick(std::uint64_t now_ms);
  void healthTick();

  // ---- const views ----
  const sparkplug::Node& node() const { return *node_; }
  std::uint64_t births() const { return births_; }
  std::uint64_t rebirths() const { return rebirths_; }
  std::uint64_t hostOffline() const { return host_offline_; }

 private:
  /// NBIRTH (seq 0) and every DBIRTH, then what was buffered (as history).
  void sendBirths();

  const BridgeConfig& cfg_;
  MqttLink& link_;
  const ShaftDirectory& dir_;
  CommandGate& gate_;
  LogBudget& log_;
  std::function<sparkplug::NodeCounters()> counters_;
  std::unique_ptr<sparkplug::Node> node_;
  std::uint64_t births_ = 0, rebirths_ = 0, host_offline_ = 0;
};

}  // namespace hoist::mqtt
