// Test helper (tests/dash, not installed): an alarm_t RAISE event as
// hoist-twind publishes it (active, unacknowledged, not shelved or latched,
// no operator), for the synthetic publishers of the dashboard's Node tests.
#pragma once

#include <cstdint>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include <chrono>

#include "hoist/alarm_t.hpp"
#include "hoist/health_t.hpp"

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

/// Speaks as the shaft's daemon (hoist-dash accepts alarm events only from
/// the daemon instance whose health it follows: issue 33).  Listens on
/// <prefix>HOIST_HEALTH for up to `wait_ms`: with a daemon heard, its
/// instance id; else instance 4242, announced by a health_t of its own
/// (published three times, as hoist-dash's discovery wants).  Event ids are
/// left 0 (one the daemon has used: it raises DUPLICATE_PUBLISHER for an
/// event with its id that it never published).
struct DaemonVoice {
  std::int64_t instance = 0;
  DaemonVoice(::lcm::LCM& lcm, const std::string& prefix, int wait_ms) {
    auto* hs = lcm.subscribeFunction(prefix + "HOIST_HEALTH",
                                     +[](const ::lcm::ReceiveBuffer*, const std::string&, const hoist::health_t* h,
                                         DaemonVoice* v) { v->instance = h->instance_id; }, this);
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(wait_ms);
    while (instance == 0 && std::chrono::steady_clock::now() < end) lcm.handleTimeout(50);
    lcm.unsubscribe(hs);
    if (instance != 0) return;
    instance = 4242;
    hoist::health_t h{};
    h.instance_id = instance;
    h.clock = "wall";
    for (int i = 0; i < 3; ++i) {
      h.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                    std::chrono::system_clock::now().time_since_epoch()).count();
      lcm.publish(prefix + "HOIST_HEALTH", &h);
      lcm.handleTimeout(100);
    }
  }
  /// `a` as the daemon's event.
  hoist::alarm_t sign(hoist::alarm_t a) {
    a.instance_id = instance;
    return a;
  }
};
