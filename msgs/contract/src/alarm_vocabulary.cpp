// The alarm vocabulary: see hoist/contract/alarm_vocabulary.hpp.
#include "hoist/contract/alarm_vocabulary.hpp"

#include "hoist/msg/names.hpp"

namespace hoist::contract {

// The names are alarm_t.lcm's (KIND_*, LEVEL_*, EVENT_*), generated into
// hoist/msg/names.hpp; the enums keep their values (checked here).
namespace names = hoist::msg::enums::alarm_t;
static_assert(names::kKindNames.size() == kAlarmKinds && names::kKindFirst == 0);
static_assert(names::parseKind("CAGE_POS_Y") == static_cast<int>(AlarmKind::CagePosY) &&
              names::parseKind("PREDICTED_SLACK") == static_cast<int>(AlarmKind::PredictedSlack) &&
              names::parseKind("SENSOR_FAULT") == static_cast<int>(AlarmKind::SensorFault) &&
              names::parseKind("GUIDE_PRELOAD_LOW") == static_cast<int>(AlarmKind::GuidePreloadLow) &&
              names::parseKind("SHAFT_FINGERPRINT") == static_cast<int>(AlarmKind::ShaftFingerprint));
static_assert(names::parseLevel("CRITICAL") == static_cast<int>(AlarmLevel::Critical));
static_assert(names::parseEvent("REANNOUNCE") == static_cast<int>(AlarmEventType::Reannounce));

// string_view::data() of the generated tables: string literals, NUL-terminated.
const char* toString(AlarmKind k) { return names::kindName(static_cast<int>(k)).data(); }
const char* toString(AlarmLevel l) { return names::levelName(static_cast<int>(l)).data(); }
const char* toString(AlarmEventType e) { return names::eventName(static_cast<int>(e)).data(); }

std::optional<AlarmKind> parseAlarmKind(std::string_view s) {
  const auto v = names::parseKind(s);
  if (!v) return std::nullopt;
  return static_cast<AlarmKind>(*v);
}

}  // namespace hoist::contract
