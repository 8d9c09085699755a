// hoist/contract/alarm_vocabulary.hpp -- the alarm vocabulary shared by
// hoist-twind and its clients (hoist-alarm-ack, hoist-mqtt, ...): the alarm
// kinds and their names (alarm_t.kind, alarm_ack_t.kind), the levels
// (alarm_t.LEVEL_*), the event types (alarm_t.EVENT_*), and the longest
// shelve the daemon grants by default.  Pure: no I/O, no allocation.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "hoist/msg/names.hpp"  // generated from alarm_t.lcm; standard library only (no LCM)

namespace hoist::contract {

/// Every alarm kind the daemon raises (alarm_t.KIND_*: KIND_CAGE_POS_Y is
/// AlarmKind::CagePosY); the name is toString(kind).  Generated from the
/// `// @enum kind KIND_` of msgs/alarm_t.lcm: a new kind is its const there
/// (and the daemon's code that raises it).
using AlarmKind = hoist::msg::enums::alarm_t::Kind;
inline constexpr int kAlarmKinds = static_cast<int>(hoist::msg::enums::alarm_t::kKindNames.size());

/// alarm_t.LEVEL_* (None, Warning, Critical), generated likewise.
using AlarmLevel = hoist::msg::enums::alarm_t::Level;

/// alarm_t.EVENT_* (Raise, Clear, Ack, Shelve, Unshelve, Reannounce), generated likewise.
using AlarmEventType = hoist::msg::enums::alarm_t::Event;

/// The default of [alarms] max_shelve: the longest shelve an operator may set [s].
inline constexpr double kDefaultMaxShelve = 3600.0;

const char* toString(AlarmKind k);        ///< "CAGE_POS_Y", ...
const char* toString(AlarmLevel l);       ///< "NONE", "WARNING", "CRITICAL"
const char* toString(AlarmEventType e);   ///< "RAISE", ...
std::optional<AlarmKind> parseAlarmKind(std::string_view s);  ///< case-sensitive names above

}  // namespace hoist::contract
