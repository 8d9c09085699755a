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
//
// Look-ahead: when the daemon publishes HOIST_FORECAST, each line
// is followed by one "forecast" line for the shaft: the time the latest
// forecast starts from and, per scenario, its worst (smallest) clearance and
// when, and the time to violation -- seconds until the first CRITICAL and
// WARNING threshold crossing ("none" within the horizon) -- and the
// smallest hoisting-rope force; a scenario stopped early says why (--no-forecast:
// no such line; scripts/demo.sh, as the README's sample).  Run one
// monitor per shaft (--channel-prefix).
//
// Load estimate: when the daemon publishes HOIST_ESTIMATE ([estimator]
// enabled), each line is followed by one "estimate" line with the latest
// estimate: the payload Fa and its offset b with their standard deviations
// ("n/a" when not observed: sigma < 0), the estimated tilt theta next to the
// open-loop twin's, the sliding window's NIS per degree of freedom against
// its MODEL_MISMATCH bound, the sensors in use, and [MISMATCH] (with its
// cause) while the model check fails, e.g.
//   estimate: Fa 1502+-3 N b 0.60+-0.01 m theta 6.5e-4 (open 8.3e-4) NIS 1.02/dof (bound 1.24) sensors imu+rope [MISMATCH: NIS]
// The line says STALE like the cage line when HOIST_ESTIMATE stops.
//
// Hostile input: every payload passes hoist::msg::checkedDecode
// before it is decoded (undecodable ones are counted and shown), no exception
// leaves an LCM callback, every string from the network is printed through
// hoist::msg::terminalSafe (no control characters or escape sequences reach
// the terminal), at most 64 active alarms are tracked, and when no HOIST_CAGE
// or no HOIST_HEALTH arrived for more than --stale seconds (default 2) the
// line says STALE with the age of the data (the forecast line likewise, after
// max(--stale, 3) seconds: forecasts come at about 1 Hz).  Scenario names
// are network strings too (terminalSafe, at most 24 bytes shown), and at
// most forecast_t.MAX_SCENARIOS scenarios are shown (the checked decoder
// rejects more).
#include "hoist/cli/app.hpp"
#include "hoist/version.hpp"
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <string>

#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/bus/subscriber.hpp"
#include "hoist/msg/codec.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }

using Clock = std::chrono::steady_clock;

class Monitor {
 public:
  static constexpr std::size_t kMaxActive = 64;

  void onCage(const lcm::ReceiveBuffer* rb, const std::string&) {
    guarded([&] {
      hoist::cage_state_t m;
      if (!decode(rb, m)) return;
      cage_ = m;
      have_cage_ = true;
      last_cage_ = Clock::now();
      ++cages_;
    });
  }
  void onAlarm(const lcm::ReceiveBuffer* rb, const std::string&) {
    guarded([&] {
      hoist::alarm_t m;
      if (!decode(rb, m)) return;
      const std::string key = hoist::msg::terminalSafe(m.kind, 40) + "/" +
                              std::string(hoist::msg::enums::alarm_t::levelName(m.level));
      if (m.active && !m.shelved) {
        if (active_.size() < kMaxActive || active_.count(key)) active_[key] = true;
        else ++active_overflow_;
      } else {
        active_.erase(key);
      }
      if (m.event_type != hoist::alarm_t::EVENT_REANNOUNCE) {
        std::printf("  >> [t=%7.2f s] %s\n", m.t, hoist::msg::terminalSafe(m.message).c_str());
        std::fflush(stdout);
      }
    });
  }
  void onForecast(const lcm::ReceiveBuffer* rb, const std::string&) {
    guarded([&] {
      hoist::forecast_t m;
      if (!decode(rb, m)) return;
      forecast_ = std::move(m);
      have_forecast_ = true;
      last_forecast_ = Clock::now();
    });
  }
  void onEstimate(const lcm::ReceiveBuffer* rb, const std::string&) {
    guarded([&] {
      hoist::estimate_t m;
      if (!decode(rb, m)) return;
      estimate_ = m;
      have_estimate_ = true;
      last_estimate_ = Clock::now();
    });
  }
  void onHealth(const lcm::ReceiveBuffer* rb, const std::string&) {
    guarded([&] {
      hoist::health_t m;
      if (!decode(rb, m)) return;
      health_ = std::move(m);
      have_health_ = true;
      last_health_ = Clock::now();
    });
  }

