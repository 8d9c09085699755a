// Alarm commands from MQTT: see hoist/mqtt/command.hpp.
#include "hoist/mqtt/command.hpp"

#include <nlohmann/json.hpp>

#include "hoist/msg/codec.hpp"
#include "hoist/contract/alarm_command.hpp"

namespace hoist::mqtt {

const char* toString(CommandReject r) {
  switch (r) {
    case CommandReject::None: return "ok";
    case CommandReject::Oversized: return "oversized";
    case CommandReject::NotJson: return "not_json";
    case CommandReject::NotObject: return "not_object";
    case CommandReject::BadFields: return "bad_fields";
    case CommandReject::UnknownKind: return "unknown_kind";
    case CommandReject::BadLevel: return "bad_level";
    case CommandReject::BadAction: return "bad_action";
    case CommandReject::BadShelveDuration: return "bad_shelve_duration";
  }
  return "?";
}

CommandResult parseAckCommand(const void* data, std::size_t size, std::size_t max_bytes, std::int64_t now_utime) {
  CommandResult r;
  try {
    if (size > max_bytes) {
      r.reject = CommandReject::Oversized;
      r.detail = std::to_string(size) + " bytes > " + std::to_string(max_bytes);
      return r;
    }
    const auto* p = static_cast<const char*>(data);
    nlohmann::json j = nlohmann::json::parse(p, p + (data ? size : 0), nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) {
      r.reject = CommandReject::NotJson;
      r.detail = std::to_string(size) + " bytes of invalid JSON";
      return r;
    }
    if (!j.is_object()) {
      r.reject = CommandReject::NotObject;
      r.detail = std::string("a JSON ") + j.type_name() + ", expected an object";
      return r;
    }
    // Conveniences for SCADA clients; everything else is the codec's strict rule.
    if (!j.contains("utime")) j["utime"] = now_utime;
    if (!j.contains("shelve_duration")) j["shelve_duration"] = 0.0;
    if (!j.contains("user")) j["user"] = "mqtt";
    std::string error;
    if (!hoist::msg::fromJson(j, r.ack, error)) {
      r.reject = CommandReject::BadFields;
      r.detail = printable(error, 120);
      return r;
    }
    hoist::contract::AlarmCommand cmd;
    switch (hoist::contract::validateAlarmCommand(r.ack.kind, r.ack.level, r.ack.action, r.ack.shelve_duration, cmd)) {
      case hoist::contract::CommandError::None: break;
      case hoist::contract::CommandError::UnknownKind:
        r.reject = CommandReject::UnknownKind;
        r.detail = "unknown alarm kind '" + printable(r.ack.kind, 32) + "'";
        return r;
      case hoist::contract::CommandError::BadLevel:
        r.reject = CommandReject::BadLevel;
        r.detail = "level " + std::to_string(int(r.ack.level)) + " (0 both, 1 WARNING, 2 CRITICAL)";
        return r;
      case hoist::contract::CommandError::BadAction:
        r.reject = CommandReject::BadAction;
        r.detail = "action " + std::to_string(int(r.ack.action)) + " (1 ack, 2 shelve, 3 unshelve)";
        return r;
      case hoist::contract::CommandError::BadShelveDuration:
        r.reject = CommandReject::BadShelveDuration;
        r.detail = "shelve needs a shelve_duration > 0 s";
        return r;
    }
    if (r.ack.utime <= 0) r.ack.utime = now_utime;
    return r;
  } catch (const std::exception& e) {  // e.g. std::bad_alloc; nothing may escape the MQTT callback
    r.reject = CommandReject::BadFields;
    r.detail = std::string("internal error: ") + printable(e.what(), 80);
    return r;
  }
}

}  // namespace hoist::mqtt
