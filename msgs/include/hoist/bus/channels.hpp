// hoist/bus/channels.hpp -- the LCM channel names (contract: the names are
// exact; the same as the `// @channel` of msgs/*.lcm, which the generated
// hoist/msg/names.hpp carries: CodecGenerated.ChannelsMatchBusChannels).
// Every program that publishes or subscribes uses these instead of spelling
// the strings; a configured prefix ([service] channel_prefix,
// --channel-prefix) is prepended to every name.
// Part of the hoist_lcm target (msgs/CMakeLists.txt).
#pragma once

#include <string>
#include <string_view>

namespace hoist::bus {

inline constexpr std::string_view kChannelWinder = "HOIST_WINDER";         ///< winder_t, into the twin
inline constexpr std::string_view kChannelCage = "HOIST_CAGE";             ///< cage_state_t, out
inline constexpr std::string_view kChannelGuideShape = "HOIST_GUIDE_SHAPE";  ///< guide_shape_t, out
inline constexpr std::string_view kChannelAlarm = "HOIST_ALARM";           ///< alarm_t, out
inline constexpr std::string_view kChannelAlarmAck = "HOIST_ALARM_ACK";    ///< alarm_ack_t, into the twin
inline constexpr std::string_view kChannelHealth = "HOIST_HEALTH";         ///< health_t, out
inline constexpr std::string_view kChannelForecast = "HOIST_FORECAST";     ///< forecast_t, out (look-ahead forecasts)
inline constexpr std::string_view kChannelTripPlan = "HOIST_TRIP_PLAN";    ///< trip_plan_t, into the twin (look-ahead forecasts)
inline constexpr std::string_view kChannelCageImu = "HOIST_CAGE_IMU";      ///< cage_imu_t, into the twin's estimator
inline constexpr std::string_view kChannelRopeLoad = "HOIST_ROPE_LOAD";    ///< rope_load_t, into the twin's estimator
inline constexpr std::string_view kChannelEstimate = "HOIST_ESTIMATE";     ///< estimate_t, out ([estimator] enabled)

/// prefix + name, e.g. channel("north/", kChannelCage) == "north/HOIST_CAGE".
inline std::string channel(std::string_view prefix, std::string_view name) {
  std::string s;
  s.reserve(prefix.size() + name.size());
  s.append(prefix);
  s.append(name);
  return s;
}

/// All channel names of one shaft with its prefix.
struct Channels {
  std::string winder, cage, shape, alarm, ack, health, forecast, trip_plan, cage_imu, rope_load, estimate;
  explicit Channels(std::string_view prefix = "")
      : winder(channel(prefix, kChannelWinder)),
        cage(channel(prefix, kChannelCage)),
        shape(channel(prefix, kChannelGuideShape)),
        alarm(channel(prefix, kChannelAlarm)),
        ack(channel(prefix, kChannelAlarmAck)),
        health(channel(prefix, kChannelHealth)),
        forecast(channel(prefix, kChannelForecast)),
        trip_plan(channel(prefix, kChannelTripPlan)),
        cage_imu(channel(prefix, kChannelCageImu)),
        rope_load(channel(prefix, kChannelRopeLoad)),
        estimate(channel(prefix, kChannelEstimate)) {}
};

}  // namespace hoist::bus
