// hoist/mqtt/bridge.hpp -- hoist-mqtt's bridge between LCM and an MQTT broker.
//
// One thread polls both sides (the LCM file descriptor and the broker's
// socket through libmosquitto's loop), so no state is shared between threads.
//
// LCM -> MQTT (topics: docs/mqtt.md; <shaft> = channel prefix without its
// trailing separator, or "default"):
//   <prefix>HOIST_CAGE    -> hoist/<shaft>/cage         QoS 0, latest state at [bridge] cage_rate
//   <prefix>HOIST_HEALTH  -> hoist/<shaft>/health       QoS 0, every message
//   <prefix>HOIST_ALARM   -> hoist/<shaft>/alarm/<KIND> QoS 1, RETAINED: the kind's current state
//   <prefix>HOIST_FORECAST -> hoist/<shaft>/forecast    QoS 0, every message
//   <prefix>HOIST_ESTIMATE -> hoist/<shaft>/estimate    QoS 0, latest estimate at [bridge] cage_rate
// MQTT -> LCM (unless --no-commands):
//   hoist/<shaft>/cmd/ack/<user> -> <prefix>HOIST_ALARM_ACK  (one identity per topic, vouched for by the
//                                   broker's ACL; its own budget; hoist/mqtt/command.hpp)
//   hoist/<shaft>/cmd/ack        -> <prefix>HOIST_ALARM_ACK  (the legacy shared topic, one small shared budget)
// The bridge itself:
//   hoist/_bridge/<client_id>/status  QoS 1, RETAINED: {"online": true|false}; the LWT sets false
//   hoist/_bridge/<client_id>/health  QoS 0, every [bridge] health_period: connection state, counters
//
// Every LCM payload is validated by the codec (hoist::msg::checkedDecode)
// before anything is allocated from it; failures are counted by type and
// reason.  No exception leaves a callback.  The broker being down at start or
// going away is never fatal: the bridge retries with exponential backoff
// ([broker] reconnect_min..reconnect_max), logs once per state change, buffers
// a bounded number of messages (hoist/mqtt/outbox.hpp) -- or, with [buffer]
// dir, stores them in an on-disk journal that survives a restart and is
// replayed in order before live data (hoist/mqtt/journal.hpp; every message
// then goes through one send function, sendOne(msg, historical)) -- and on
// every (re)connection re-subscribes and republishes every alarm's current state.
//
// Inside, the bridge is in rooms (tools/mqtt/src; the map is at the top of
// bridge.cpp): the LCM side, the shaft directory, the data path, the MQTT
// link, the Sparkplug session, the command gate and the bridge's health.
#pragma once

#include <csignal>
#include <memory>
#include <string>

#include "hoist/mqtt/config.hpp"

namespace hoist::mqtt {

class Bridge {
 public:
  /// `password` already resolved (resolvePassword).  Throws std::runtime_error
  /// if LCM cannot be opened or libmosquitto refuses the settings.
  Bridge(const BridgeConfig& cfg, const std::string& password);
  ~Bridge();
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;

  /// Runs until `stop` becomes non-zero; then publishes the offline status,
  /// disconnects cleanly and returns 0.
  int run(const volatile std::sig_atomic_t& stop);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hoist::mqtt
