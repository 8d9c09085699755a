// hoist-mqtt built without nanopb: no Sparkplug B payloads (hoist/mqtt/sparkplug.hpp).
#include <stdexcept>

#include "hoist/mqtt/sparkplug.hpp"
#include "hoist/mqtt/sparkplug_node.hpp"

namespace hoist::mqtt::sparkplug {

namespace {
[[noreturn]] void missing() {
  throw std::runtime_error("this hoist-mqtt was built without nanopb: no Sparkplug B mode (apt-get install nanopb "
                           "libnanopb-dev, then rebuild)");
}
}  // namespace

bool available() { return false; }
std::string encode(const Payload&) { missing(); }
std::optional<Payload> decode(const void*, std::size_t, std::size_t, std::string& why) {
  why = "no Sparkplug support in this build";
  return std::nullopt;
}
std::string stamp(std::string_view payload, std::uint8_t, bool) { return std::string(payload); }

}  // namespace hoist::mqtt::sparkplug
