// Alarm commands from MQTT: see hoist/mqtt/command.hpp.
#include "hoist/mqtt/command.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <cstdio>
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
    case CommandReject::DuplicateKey: return "duplicate_key";
    case CommandReject::BadUser: return "bad_user";
    case CommandReject::StaleUtime: return "stale_utime";
    case CommandReject::Retained: return "retained";
    case CommandReject::RateLimited: return "rate_limited";
    case CommandReject::NoMatchingAlarm: return "no_matching_alarm";
    case CommandReject::AmbiguousShaft: return "ambiguous_shaft";
    case CommandReject::BadPayload: return "bad_payload";
    case CommandReject::UnknownMetric: return "unknown_metric";
    case CommandReject::ReadOnly: return "read_only";
    case CommandReject::BadValue: return "bad_value";
    case CommandReject::Disabled: return "disabled";
    case CommandReject::BadCalibration: return "bad_calibration";
  }
  return "?";
}

std::string checkUser(const std::string& user) {
  const char* why = hoist::contract::operatorNameProblem(user);  // the contract's one rule
  return why ? why : "";
}

CommandResult parseAckCommand(const void* data, std::size_t size, std::size_t max_bytes, std::int64_t now_utime,
                              double max_age_s) {
  CommandResult r;
  try {
    if (size > max_bytes) {
      r.reject = CommandReject::Oversized;
      r.detail = std::to_string(size) + " bytes > " + std::to_string(max_bytes);
      return r;
    }
    const auto* p = static_cast<const char*>(data);
    // Keys seen per open object: a key given twice is refused (nlohmann keeps the last).
    std::vector<std::vector<std::string>> open_objects;
    std::string duplicate;
    nlohmann::json::parser_callback_t cb = [&](int, nlohmann::json::parse_event_t ev, nlohmann::json& parsed) {
      using E = nlohmann::json::parse_event_t;
      if (ev == E::object_start) {
        open_objects.emplace_back();
      } else if (ev == E::object_end) {
        if (!open_objects.empty()) open_objects.pop_back();
      } else if (ev == E::key && !open_objects.empty() && parsed.is_string()) {
        auto& keys = open_objects.back();
        const auto& k = parsed.get_ref<const std::string&>();
        if (std::find(keys.begin(), keys.end(), k) != keys.end()) {
          if (duplicate.empty()) duplicate = k;
        } else {
          keys.push_back(k);
        }
      }
      return true;
    };
    nlohmann::json j = nlohmann::json::parse(p, p + (data ? size : 0), cb, /*allow_exceptions=*/false);
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
    if (!duplicate.empty()) {
      r.reject = CommandReject::DuplicateKey;
      r.detail = "key '" + printable(duplicate, 32) + "' given twice";
      return r;
    }
    // Conveniences for SCADA clients; everything else is the codec's strict rule.
    const bool client_utime = j.contains("utime");
    if (!client_utime) j["utime"] = now_utime;
    if (!j.contains("shelve_duration")) j["shelve_duration"] = 0.0;
    // The calibration's fields (alarm_ack_t.ACTION_CALIBRATE only): absent
    // in every alarm command.
    for (const char* k : {"known_fa", "known_b", "calibrate_duration", "preload_scale"})
      if (!j.contains(k)) j[k] = 0.0;
    if (!j.contains("user")) j["user"] = kDefaultCommandUser;
    std::string error;
    if (!hoist::msg::fromJson(j, r.ack, error)) {
      r.reject = CommandReject::BadFields;
      r.detail = printable(error, 120);
      return r;
    }
    if (const std::string why = checkUser(r.ack.user); !why.empty()) {
      r.reject = CommandReject::BadUser;
      r.detail = why + " ('" + printable(r.ack.user, 32) + "')";
      return r;
    }
    if (client_utime && max_age_s > 0.0 && r.ack.utime > 0) {
      const double age = static_cast<double>(now_utime - r.ack.utime) * 1e-6;
      if (std::abs(age) > max_age_s) {
        r.reject = CommandReject::StaleUtime;
        char buf[128];
        std::snprintf(buf, sizeof buf, "utime is %.1f s %s the bridge's clock (at most %g s)", std::abs(age),
                      age > 0 ? "behind" : "ahead of", max_age_s);
        r.detail = buf;
        return r;
      }
    }
    hoist::contract::AlarmCommand cmd;
    switch (hoist::contract::validateAlarmCommand(r.ack.kind, r.ack.level, r.ack.action, r.ack.shelve_duration,
                                                  r.ack.known_fa, r.ack.known_b, r.ack.calibrate_duration, cmd)) {
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
        r.detail = "action " + std::to_string(int(r.ack.action)) +
                   " (1 ack, 2 shelve, 3 unshelve, 4 re-announce, 5 calibrate)";
        return r;
      case hoist::contract::CommandError::BadShelveDuration:
        r.reject = CommandReject::BadShelveDuration;
        r.detail = "shelve needs a shelve_duration > 0 s";
        return r;
      case hoist::contract::CommandError::BadCalibration: {
        r.reject = CommandReject::BadCalibration;
        char got[96];
        std::snprintf(got, sizeof got, " (got %g, %g, %g)", r.ack.known_fa, r.ack.known_b, r.ack.calibrate_duration);
        r.detail = std::string(hoist::contract::kCalibrationRule) + got;
        return r;
      }
      case hoist::contract::CommandError::BadPreload:
        // The 8-field rule refuses ACTION_ADOPT_PRELOAD: a new model for the
        // twin is adopted at the control room (hoist-alarm-ack), not over MQTT.
        r.reject = CommandReject::BadAction;
        r.detail = "action 6 (adopt preload) is not accepted over MQTT: use hoist-alarm-ack --adopt-preload";
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
