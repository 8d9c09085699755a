// hoist-alarm-ack -- send one operator command to hoist-twind's alarms.
//
//   hoist-alarm-ack [--kind CAGE_POS_Y|...|*] [--level warning|critical|both]
//                   [--shelve SECONDS | --unshelve] [--user NAME]
//                   [--lcm-url URL] [--channel-prefix P]
//   hoist-alarm-ack --calibrate FA,B,SECONDS [--user NAME] ...
//   hoist-alarm-ack --adopt-preload S [--user NAME] ...
//
// --calibrate declares the load known for the load estimator's live
// calibration (alarm_ack_t ACTION_CALIBRATE: the empty conveyance at the
// bank with its own Fa and b, or a test weight) for SECONDS from now; the
// daemon logs it with the user (AUDIT line) and HOIST_ESTIMATE.calibrating
// shows it in force.
//
// --adopt-preload makes the live twin run both guide-rope preloads times S
// (alarm_ack_t ACTION_ADOPT_PRELOAD; S in [0.3, 1.6], 1 = back to the
// config's): the preload the shaft's memory identified (hoist-trips trend,
// GUIDE_PRELOAD_LOW's text).  The daemon builds the model off its loop,
// swaps it in when the cage rests, keeps it in its state file and logs both
// steps with the user; HOIST_HEALTH.preload_scale shows it in use.
//
// Default: acknowledge every active alarm ("*", both levels).  The daemon
// answers on HOIST_ALARM with an ACK / SHELVE / UNSHELVE event (watch it with
// hoist-monitor).  Exit status: 0 sent, 1 LCM failure, 2 bad usage (options, LCM URL,
// a shelve longer than the daemon's limit).
#include "hoist/cli/app.hpp"
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/contract/alarm_command.hpp"
#include "hoist/contract/alarm_vocabulary.hpp"

