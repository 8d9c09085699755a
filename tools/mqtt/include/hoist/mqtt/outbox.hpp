// hoist/mqtt/outbox.hpp -- the bridge's bounded buffer of outgoing MQTT
// messages, used while the broker is unreachable (or its socket congested).
//
// Two bounds: at most `max_messages` cage and health messages, and at most
// `max_alarm_events` alarm transitions (and bridge status messages).  When the
// first bound is reached the OLDEST CAGE STATE is dropped (then, with no cage
// state left, the oldest health message); cage states never displace an
// alarm transition.  Alarm transitions are dropped (oldest first, counted)
// only past their own, much larger bound; after a reconnection the bridge
// republishes every alarm's current state anyway.  Order is preserved.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <string>

namespace hoist::mqtt {

enum class MsgClass : std::uint8_t { Cage, Health, Alarm };

struct OutMsg {
  std::string topic;
  std::string payload;
  int qos = 0;
  bool retain = false;
  MsgClass cls = MsgClass::Cage;
  std::chrono::steady_clock::time_point queued{};  ///< set by Outbox::push (age at sending: stale cage states)
  /// The payload is an encoded Sparkplug B Payload whose seq (and the
  /// metrics' is_historical) are set when it is actually sent
  /// (hoist::mqtt::sparkplug::stamp, in the bridge's one send path).
  bool sparkplug = false;
};

class Outbox {
 public:
  Outbox(std::size_t max_messages, std::size_t max_alarm_events)
      : max_msgs_(max_messages), max_alarms_(max_alarm_events) {}

  void push(OutMsg m);

  bool empty() const { return q_.empty(); }
  std::size_t size() const { return q_.size(); }
  const OutMsg& front() const { return q_.front(); }
  void pop();

  std::size_t queuedAlarms() const { return n_alarm_; }
  std::uint64_t droppedCage() const { return dropped_cage_; }
  std::uint64_t droppedHealth() const { return dropped_health_; }
  std::uint64_t droppedAlarm() const { return dropped_alarm_; }

 private:
  bool dropOldest(MsgClass c);
  std::size_t& counter(MsgClass c) { return c == MsgClass::Cage ? n_cage_ : c == MsgClass::Health ? n_health_ : n_alarm_; }

  std::size_t max_msgs_, max_alarms_;
  std::deque<OutMsg> q_;
  std::size_t n_cage_ = 0, n_health_ = 0, n_alarm_ = 0;
  std::uint64_t dropped_cage_ = 0, dropped_health_ = 0, dropped_alarm_ = 0;
};

}  // namespace hoist::mqtt