  /// " STALE: no HOIST_CAGE for 3.2 s, no HOIST_HEALTH for 3.1 s" or "".
  std::string staleness(Clock::time_point now) const {
    std::string out;
    auto add = [&](bool have, Clock::time_point last, const char* what) {
      const double age = std::chrono::duration<double>(now - (have ? last : start_)).count();
      if (age <= stale_s_) return;
      char b[96];
      std::snprintf(b, sizeof b, "%s no %s for %.1f s", out.empty() ? "" : ",", what, age);
      out += b;
    };
    add(have_cage_, last_cage_, "HOIST_CAGE");
    add(have_health_, last_health_, "HOIST_HEALTH");
    return out.empty() ? out : "  ** STALE:" + out + " **";
  }

  void printLine() {
    const std::string stale = staleness(Clock::now());
    std::string bad;
    if (undecodable_ > 0) bad = "  [undecodable messages: " + std::to_string(undecodable_) + "]";
    if (lines_ % 20 == 0)
      std::printf("%9s %9s %9s %10s %11s %10s %11s  %s\n", "time[s]", "depth[m]", "v[m/s]",
                  "sway[mm]", "tilt[mrad]", "Fmax[N]", "clear[mm]", "alarms");
    ++lines_;
    if (!have_cage_) {
      std::printf("%9s  waiting for %s ...%s%s%s\n", "-", hoist::msg::terminalSafe(cage_channel_).c_str(),
                  have_health_ ? " (daemon is up, no model output yet)" : "", stale.c_str(), bad.c_str());
      std::fflush(stdout);
      return;
    }
    double fmax = 0.0;
    for (int i = 1; i < 5; ++i) fmax = std::max(fmax, std::fabs(cage_.lambdas[i]));
    std::string alarms;
    for (const auto& [k, on] : active_) alarms += (alarms.empty() ? "" : " ") + k;
    if (alarms.empty()) alarms = "none";
    if (active_overflow_ > 0) alarms += " (+more)";
    if (cage_.degraded) alarms += "  (DEGRADED)";
    if (have_health_ && health_.rejected_total > 0)
      alarms += "  [rejected inputs: " + std::to_string(health_.rejected_total) + "]";
    std::printf("%9.2f %9.2f %9.2f %+10.3f %+11.4f %10.1f %11.1f  %s%s%s\n", cage_.t, cage_.l, cage_.v,
                cage_.y_c * 1e3, cage_.theta * 1e3, fmax, cage_.min_clearance * 1e3, alarms.c_str(),
                stale.c_str(), bad.c_str());
    if (have_forecast_ && show_forecast_) std::printf("%s\n", forecastLine(Clock::now()).c_str());
    if (have_estimate_) std::printf("%s\n", estimateLine(Clock::now()).c_str());
    std::fflush(stdout);
  }

