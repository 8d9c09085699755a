// hoist/contract/alarm_vocabulary.hpp -- the alarm vocabulary shared by
// hoist-twind and its clients (hoist-alarm-ack, hoist-mqtt, ...): the alarm
// kinds and their names (alarm_t.kind, alarm_ack_t.kind), the levels
// (alarm_t.LEVEL_*), the event types (alarm_t.EVENT_*), and the longest
// shelve the daemon grants by default.  Pure: no I/O, no allocation.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace hoist::contract {

/// Every alarm kind the daemon raises; the name is toString(kind).
enum class AlarmKind : std::uint8_t {
  CagePosY, CageNegY, GuideRope, InputStale, ModelFault, ModelDomain, DuplicatePublisher,
  RopeSlack, RopeOverload,            // live rope-force alarms
  PredictedClearance, PredictedSlack,  // look-ahead forecasts
  ModelMismatch,                      // the load estimator: the shaft does not behave like its model
  SensorFault,                        // a sensor of the estimator refused or not believed (names the sensor and why)
  GuidePreloadLow,                    // the shaft's memory: the guide-rope preload identified over trips is low
  ShaftFingerprint                    // the shaft's memory: a depth left its commissioning fingerprint
};
inline constexpr int kAlarmKinds = 15;

/// Values match alarm_t.LEVEL_*.
enum class AlarmLevel : std::int8_t { None = 0, Warning = 1, Critical = 2 };

/// Values match alarm_t.EVENT_*.
enum class AlarmEventType : std::int8_t {
  Raise = 1, Clear = 2, Ack = 3, Shelve = 4, Unshelve = 5, Reannounce = 6
};

/// The default of [alarms] max_shelve: the longest shelve an operator may set [s].
inline constexpr double kDefaultMaxShelve = 3600.0;

const char* toString(AlarmKind k);        ///< "CAGE_POS_Y", ...
const char* toString(AlarmLevel l);       ///< "NONE", "WARNING", "CRITICAL"
const char* toString(AlarmEventType e);   ///< "RAISE", ...
std::optional<AlarmKind> parseAlarmKind(std::string_view s);  ///< case-sensitive names above

}  // namespace hoist::contract
