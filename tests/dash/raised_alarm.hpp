// Test helper (tests/dash, not installed): an alarm_t RAISE event as
// hoist-twind publishes it (active, unacknowledged, not shelved or latched,
// no operator), for the synthetic publishers of the dashboard's Node tests.
#pragma once

#include <cstdint>
#include <string>

#include "hoist/alarm_t.hpp"

inline hoist::alarm_t raisedAlarm(std::int64_t utime, double t, const std::string& kind, std::int8_t level, double value,
                                  double threshold, const std::string& message) {
  hoist::alarm_t a{};
  a.utime = utime;
  a.t = t;
  a.kind = kind;
  a.level = level;
  a.event_type = hoist::alarm_t::EVENT_RAISE;
  a.active = 1;
  a.value = value;
  a.threshold = threshold;
  a.message = message;
  a.user = "";
  return a;
}