  /// "  estimate: Fa 1502+-3 N b 0.60+-0.01 m theta 6.5e-4 (open 8.3e-4)
  /// NIS 1.02/dof (bound 1.24) sensors imu+rope [MISMATCH: NIS]"
  std::string estimateLine(Clock::time_point now) const {
    const auto& e = estimate_;
    char b[160];
    auto withSigma = [&](const char* name, double v, double sigma, const char* fmt_v, const char* unit) {
      std::string out = std::string(" ") + name + " ";
      if (!(sigma >= 0.0) || !std::isfinite(v)) return out + "n/a";  // not observed (or NaN: nothing to show)
      std::snprintf(b, sizeof b, fmt_v, v, sigma);
      return out + b + " " + unit;
    };
    std::string out = "  estimate:";
    out += withSigma("Fa", e.Fa, e.sigma_Fa, "%.0f+-%.0f", "N");
    out += withSigma("b", e.b, e.sigma_b, "%.2f+-%.2f", "m");
    if (e.sigma_theta >= 0.0) std::snprintf(b, sizeof b, " theta %.1e (open %.1e)", e.theta, e.theta_open);
    else std::snprintf(b, sizeof b, " theta n/a (open %.1e)", e.theta_open);
    out += b;
    if (e.nis_dof > 0) {
      std::snprintf(b, sizeof b, " NIS %.2f/dof (bound %.2f)", e.nis_window / e.nis_dof, e.nis_bound / e.nis_dof);
      out += b;
    } else {
      out += " NIS n/a";
    }
    std::string sensors;
    const int imu = int{hoist::estimate_t::SENSOR_IMU_ACCEL} | int{hoist::estimate_t::SENSOR_IMU_RATE};
    if (e.sensors & imu) sensors = "imu";
    if (e.sensors & int{hoist::estimate_t::SENSOR_ROPE_LOAD}) sensors += sensors.empty() ? "rope" : "+rope";
    out += " sensors " + (sensors.empty() ? std::string("none (open loop)") : sensors);
    if (e.mismatch) {
      out += " [MISMATCH";
      if (e.nis_exceeded) out += e.drift_exceeded ? ": NIS, drift" : ": NIS";
      else if (e.drift_exceeded) out += ": drift";
      else out += ": the trip's preload fit";  // the trip-end preload test (docs/estimation.md)
      out += "]";
    }
    const double age = std::chrono::duration<double>(now - last_estimate_).count();
    if (age > stale_s_) {
      std::snprintf(b, sizeof b, "  ** STALE: no HOIST_ESTIMATE for %.1f s **", age);
      out += b;
    }
    return out;
  }

  /// "  forecast from t=20.00 s: estop: worst 31.0 mm at +4.25 s, CRITICAL
  /// none, WARNING in 3.50 s, F0 min 2.41 kN | continue: ..."
  std::string forecastLine(Clock::time_point now) const {
    auto secs = [](double t) -> std::string {
      if (!(t >= 0.0)) return "none";  // -1 (or NaN): not within the horizon
      char b[32];
      std::snprintf(b, sizeof b, "in %.2f s", t);
      return b;
    };
    char b[256];
    std::snprintf(b, sizeof b, "  forecast from t=%.2f s:", forecast_.t_start);
    std::string out = b;
    if (forecast_.scenarios.empty()) out += " (no scenarios)";
    for (std::size_t i = 0; i < forecast_.scenarios.size(); ++i) {
      const auto& sc = forecast_.scenarios[i];
      std::snprintf(b, sizeof b, "%s %s: worst %.1f mm at +%.2f s, CRITICAL %s, WARNING %s, F0 min %.2f kN",
                    i == 0 ? "" : " |", hoist::msg::terminalSafe(sc.name, 24).c_str(), sc.min_clearance * 1e3,
                    sc.t_min_clearance, secs(sc.t_critical).c_str(), secs(sc.t_warning).c_str(),
                    sc.lambda0_min * 1e-3);
      out += b;
      if (sc.status != hoist::forecast_scenario_t::STATUS_OK) {
        const char* why = sc.status == hoist::forecast_scenario_t::STATUS_LEFT_SHAFT ? "left the shaft"
                          : sc.status == hoist::forecast_scenario_t::STATUS_NON_FINITE ? "non-finite state"
                                                                                       : "unknown status";
        std::snprintf(b, sizeof b, " [stopped at +%.2f s: %s]", sc.t_reached, why);
        out += b;
      }
    }
    const double age = std::chrono::duration<double>(now - last_forecast_).count();
    if (age > std::max(stale_s_, 3.0)) {
      std::snprintf(b, sizeof b, "  ** STALE: no HOIST_FORECAST for %.1f s **", age);
      out += b;
    }
    return out;
  }

  std::string cage_channel_;
  long cages_ = 0;
  double stale_s_ = 2.0;
  bool show_forecast_ = true;  // --no-forecast: false
  Clock::time_point start_ = Clock::now();

