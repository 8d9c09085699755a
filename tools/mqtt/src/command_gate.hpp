// command_gate.hpp -- the bridge's command gate: an operator's alarm
// command (hoist/<shaft>/cmd/ack, or a Sparkplug DCMD already parsed into
// JSON) is checked (hoist/mqtt/command.hpp), rate-limited, matched against
// the alarms the bridge knows, forwarded as HOIST_ALARM_ACK on LCM, and
// answered on hoist/<shaft>/cmd/result.  Private to tools/mqtt; the map of
// the rooms is bridge.cpp.
//
// Writes only its own state (counters, the token buckets); reads the shaft
// directory and the alarm states through const views.
#pragma once

#include <mosquitto.h>

#include <array>
#include <cstdint>
#include <map>
#include <string>

#include "bridge_common.hpp"
#include "hoist/mqtt/command.hpp"
#include "hoist/mqtt/config.hpp"
#include "hoist/rt/token_bucket.hpp"
#include "lcm_side.hpp"
#include "mqtt_link.hpp"
#include "shaft_data.hpp"
#include "shaft_directory.hpp"

namespace hoist::mqtt {

class CommandGate {
 public:
  static constexpr std::size_t kMaxUsersPerShaft = 256;  // rate-limit buckets kept per shaft

  /// Every argument is referenced and must outlive the gate.  `sparkplug`:
  /// commands arrive as DCMD (no result topic; counted only).
  CommandGate(const BridgeConfig& cfg, bool sparkplug, const ShaftDirectory& dir, const ShaftData& data, LcmSide& lcm,
              MqttLink& link, LogBudget& log);
  CommandGate(const CommandGate&) = delete;
  CommandGate& operator=(const CommandGate&) = delete;

  /// A message on a subscribed JSON command topic: the legacy shared
  /// hoist/<shaft>/cmd/ack, or hoist/<shaft>/cmd/ack/<user>, whose <user>
  /// the broker vouches for (an ACL pattern "write hoist/+/cmd/ack/%u":
  /// tools/mqtt/config/mosquitto-acl.conf).
  void onMessage(const struct mosquitto_message* m);
  /// A command that passed the checker (parseAckCommand), for shaft `s`:
  /// rate limit, a matching alarm, then HOIST_ALARM_ACK on LCM.
  /// `identity`: the topic's <user> ("" = the legacy shared topic).
  void execute(const Shaft& s, const CommandResult& r, int payloadlen, bool may_log, Clock::time_point now,
               const std::string& identity = "");
  /// A refused command (`s` may be nullptr: no such shaft).
  void refuse(const Shaft* s, CommandReject why, const std::string& detail, const std::string& topic, int payloadlen,
              bool may_log, const hoist::alarm_ack_t* ack = nullptr, const std::string& identity = "");
  /// Sparkplug: a command that is not an alarm command (Rebirth).
  void countReceived() { ++n_.received; }
  void countForwarded() { ++n_.forwarded; }
  /// The shaft's buckets go with it.
  void forget(const std::string& prefix) { shafts_.erase(prefix); }

  /// Where a shaft's commands arrive (for the log).
  std::string cmdTopic(const Shaft& s) const;

  struct Counters {
    std::uint64_t received = 0, forwarded = 0, rejected = 0, lcm_failures = 0;
    std::uint64_t results_published = 0, results_dropped = 0;
    std::array<std::uint64_t, kCommandRejects> by_reason{};
  };
  const Counters& counters() const { return n_; }
  /// Commands forwarded to the shaft of `prefix`.
  std::uint64_t commands(const std::string& prefix) const;

 private:
  bool rateAllows(const Shaft& s, const std::string& user, const std::string& identity, Clock::time_point now);
  void answer(const Shaft& s, const char* result, const char* reason, const std::string& detail,
              const hoist::alarm_ack_t* ack, const std::string& identity = "");

  /// A shaft's command budget.  Legacy topic: all its users together (4x a
  /// user's: the small shared budget) and per payload user.  Per-identity
  /// topics: one bucket per identity, nobody else's to spend; results too.
  struct ShaftBudget {
    explicit ShaftBudget(double rate, double burst) : total(4.0 * rate, 4.0 * burst) {}
    hoist::rt::TokenBucket total;
    std::map<std::string, hoist::rt::TokenBucket> users;       // legacy, by payload user (bounded: kMaxUsersPerShaft)
    std::map<std::string, hoist::rt::TokenBucket> identities;  // cmd/ack/<user> (bounded: kMaxUsersPerShaft)
    std::map<std::string, hoist::rt::TokenBucket> results;     // cmd/result budget per identity (bounded)
    std::uint64_t commands = 0;
  };
  /// `table`'s bucket for `key`, made (rate, burst) if missing; idle ones
  /// are forgotten when the table is full; nullptr if it stays full.
  static hoist::rt::TokenBucket* bucket(std::map<std::string, hoist::rt::TokenBucket>& table, const std::string& key,
                                        double rate, double burst, double now);

  const BridgeConfig& cfg_;
  const bool sparkplug_;
  const ShaftDirectory& dir_;
  const ShaftData& data_;
  LcmSide& lcm_;
  MqttLink& link_;
  LogBudget& log_;
  std::map<std::string, ShaftBudget> shafts_;  // by prefix
  hoist::rt::TokenBucket result_budget_{20.0, 50.0};  // cmd/result: at most 20/s (bursts of 50), so a flood is not echoed
  Counters n_;
};

}  // namespace hoist::mqtt
