// Bounded outgoing buffer: see hoist/mqtt/outbox.hpp.
#include "hoist/mqtt/outbox.hpp"

namespace hoist::mqtt {

bool Outbox::dropOldest(MsgClass c) {
  for (auto it = q_.begin(); it != q_.end(); ++it) {
    if (it->cls != c) continue;
    q_.erase(it);
    --counter(c);
    (c == MsgClass::Cage ? dropped_cage_ : c == MsgClass::Health ? dropped_health_ : dropped_alarm_)++;
    return true;
  }
  return false;
}

void Outbox::push(OutMsg m) {
  if (m.cls == MsgClass::Alarm) {
    if (n_alarm_ >= max_alarms_) dropOldest(MsgClass::Alarm);
  } else if (n_cage_ + n_health_ >= max_msgs_) {
    if (!dropOldest(MsgClass::Cage)) dropOldest(MsgClass::Health);
  }
  ++counter(m.cls);
  if (m.queued == std::chrono::steady_clock::time_point{}) m.queued = std::chrono::steady_clock::now();
  q_.push_back(std::move(m));
}

void Outbox::pop() {
  --counter(q_.front().cls);
  q_.pop_front();
}

}  // namespace hoist::mqtt
