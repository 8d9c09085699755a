// hoist/bus/lcm_url.hpp -- the one LCM URL check of every program of the
// project (hoist-twind, hoist-dash, hoist-mqtt, hoist-replay,
// hoist-timing-test, hoist-monitor, hoist-alarm-ack).  Header-only, part of
// hoist_lcm (msgs/CMakeLists.txt); needs nothing but the standard library.
//
// A malformed URL is bad input: every program exits 2 naming itself, where
// the URL came from and what is wrong ("hoist-dash: --lcm-url: LCM URL
// 'udpm://239.255.76.67:7667?ttl=abc': ttl 'abc' is not in 0..255"), before
// LCM sees it (LCM 1.3.1 warns and goes on, or fails later with an errno
// text that cannot tell a typo from a network problem).  Exit 1 is left for
// a well-formed URL that cannot be opened.
#pragma once

#include <cstdlib>
#include <string>
#include <string_view>

namespace hoist::bus {

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

/// The message (exit status 2) for the LCM URL `program` is about to use,
/// or "" if it is usable.  `option_given`: the command line had `option`
/// (then an empty value is refused, since it would silently mean LCM's
/// default); `cli`: its value; `resolved`: the URL after resolveLcmUrl
/// (the option, else $LCM_DEFAULT_URL, else the configuration's lcm_url).
/// The message starts "PROGRAM: SOURCE: " where SOURCE is the option, the
/// environment variable or "the configuration's lcm_url".
inline std::string lcmUrlUsageError(std::string_view program, bool option_given, std::string_view cli,
                                    std::string_view resolved, std::string_view option = "--lcm-url") {
  const std::string who = std::string(program) + ": ";
  if (option_given && cli.empty())
    return who + std::string(option) + ": empty LCM URL (omit the option for the default, or give e.g. "
                                       "udpm://239.255.76.67:7667?ttl=0)";
  const std::string bad = lcmUrlError(resolved);
  if (bad.empty()) return {};
  const char* env = std::getenv("LCM_DEFAULT_URL");
  const std::string from = option_given                               ? std::string(option)
                           : (env && *env && resolved == env)         ? std::string("LCM_DEFAULT_URL")
                                                                      : std::string("the configuration's lcm_url");
  return who + from + ": " + bad;
}

}  // namespace hoist::bus
