// Operator alarm commands: see hoist/contract/alarm_command.hpp.
#include <algorithm>
#include "hoist/contract/alarm_command.hpp"

#include <cmath>
#include <limits>

namespace hoist::contract {

const char* toString(AlarmAction a) {
  switch (a) {
    case AlarmAction::Ack: return "ACK";
    case AlarmAction::Shelve: return "SHELVE";
    case AlarmAction::Unshelve: return "UNSHELVE";
    case AlarmAction::Reannounce: return "REANNOUNCE";
    case AlarmAction::Calibrate: return "CALIBRATE";
    case AlarmAction::AdoptPreload: return "ADOPT_PRELOAD";
  }
  return "?";
}

const char* toString(CommandError e) {
  switch (e) {
    case CommandError::None: return "ok";
    case CommandError::UnknownKind: return "unknown_kind";
    case CommandError::BadLevel: return "bad_level";
    case CommandError::BadAction: return "bad_action";
    case CommandError::BadShelveDuration: return "bad_shelve_duration";
    case CommandError::BadCalibration: return "bad_calibration";
    case CommandError::BadPreload: return "bad_preload";
  }
  return "?";
}

CommandError validateAlarmCommand(std::string_view kind, int level, int action, double shelve_duration,
                                  AlarmCommand& out) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return validateAlarmCommand(kind, level, action, shelve_duration, nan, nan, nan, nan, out);
}

CommandError validateAlarmCommand(std::string_view kind, int level, int action, double shelve_duration,
                                  double known_fa, double known_b, double calibrate_duration, AlarmCommand& out) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return validateAlarmCommand(kind, level, action, shelve_duration, known_fa, known_b, calibrate_duration, nan, out);
}

CommandError validateAlarmCommand(std::string_view kind, int level, int action, double shelve_duration,
                                  double known_fa, double known_b, double calibrate_duration, double preload_scale,
                                  AlarmCommand& out) {
  AlarmCommand c;
  if (action == static_cast<int>(AlarmAction::AdoptPreload)) {
    // The model, not an alarm: kind and level are ignored.
    if (!(std::isfinite(preload_scale) && preload_scale >= kMinPreloadScale && preload_scale <= kMaxPreloadScale))
      return CommandError::BadPreload;
    c.action = AlarmAction::AdoptPreload;
    c.preload_scale = preload_scale;
    out = c;
    return CommandError::None;
  }
  if (action == static_cast<int>(AlarmAction::Calibrate)) {
    // The load, not an alarm: kind and level are ignored.
    if (!(std::isfinite(known_fa) && known_fa >= 0.0 && known_fa <= kMaxCalibrationForce) ||
        !(std::isfinite(known_b) && std::abs(known_b) <= kMaxCalibrationOffset) ||
        !(std::isfinite(calibrate_duration) && calibrate_duration > 0.0 && calibrate_duration <= kMaxCalibration))
      return CommandError::BadCalibration;
    c.action = AlarmAction::Calibrate;
    c.known_fa = known_fa;
    c.known_b = known_b;
    c.calibrate_duration = calibrate_duration;
    out = c;
    return CommandError::None;
  }
  if (!kind.empty() && kind != "*") {
    c.kind = parseAlarmKind(kind);
    if (!c.kind) return CommandError::UnknownKind;
  }
  if (level < 0 || level > 2) return CommandError::BadLevel;
  c.level = static_cast<AlarmLevel>(level);
  switch (action) {
    case static_cast<int>(AlarmAction::Ack): c.action = AlarmAction::Ack; break;
    case static_cast<int>(AlarmAction::Shelve): c.action = AlarmAction::Shelve; break;
    case static_cast<int>(AlarmAction::Unshelve): c.action = AlarmAction::Unshelve; break;
    case static_cast<int>(AlarmAction::Reannounce): c.action = AlarmAction::Reannounce; break;
    default: return CommandError::BadAction;
  }
  if (c.action == AlarmAction::Shelve && !(std::isfinite(shelve_duration) && shelve_duration > 0.0))
    return CommandError::BadShelveDuration;
  c.shelve_duration = c.action == AlarmAction::Shelve ? shelve_duration : 0.0;
  out = c;
  return CommandError::None;
}

const char* operatorNameProblem(std::string_view user) {
  if (user.empty() || user.size() > kMaxOperatorName) return "user must have 1..64 characters";
  for (std::size_t i = 0; i < user.size(); ++i) {
    const auto ch = static_cast<unsigned char>(user[i]);
    if (ch < 0x20 || ch == 0x7f) return "user may not contain control characters";
    // C1 controls U+0080..U+009F are C2 80..C2 9F in UTF-8.
    if (ch == 0xc2 && i + 1 < user.size() && static_cast<unsigned char>(user[i + 1]) <= 0x9f)
      return "user may not contain control characters";
  }
  return nullptr;
}

std::string printable(const std::string& s, std::size_t max) {
  std::string o;
  o.reserve(std::min(s.size(), max) + 3);
  for (std::size_t i = 0; i < s.size() && i < max; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    o.push_back(c >= 32 && c < 127 ? static_cast<char>(c) : '?');
  }
  if (s.size() > max) o += "...";
  return o;
}

}  // namespace hoist::contract
