// hoist-monitor -- a readable console view of a running hoist-twind.
//
//   hoist-monitor [--lcm-url URL] [--channel-prefix P] [--period S] [--duration S]
//
// Subscribes to HOIST_CAGE, HOIST_ALARM and HOIST_HEALTH and prints, once per
// period (default 1 s of wall time), one line with the latest cage state:
// model time, depth of the cage top (rope length l), speed, sway (y_c), tilt
// (theta), the largest guide-sleeve force max|lambda_1..4|, the minimum
// remaining clearance and the active alarms.  Alarm events are printed as
// they arrive.  Stops on SIGINT/SIGTERM or after --duration.
#include <CLI/CLI.hpp>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <string>

#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/bus/channels.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }

class Monitor {
 public:
  void onCage(const lcm::ReceiveBuffer*, const std::string&, const hoist::cage_state_t* m) {
    cage_ = *m;
    have_cage_ = true;
    ++cages_;
  }
  void onAlarm(const lcm::ReceiveBuffer*, const std::string&, const hoist::alarm_t* m) {
    static const char* lv[] = {"", "WARNING", "CRITICAL"};
    const std::string key = m->kind + "/" + ((m->level >= 0 && m->level <= 2) ? lv[m->level] : "?");
    if (m->active && !m->shelved) active_[key] = true;
    else active_.erase(key);
    if (m->event_type != hoist::alarm_t::EVENT_REANNOUNCE) {
      std::printf("  >> [t=%7.2f s] %s\n", m->t, m->message.c_str());
      std::fflush(stdout);
    }
  }
  void onHealth(const lcm::ReceiveBuffer*, const std::string&, const hoist::health_t* m) {
    health_ = *m;
    have_health_ = true;
  }

  void printLine() {
    if (lines_ % 20 == 0)
      std::printf("%9s %9s %9s %10s %11s %10s %11s  %s\n", "time[s]", "depth[m]", "v[m/s]",
                  "sway[mm]", "tilt[mrad]", "Fmax[N]", "clear[mm]", "alarms");
    ++lines_;
    if (!have_cage_) {
      std::printf("%9s  waiting for %s ...%s\n", "-", cage_channel_.c_str(),
                  have_health_ ? " (daemon is up, no model output yet)" : "");
      std::fflush(stdout);
      return;
    }
    double fmax = 0.0;
    for (int i = 1; i < 5; ++i) fmax = std::max(fmax, std::fabs(cage_.lambdas[i]));
    std::string alarms;
    for (const auto& [k, on] : active_) alarms += (alarms.empty() ? "" : " ") + k;
    if (alarms.empty()) alarms = "none";
    if (cage_.degraded) alarms += "  (DEGRADED)";
    if (have_health_ && health_.rejected_total > 0)
      alarms += "  [rejected inputs: " + std::to_string(health_.rejected_total) + "]";
    std::printf("%9.2f %9.2f %9.2f %+10.3f %+11.4f %10.1f %11.1f  %s\n", cage_.t, cage_.l, cage_.v,
                cage_.y_c * 1e3, cage_.theta * 1e3, fmax, cage_.min_clearance * 1e3, alarms.c_str());
    std::fflush(stdout);
  }

  std::string cage_channel_;
  long cages_ = 0;

 private:
  hoist::cage_state_t cage_{};
  hoist::health_t health_{};
  bool have_cage_ = false, have_health_ = false;
  std::map<std::string, bool> active_;
  long lines_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "hoist-monitor: print the digital twin's cage state once a second (time, depth, speed,\n"
      "sway, tilt, largest sleeve force, minimum clearance, active alarms) and every alarm event."};
  std::string url, prefix;
  double period = 1.0, duration = 0.0;
  app.add_option("--lcm-url", url, "LCM URL; default: $LCM_DEFAULT_URL, else LCM's default");
  app.add_option("--channel-prefix", prefix, "channel name prefix (as hoist-twind's)");
  app.add_option("--period", period, "seconds between lines (default 1)")->check(CLI::PositiveNumber);
  app.add_option("--duration", duration, "stop after this many seconds (default: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  url = hoist::bus::resolveLcmUrl(url);
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "hoist-monitor: cannot open LCM at %s\n", hoist::bus::describeLcmUrl(url).c_str());
    return 1;
  }
  Monitor mon;
  const hoist::bus::Channels ch(prefix);
  mon.cage_channel_ = ch.cage;
  lcm.subscribe(ch.cage, &Monitor::onCage, &mon);
  lcm.subscribe(ch.alarm, &Monitor::onAlarm, &mon);
  lcm.subscribe(ch.health, &Monitor::onHealth, &mon);
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto next = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period));
  const int fd = lcm.getFileno();
  while (!g_stop) {
    const auto now = Clock::now();
    if (duration > 0.0 && now - start >= std::chrono::duration<double>(duration)) break;
    if (now >= next) {
      mon.printLine();
      next += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period));
      if (next < now) next = now;
      continue;
    }
    const int wait_ms = static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(next - now).count()) + 1;
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, std::min(wait_ms, 200));
    if (r > 0) lcm.handle();
  }
  return 0;
}
