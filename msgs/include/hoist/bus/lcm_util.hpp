// hoist/bus/lcm_util.hpp -- small helpers shared by every LCM program of
// the project (hoist-twind, hoist-replay, hoist-monitor, hoist-alarm-ack,
// tests).  Part of the hoist_lcm target (msgs/CMakeLists.txt).
// Namespace hoist::bus, not hoist::lcm: inside namespace hoist a
// hoist::lcm would hide LCM's own ::lcm (lcm::LCM, lcm::ReceiveBuffer).
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "hoist/bus/lcm_url.hpp"  // lcmUrlError, lcmUrlUsageError: the shared URL check

namespace hoist::bus {

/// The LCM URL to use, by precedence: --lcm-url (cli), the LCM_DEFAULT_URL
/// environment variable, the config file's [service].lcm_url, LCM's default
/// (returned as "", which makes LCM use its built-in default).
inline std::string resolveLcmUrl(const std::string& cli, const std::string& config = "") {
  if (!cli.empty()) return cli;
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return env;
  return config;
}

/// `name` as a regular expression that matches exactly that channel name:
/// lcm::LCM::subscribe() takes a regular expression (GLib's, anchored), so
/// a channel prefix "mine.1/" would also match "mineX1/".  Every program
/// that subscribes to a name built from a prefix goes through this.
inline std::string regexEscape(const std::string& name) {
  std::string o;
  o.reserve(name.size() * 2);
  for (char c : name) {
    if (c != '\0' && std::string_view("\\^$.|?*+()[]{}-/").find(c) != std::string_view::npos) o.push_back('\\');
    o.push_back(c);
  }
  return o;
}

/// For messages: "LCM default" when url is empty.
inline std::string describeLcmUrl(const std::string& url) {
  return url.empty() ? std::string("LCM default (udpm://239.255.76.67:7667?ttl=0)") : url;
}

/// Wall-clock time in microseconds since the Unix epoch (LCM's utime).
inline std::int64_t wallUtime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

}  // namespace hoist::bus
