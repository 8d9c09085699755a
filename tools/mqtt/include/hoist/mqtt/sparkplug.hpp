// hoist/mqtt/sparkplug.hpp -- the Sparkplug B payload on the wire (protobuf,
// encoded and decoded with nanopb; tools/mqtt/proto/sparkplug_b.proto).
// Built only with nanopb (HOIST_MQTT_SPARKPLUG); without it hoist-mqtt has
// no Sparkplug mode.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "hoist/mqtt/sparkplug_metrics.hpp"

namespace hoist::mqtt::sparkplug {

/// The payload's protobuf encoding.  Throws std::length_error if it does not
/// fit the static sizes (sparkplug_b.options: 200 metrics, names of 63 bytes).
std::string encode(const Payload& p);

/// Decodes at most `max_bytes` (larger: nullopt, why = "oversized ...").
/// Malformed protobuf, or more metrics or longer strings than the static
/// sizes: nullopt with why.  Nothing is allocated before the size check.
std::optional<Payload> decode(const void* data, std::size_t size, std::size_t max_bytes, std::string& why);

/// `payload` (an encoded Payload) with its seq set to `seq` and, if
/// `historical`, every metric's is_historical set: used when a message is
/// actually sent (live, or replayed after an outage).  A payload that does
/// not decode is returned unchanged.
std::string stamp(std::string_view payload, std::uint8_t seq, bool historical);

}  // namespace hoist::mqtt::sparkplug
