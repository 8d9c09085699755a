// hoist/mqtt/command.hpp -- an operator's alarm command arriving on
// hoist/<shaft>/cmd/ack, checked before it becomes a HOIST_ALARM_ACK.
//
// Payload: one JSON object with the fields of alarm_ack_t (msgs/alarm_ack_t.lcm):
//   {"kind": "CAGE_POS_Y", "level": 0, "action": 1, "shelve_duration": 0, "user": "op1", "utime": 0}
// `kind`, `level` and `action` are required; `shelve_duration` (default 0),
// `user` (default "mqtt") and `utime` (default: the bridge's clock) may be
// left out.  The JSON is converted by the codec's strict fromJson (unknown
// keys, wrong types, out-of-range integers rejected) and then validated by
// the daemon's own rule (hoist::contract::validateAlarmCommand), so the bridge
// forwards exactly what hoist-twind would accept.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/contract/alarm_command.hpp"

namespace hoist::mqtt {

/// Why a command payload was rejected (counted by reason in the bridge's health).
enum class CommandReject : std::uint8_t {
  None,
  Oversized,      ///< more than max_command_bytes
  NotJson,        ///< not valid JSON (or not UTF-8)
  NotObject,      ///< JSON, but not an object
  BadFields,      ///< missing/unknown keys, wrong types, out-of-range integers (codec fromJson)
  UnknownKind,    ///< kind is not an alarm kind, "" or "*"
  BadLevel,       ///< level not 0, 1 or 2
  BadAction,      ///< action not 1 (ack), 2 (shelve) or 3 (unshelve)
  BadShelveDuration,  ///< shelve without a finite duration > 0
};
inline constexpr int kCommandRejects = 9;
const char* toString(CommandReject r);  ///< "ok", "oversized", "not_json", ...

struct CommandResult {
  CommandReject reject = CommandReject::None;
  std::string detail;        ///< for the log: printable, at most 120 characters, never raw payload bytes
  hoist::alarm_ack_t ack{};  ///< valid when reject == None
};

/// Parses and validates one payload.  Never throws.
CommandResult parseAckCommand(const void* data, std::size_t size, std::size_t max_bytes, std::int64_t now_utime);

/// printable(): the daemon's own, hoist/contract/alarm_command.hpp.
using hoist::contract::printable;

}  // namespace hoist::mqtt
