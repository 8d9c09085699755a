// The alarm vocabulary: see hoist/contract/alarm_vocabulary.hpp.
#include "hoist/contract/alarm_vocabulary.hpp"

namespace hoist::contract {

const char* toString(AlarmKind k) {
  switch (k) {
    case AlarmKind::CagePosY: return "CAGE_POS_Y";
    case AlarmKind::CageNegY: return "CAGE_NEG_Y";
    case AlarmKind::GuideRope: return "GUIDE_ROPE";
    case AlarmKind::InputStale: return "INPUT_STALE";
    case AlarmKind::ModelFault: return "MODEL_FAULT";
    case AlarmKind::ModelDomain: return "MODEL_DOMAIN";
    case AlarmKind::DuplicatePublisher: return "DUPLICATE_PUBLISHER";
    case AlarmKind::RopeSlack: return "ROPE_SLACK";
    case AlarmKind::RopeOverload: return "ROPE_OVERLOAD";
    case AlarmKind::PredictedClearance: return "PREDICTED_CLEARANCE";
    case AlarmKind::PredictedSlack: return "PREDICTED_SLACK";
  }
  return "?";
}

const char* toString(AlarmLevel l) {
  switch (l) {
    case AlarmLevel::None: return "NONE";
    case AlarmLevel::Warning: return "WARNING";
    case AlarmLevel::Critical: return "CRITICAL";
  }
  return "?";
}

const char* toString(AlarmEventType e) {
  switch (e) {
    case AlarmEventType::Raise: return "RAISE";
    case AlarmEventType::Clear: return "CLEAR";
    case AlarmEventType::Ack: return "ACK";
    case AlarmEventType::Shelve: return "SHELVE";
    case AlarmEventType::Unshelve: return "UNSHELVE";
    case AlarmEventType::Reannounce: return "REANNOUNCE";
  }
  return "?";
}

std::optional<AlarmKind> parseAlarmKind(std::string_view s) {
  for (int i = 0; i < kAlarmKinds; ++i) {
    const auto k = static_cast<AlarmKind>(i);
    if (s == toString(k)) return k;
  }
  return std::nullopt;
}

}  // namespace hoist::contract
