// The alarm vocabulary: see hoist/contract/alarm_vocabulary.hpp.
#include "hoist/contract/alarm_vocabulary.hpp"

#include "hoist/msg/names.hpp"

namespace hoist::contract {

// The names and the enums are both alarm_t.lcm's (KIND_*, LEVEL_*, EVENT_*),
// generated into hoist/msg/names.hpp.
namespace names = hoist::msg::enums::alarm_t;
static_assert(names::kKindFirst == 0, "AlarmKind indexes per-kind tables from 0");

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