int main(int argc, char** argv) {
  CLI::App app{"hoist-alarm-ack: acknowledge, shelve or unshelve hoist-twind alarms (one HOIST_ALARM_ACK message)",
               "hoist-alarm-ack"};
  hoist::cli::nameProgram(app, "hoist-alarm-ack");  // usage, errors and --version name the program
  std::string kind = "*", level = "both", user, url, prefix;
  double shelve = 0.0;
  bool unshelve = false;
  // Every kind the daemon knows (hoist::contract::AlarmKind), so the list cannot
  // fall behind the engine.
  std::vector<std::string> kinds{"*"};
  std::string kind_list;
  for (int i = 0; i < hoist::contract::kAlarmKinds; ++i) {
    kinds.emplace_back(hoist::contract::toString(static_cast<hoist::contract::AlarmKind>(i)));
    kind_list += kinds.back() + ", ";
  }
  app.add_option("--kind", kind, "alarm kind: " + kind_list + "or * for all")
      ->capture_default_str()
      ->check(CLI::IsMember(kinds));
  app.add_option("--level", level, "warning, critical or both")
      ->capture_default_str()
      ->check(CLI::IsMember({"warning", "critical", "both"}));
  // The longest shelve the daemon grants ([alarms] max_shelve, default
  // 3600 s): refuse more here rather than have it clamped silently.
  const double max_shelve = hoist::contract::kDefaultMaxShelve;
  auto* sh = app.add_option("--shelve", shelve,
                            "shelve for this many seconds instead of acknowledging (at most " +
                                std::to_string(static_cast<long>(max_shelve)) + " s)")
                 ->check(CLI::PositiveNumber)
                 ->check(CLI::Validator(
                     [max_shelve](std::string& v) -> std::string {
                       double d = 0.0;
                       if (!CLI::detail::lexical_cast(v, d) || !(d <= max_shelve))
                         return "longer than the longest shelve, " + std::to_string(static_cast<long>(max_shelve)) +
                                " s (the daemon's [alarms] max_shelve)";
                       return {};
                     },
                     "SECONDS<=" + std::to_string(static_cast<long>(max_shelve)), "max shelve"));
  auto* un = app.add_flag("--unshelve", unshelve, "end a shelve early")->excludes(sh);
  std::string calibrate;
  double known_fa = 0.0, known_b = 0.0, known_s = 0.0;
  app.add_option("--calibrate", calibrate,
                 "FA,B,SECONDS: declare the load known -- eccentric force FA N (>= 0) at offset B m -- for SECONDS s "
                 "(at most " + std::to_string(static_cast<long>(hoist::contract::kMaxCalibration)) +
                     "): the load estimator's live calibration (docs/estimation.md)")
      ->excludes(sh)
      ->excludes(un)
      ->check(CLI::Validator(
          [&](std::string& v) -> std::string {
            hoist::contract::AlarmCommand c;
            double f[3] = {0.0, 0.0, 0.0};
            std::vector<std::string> parts;
            for (std::size_t at = 0;;) {
              const std::size_t comma = v.find(',', at);
              parts.push_back(v.substr(at, comma == std::string::npos ? std::string::npos : comma - at));
              if (comma == std::string::npos) break;
              at = comma + 1;
            }
            if (parts.size() != 3) return "expected FA,B,SECONDS (three numbers), got '" + v + "'";
            for (int i = 0; i < 3; ++i)
              if (!CLI::detail::lexical_cast(parts[static_cast<std::size_t>(i)], f[i]))
                return "expected FA,B,SECONDS (three numbers), got '" + v + "'";
            if (hoist::contract::validateAlarmCommand("", 0, hoist::alarm_ack_t::ACTION_CALIBRATE, 0.0, f[0], f[1],
                                                      f[2], c) != hoist::contract::CommandError::None)
              return "FA must be in [0, 1e7] N, |B| <= 100 m, SECONDS in (0, 600]; got '" + v + "'";
            known_fa = f[0];
            known_b = f[1];
            known_s = f[2];
            return {};
          },
          "FA,B,SECONDS", "calibration"));
  double adopt = 0.0;
  auto* ad = app.add_option("--adopt-preload", adopt,
                            "S: the live twin runs both guide-rope preloads times S, in [0.3, 1.6] (1 = the config's): "
                            "the preload the shaft's memory identified (docs/condition.md)")
                 ->excludes(sh)
                 ->excludes(un)
                 ->excludes("--calibrate")
                 ->check(CLI::Range(hoist::contract::kMinPreloadScale, hoist::contract::kMaxPreloadScale));
  app.add_option("--user", user, "operator name (logged by the daemon; default: $USER)");
  app.add_option("--lcm-url", url, "LCM URL; default: $LCM_DEFAULT_URL, else LCM's default");
  app.add_option("--channel-prefix", prefix, "prefix of the daemon's channels");
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  if (user.empty()) {
    const char* u = std::getenv("USER");
    user = u ? u : "operator";
  }
  hoist::alarm_ack_t m{};
  m.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                std::chrono::system_clock::now().time_since_epoch())
                .count();
  m.kind = kind;
  m.level = level == "warning" ? 1 : level == "critical" ? 2 : 0;
  m.action = unshelve ? hoist::alarm_ack_t::ACTION_UNSHELVE
                      : (shelve > 0 ? hoist::alarm_ack_t::ACTION_SHELVE : hoist::alarm_ack_t::ACTION_ACK);
  m.shelve_duration = shelve;
  const bool cal = !calibrate.empty();
  if (cal) {
    m.kind = "";
    m.level = 0;
    m.action = hoist::alarm_ack_t::ACTION_CALIBRATE;
    m.known_fa = known_fa;
    m.known_b = known_b;
    m.calibrate_duration = known_s;
  }
  const bool adopting = ad->count() > 0;
  if (adopting) {
    m.kind = "";
    m.level = 0;
    m.action = hoist::alarm_ack_t::ACTION_ADOPT_PRELOAD;
    m.preload_scale = adopt;
  }
  m.user = user;
  if (const std::string bad = hoist::bus::lcmUrlUsageError("hoist-alarm-ack", app.count("--lcm-url") > 0, url,
                                                            hoist::bus::resolveLcmUrl(url));
      !bad.empty()) {
    std::cerr << bad << "\n";
    return 2;
  }
  url = hoist::bus::resolveLcmUrl(url);
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << "hoist-alarm-ack: cannot open LCM (" << (url.empty() ? "default URL" : url)
              << "); is loopback multicast enabled? (scripts/setup.sh)\n";
    return 1;
  }
  const std::string channel = hoist::bus::channel(prefix, hoist::bus::kChannelAlarmAck);
  if (lcm.publish(channel, &m) != 0) {
    std::cerr << "hoist-alarm-ack: publish on " << channel << " failed\n";
    return 1;
  }
  if (adopting) {
    std::cout << "sent ADOPT_PRELOAD x" << adopt << " user=" << user << " on " << channel
              << " (in use when the cage rests: HOIST_HEALTH.preload_scale)\n";
    return 0;
  }
  if (cal) {
    std::cout << "sent CALIBRATE Fa=" << known_fa << " N b=" << known_b << " m for " << known_s << " s user=" << user
              << " on " << channel << "\n";
    return 0;
  }
  std::cout << "sent " << (unshelve ? "UNSHELVE" : shelve > 0 ? "SHELVE" : "ACK") << " kind=" << kind
            << " level=" << level << (shelve > 0 ? " for " + std::to_string(shelve) + " s" : "") << " user=" << user
            << " on " << channel << "\n";
  return 0;
}
