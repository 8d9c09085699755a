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

/// Why `url` is not an LCM URL this project can use, or "" if it is (""
/// itself, LCM's default, is fine).  LCM's own check happens only when the
/// URL is opened and cannot tell a typo from a network problem; with this,
/// every program exits 2 (bad input) for a malformed URL and 1 only when a
/// well-formed one cannot be opened.  Accepted (LCM 1.3.1's providers):
///   udpm://GROUP[:PORT][?ttl=N&recv_buf_size=N&transmit_only=true|false]
///     GROUP an IPv4 multicast address (224.0.0.0 - 239.255.255.255)
///   tcpq://HOST[:PORT]   memq://   file://PATH[?mode=r|w|a&speed=X&start_timestamp=N]
inline std::string lcmUrlError(std::string_view url) {
  if (url.empty()) return {};
  const auto sep = url.find("://");
  if (sep == std::string_view::npos)
    return "'" + std::string(url) + "' is not an LCM URL (expected PROVIDER://NETWORK?OPTIONS, e.g. "
           "udpm://239.255.76.67:7667?ttl=0)";
  const std::string_view provider = url.substr(0, sep);
  std::string_view rest = url.substr(sep + 3), options;
  if (const auto q = rest.find('?'); q != std::string_view::npos) {
    options = rest.substr(q + 1);
    rest = rest.substr(0, q);
  }
  const auto number = [](std::string_view v, long lo, long hi) {
    if (v.empty() || v.size() > 9) return false;
    long n = 0;
    for (char c : v) {
      if (c < '0' || c > '9') return false;
      n = n * 10 + (c - '0');
    }
    return n >= lo && n <= hi;
  };
  const std::string u = "LCM URL '" + std::string(url) + "': ";
  if (provider == "udpm") {
    std::string_view host = rest, port;
    if (const auto c = rest.find(':'); c != std::string_view::npos) {
      host = rest.substr(0, c);
      port = rest.substr(c + 1);
      if (!number(port, 1, 65535)) return u + "port '" + std::string(port) + "' is not in 1..65535";
    }
    int octets[4] = {-1, -1, -1, -1}, k = 0;
    std::size_t i = 0;
    for (; k < 4; ++k) {
      const std::size_t j = host.find('.', i);
      const std::string_view part = host.substr(i, j == std::string_view::npos ? std::string_view::npos : j - i);
      if (!number(part, 0, 255)) break;
      octets[k] = static_cast<int>(std::stol(std::string(part)));
      if (j == std::string_view::npos) {
        ++k;
        break;
      }
      i = j + 1;
    }
    if (k != 4 || octets[3] < 0 || host.find_first_not_of("0123456789.") != std::string_view::npos)
      return u + "'" + std::string(host) + "' is not an IPv4 address";
    if (octets[0] < 224 || octets[0] > 239)
      return u + std::string(host) + " is not a multicast address (224.0.0.0 - 239.255.255.255)";
    while (!options.empty()) {
      const auto amp = options.find('&');
      const std::string_view kv = options.substr(0, amp);
      options = amp == std::string_view::npos ? std::string_view{} : options.substr(amp + 1);
      const auto eq = kv.find('=');
      const std::string_view key = kv.substr(0, eq), val = eq == std::string_view::npos ? "" : kv.substr(eq + 1);
      if (key == "ttl") {
        if (!number(val, 0, 255)) return u + "ttl '" + std::string(val) + "' is not in 0..255";
      } else if (key == "recv_buf_size") {
        if (!number(val, 1, 999999999)) return u + "recv_buf_size '" + std::string(val) + "' is not a positive size";
      } else if (key == "transmit_only") {
        if (val != "true" && val != "false") return u + "transmit_only must be true or false";
      } else {
        return u + "unknown option '" + std::string(key) + "' (udpm takes ttl, recv_buf_size, transmit_only)";
      }
    }
    return {};
  }
  if (provider == "memq") return rest.empty() ? std::string{} : u + "memq:// takes no address";
  if (provider == "tcpq" || provider == "file") return rest.empty() ? u + "no address or path" : std::string{};
  return u + "unknown provider '" + std::string(provider) + "' (udpm, tcpq, memq or file)";
}

/// Wall-clock time in microseconds since the Unix epoch (LCM's utime).
inline std::int64_t wallUtime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

}  // namespace hoist::bus
