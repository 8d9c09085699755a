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
// forwards exactly what hoist-twind would accept.  On top of that:
//   * a key given twice anywhere in the payload is refused (no "last wins");
//   * `user` follows hoist-dash's rule (1..64 bytes, no control character:
//     bytes < 0x20, 0x7f, and the C1 controls U+0080..U+009F) -- refused, never forwarded;
//   * with max_age_s > 0, a `utime` given by the client must be within
//     max_age_s of the bridge's clock (a stale or replayed command is refused).
// The bridge itself refuses retained messages, rate-limits per user and
// shaft, and answers every command on hoist/<shaft>/cmd/result (bridge.hpp).
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
  BadAction,      ///< action not 1 (ack), 2 (shelve), 3 (unshelve), 4 (re-announce) or 5 (calibrate)
  BadShelveDuration,  ///< shelve without a finite duration > 0
  DuplicateKey,   ///< a JSON key given twice
  BadUser,        ///< user empty, longer than 64 bytes, or with a control character
  StaleUtime,     ///< utime further than max_age_s from the bridge's clock
  Retained,       ///< a retained MQTT message (never executed: it would replay on every resubscription)
  RateLimited,    ///< over the per-user, per-shaft rate ([bridge] command_rate, command_burst)
  NoMatchingAlarm,  ///< an acknowledge that matches no unacknowledged alarm the bridge knows of
  AmbiguousShaft,   ///< no longer used (issue 33: the name stays with the daemon first heard); kept so the health keys do not change
  // Sparkplug B mode (DCMD/NCMD; hoist/mqtt/sparkplug_node.hpp):
  BadPayload,       ///< not a Sparkplug B payload (malformed protobuf, too many metrics, strings too long)
  UnknownMetric,    ///< a name or alias that is not a metric of the device (or node), or an unknown device
  ReadOnly,         ///< a write to a metric that is not writable
  BadValue,         ///< the value's type or range does not fit the metric
  Disabled,         ///< alarm commands are off (--no-commands, [bridge] commands = false)
  BadCalibration,   ///< calibrate (action 5) without known_fa in [0, 1e7] N, |known_b| <= 100 m, duration in (0, 600] s
};
inline constexpr int kCommandRejects = 22;
const char* toString(CommandReject r);  ///< "ok", "oversized", "not_json", ...

/// The `user` of a payload that names none.
inline constexpr const char* kDefaultCommandUser = "mqtt";

struct CommandResult {
  CommandReject reject = CommandReject::None;
  std::string detail;        ///< for the log: printable, at most 120 characters, never raw payload bytes
  hoist::alarm_ack_t ack{};  ///< valid when reject == None
};

/// Parses and validates one payload.  Never throws.  `max_age_s` > 0: a
/// client-given utime must be within that many seconds of `now_utime`.
CommandResult parseAckCommand(const void* data, std::size_t size, std::size_t max_bytes, std::int64_t now_utime,
                              double max_age_s = 0.0);

/// The contract's one operator-name rule (hoist::contract::operatorNameProblem,
/// as hoist-dash's): "" if valid, else why.
std::string checkUser(const std::string& user);

/// printable(): the daemon's own, hoist/contract/alarm_command.hpp.
using hoist::contract::printable;

}  // namespace hoist::mqtt