 private:
  template <class M>
  bool decode(const lcm::ReceiveBuffer* rb, M& m) {
    if (hoist::msg::checkedDecode(rb->data, rb->data_size, m) == hoist::msg::DecodeStatus::ok) return true;
    ++undecodable_;
    return false;
  }
  /// No exception leaves an LCM callback: a failure drops the message.
  template <class F>
  void guarded(F&& f) {
    try {
      f();
    } catch (...) {
      ++undecodable_;
    }
  }
  Clock::time_point last_cage_{}, last_health_{};
  long undecodable_ = 0;
  std::size_t active_overflow_ = 0;
  hoist::cage_state_t cage_{};
  hoist::health_t health_{};
  hoist::forecast_t forecast_{};
  Clock::time_point last_forecast_{};
  hoist::estimate_t estimate_{};
  Clock::time_point last_estimate_{};
  bool have_cage_ = false, have_health_ = false, have_forecast_ = false, have_estimate_ = false;
  std::map<std::string, bool> active_;
  long lines_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "hoist-monitor: print the digital twin's cage state once a second (time, depth, speed,\n"
      "sway, tilt, largest sleeve force, minimum clearance, active alarms) and every alarm event;\n"
      "with HOIST_FORECAST, per scenario the worst forecast clearance and the time to violation\n"
      "(seconds to the first CRITICAL / WARNING crossing); with HOIST_ESTIMATE, the estimated\n"
      "load (Fa, b with their sigmas), theta estimated and open loop, the NIS and MODEL_MISMATCH."};
  hoist::cli::nameProgram(app, "hoist-monitor");
  std::string url, prefix;
  double period = 1.0, duration = 0.0;
  app.add_option("--lcm-url", url, "LCM URL; default: $LCM_DEFAULT_URL, else LCM's default");
  app.add_option("--channel-prefix", prefix, "channel name prefix (as hoist-twind's)");
  app.add_option("--period", period, "seconds between lines (default 1)")->check(CLI::PositiveNumber);
  app.add_option("--duration", duration, "stop after this many seconds (default: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  double stale = 2.0;
  app.add_option("--stale", stale, "flag the data STALE after this many seconds without HOIST_CAGE/HEALTH (default 2)")
      ->check(CLI::PositiveNumber);
  bool no_forecast = false;
  app.add_flag("--no-forecast", no_forecast,
               "no forecast line under each line (the look-ahead's scenarios; scripts/demo.sh shows none)");
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  if (const std::string bad = hoist::bus::lcmUrlUsageError("hoist-monitor", app.count("--lcm-url") > 0, url,
                                                            hoist::bus::resolveLcmUrl(url));
      !bad.empty()) {
    std::fprintf(stderr, "%s\n", bad.c_str());
    return 2;
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
  mon.stale_s_ = stale;
  mon.show_forecast_ = !no_forecast;
  // The receive path for the URL (our own for udpm://, LCM's otherwise,
  // exact names either way: hoist/bus/subscriber.hpp).
  hoist::bus::Subscriber rx(lcm);
  std::string rx_why;
  if (!rx.open(url, rx_why)) {
    std::fprintf(stderr, "hoist-monitor: %s\n", rx_why.c_str());
    return 1;
  }
  rx.add(ch.cage, [&mon](const lcm::ReceiveBuffer* rb, const std::string& c) { mon.onCage(rb, c); });
  rx.add(ch.alarm, [&mon](const lcm::ReceiveBuffer* rb, const std::string& c) { mon.onAlarm(rb, c); });
  rx.add(ch.health, [&mon](const lcm::ReceiveBuffer* rb, const std::string& c) { mon.onHealth(rb, c); });
  rx.add(ch.forecast, [&mon](const lcm::ReceiveBuffer* rb, const std::string& c) { mon.onForecast(rb, c); });
  rx.add(ch.estimate, [&mon](const lcm::ReceiveBuffer* rb, const std::string& c) { mon.onEstimate(rb, c); });
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  const auto start = Clock::now();
  auto next = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period));
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
    rx.poll(std::min(wait_ms, 200), 256);
  }
  return 0;
}
