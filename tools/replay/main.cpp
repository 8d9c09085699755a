// hoist-replay -- publishes the winder input HOIST_WINDER (winder_t) for
// hoist-twind, in real time or faster.
//
//   hoist-replay [--profile FILE|SPEC | --lcm-log FILE] [--speed X] [--rate HZ]
//                [--lcm-url URL] [--with-length] [--channel-prefix P]
//
// Sources:
//   * a synthetic profile SPEC (hoist_io): `paper` (the default: the paper's
//     Fig. 2 trapezoid, 50 m -> 300 m in 60 s), `trapezoid:...`, `scurve:...`,
//     `estop:...`; or a profile CSV (t, v, a [, l]; INTERFACES.md).  Sampled
//     at --rate (default 100 Hz) at t_k = t0 + k / rate, k = 0 .. round((t_end -
//     t0) * rate), exactly the times hoist-sim --dt 1/rate steps to;
//   * an LCM log (lcm-logger): every event whose channel ends in HOIST_WINDER
//     is re-published with its recorded timing, payload unchanged (so
//     `hoist-twind --clock input` reproduces the recorded run), unless
//     --restamp rewrites utime to the replay's wall clock.
// Message k carries seq = k and utime = (wall time at start, us) + round((t_k -
// t0) * 1e6): utime follows PROFILE time whatever the speed, so that
// `hoist-twind --clock input` steps the model exactly by the profile's dt.
// --speed X publishes X times faster than real time (0 = as fast as possible;
// over UDP a too fast stream may overrun the receiver's socket buffer, which
// the daemon counts as sequence gaps).  Sleeps follow an absolute schedule
// (clock_nanosleep TIMER_ABSTIME), so timing errors do not accumulate.
// Progress is shown on a terminal only.  Ctrl-C stops cleanly (status 130).
//
// --timing-test: a soft-real-time check of a running hoist-twind (a deployment
// machine): feeds it at --rate for --duration, listens to its HOIST_HEALTH and
// HOIST_CAGE, and judges deadline misses, tick lateness, step time, end-to-end
// latency and rejected inputs against budgets (timing_test.hpp).
#include <CLI/CLI.hpp>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "hoist/io/profile.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/winder_t.hpp"
#include "hoist/io/config.hpp"
#include "timing_test.hpp"

namespace {

volatile std::sig_atomic_t g_signal = 0;
void onSignal(int sig) { g_signal = sig; }

/// Sleep until the absolute CLOCK_MONOTONIC time `deadline_ns`; false if a
/// signal asked us to stop.
bool sleepUntil(std::int64_t deadline_ns) {
  timespec ts{static_cast<time_t>(deadline_ns / 1000000000), static_cast<long>(deadline_ns % 1000000000)};
  while (!g_signal) {
    const int r = clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    if (r == 0) return true;
    if (r != EINTR) return true;
  }
  return false;
}

std::int64_t monotonicNs() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

class Progress {
 public:
  explicit Progress(bool on) : on_(on) {}
  void update(double t, double t0, double t1, long sent) {
    if (!on_) return;
    const std::int64_t now = monotonicNs();
    if (now - last_ < 200000000) return;
    last_ = now;
    const double f = t1 > t0 ? (t - t0) / (t1 - t0) : 1.0;
    std::fprintf(stderr, "\rhoist-replay: t = %8.2f / %.2f s  %5.1f %%  %ld messages ", t, t1, 100.0 * f, sent);
    std::fflush(stderr);
  }
  void done() {
    if (on_) std::fputc('\n', stderr);
  }

 private:
  bool on_;
  std::int64_t last_ = 0;
};

/// The command line as typed (arguments quoted for a shell where needed).
std::string commandLine(int argc, char** argv) {
  std::string out;
  for (int i = 0; i < argc; ++i) {
    std::string a = argv[i];
    if (i == 0) {
      const auto slash = a.rfind('/');
      if (slash != std::string::npos) a = a.substr(slash + 1);
    }
    const bool plain = !a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                         "0123456789-_./:=,+@%") == std::string::npos;
    if (!out.empty()) out += ' ';
    if (plain) {
      out += a;
    } else {
      out += '\'';
      for (char c : a) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
      out += '\'';
    }
  }
  return out;
}

/// A number check whose message reads well: "--opt: must be >= 0 (got -1)".
CLI::Validator numberIn(double lo, double hi, bool lo_open, const std::string& what) {
  return CLI::Validator(
      [=](std::string& in) -> std::string {
        double x = 0.0;
        std::size_t used = 0;
        try {
          x = std::stod(in, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != in.size() || in.empty() || !std::isfinite(x)) return "not a number: '" + in + "'";
        if ((lo_open ? !(x > lo) : !(x >= lo)) || !(x <= hi)) return "must be " + what + " (got " + in + ")";
        return std::string();
      },
      "NUMBER");
}

const char* kTimingHelp = R"(
Timing test (--timing-test): how a user checks a deployment machine.
  hoist-twind --rate 1000 & hoist-replay --timing-test --rate 1000 --duration 600 --max-late-p99-us 200 --report timing.md
Feeds the RUNNING hoist-twind at --rate Hz (1..1000, default 100) for --duration s (default 60) with
the paper's trapezoid trip down and back up again, repeated, with the encoder length (the cage moves
the whole time; seq contiguous from 0, utime = wall clock), and listens to its HOIST_HEALTH and
HOIST_CAGE on the same --lcm-url and channel prefix.  Measured: deadline misses, tick lateness p99
(worst window) and max, model step time p99/max (from HOIST_HEALTH, as deltas over the test),
rejected and lost inputs, model faults, degraded outputs; the end-to-end latency input -> first
HOIST_CAGE answering it (input_seq) p50/p99/p99.9/max; the feeder's own lateness.  Budgets:
--max-misses (default 0), --max-rejected (default 0), --max-late-p99-us, --max-late-max-us,
--max-step-p99-us, --max-e2e-p99-us (unchecked unless given).  Several shafts: repeat
--channel-prefix, or --shafts N for shaft1/ .. shaftN/ (one input per shaft per period; misses and
counts summed, latencies worst case).  Prints a Markdown summary (--report FILE writes it too; its
first line is VERDICT: PASS|FAIL|INCONCLUSIVE); progress once a second on a terminal (not with -q).
Exit status: 0 PASS; 1 FAIL, or INCONCLUSIVE when the feeder itself was late (p99 over one period),
or no HOIST_HEALTH within 5 s; 2 bad options; 128+signal after Ctrl-C (the shortened run is
still reported).
)";

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "hoist-replay: publish the winder input (LCM channel HOIST_WINDER) for hoist-twind from\n"
      "a synthetic hoist profile, a profile CSV or an LCM log, in real time or at --speed X.\n"
      "With no source it plays the paper's trapezoid (Fig. 2: 50 m -> 300 m, 60 s).\n"
      "--timing-test checks a running hoist-twind's real-time behaviour against budgets (see the end)."};
  app.footer(kTimingHelp);
  std::string profile_arg, log_path, url, config_path;
  std::vector<std::string> prefixes;
  double speed = 1.0, rate = 100.0;
  bool with_length = false, restamp = false, quiet = false;
  bool timing = false;
  double duration = 60.0;
  int shafts = 0;
  hoist::replay::Budgets budgets;
  double b_late_p99 = 0, b_late_max = 0, b_step_p99 = 0, b_e2e_p99 = 0;
  std::string report_path;
  auto* prof = app.add_option("--profile", profile_arg,
                              "profile CSV file, or SPEC: paper | trapezoid:... | scurve:... | estop:... "
                              "(see hoist-sim --help)");
  auto* logopt = app.add_option("--lcm-log", log_path, "re-publish HOIST_WINDER events of this LCM log")
                     ->check(CLI::ExistingFile);
  prof->excludes(logopt);
  logopt->excludes(prof);
  app.add_option("--speed", speed, "playback speed factor; 0 = as fast as possible (default 1)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--rate", rate, "messages per second of profile time (default 100)")
      ->check(numberIn(0.1, 10000.0, false, "in [0.1, 10000] Hz ([1, 1000] with --timing-test)"));
  app.add_option("--lcm-url", url, "LCM URL; default: $LCM_DEFAULT_URL, else LCM's default");
  auto* prefix_opt = app.add_option("--channel-prefix", prefixes,
                                    "prepended to the channel names (HOIST_WINDER; with --timing-test also "
                                    "HOIST_HEALTH, HOIST_CAGE); repeat it to test several shafts")
                         ->allow_extra_args(false);
  app.add_option("--config", config_path,
                 "shaft TOML: hoisting_rope.initial_length starts profiles that have no l column")
      ->check(CLI::ExistingFile);
  app.add_flag("--with-length", with_length, "include the encoder rope length l in every message");
  app.add_flag("--restamp", restamp, "--lcm-log: rewrite utime to the replay's wall clock");
  app.add_flag("-q,--quiet", quiet, "no progress display");
  auto* t_opt = app.add_flag("--timing-test", timing,
                             "check a running hoist-twind's timing against budgets (see below)")
                    ->group("Timing test");
  t_opt->excludes(prof)->excludes(logopt);
  for (const char* o : {"--speed", "--restamp", "--with-length"}) t_opt->excludes(app.get_option(o));
  const char* g = "Timing test";
  app.add_option("--duration", duration, "--timing-test: how long to feed [s] (default 60)")
      ->check(numberIn(0.0, 7 * 86400.0, true, "> 0 and at most 604800 s"))->needs(t_opt)->group(g);
  app.add_option("--shafts", shafts, "--timing-test: shafts with prefixes shaft1/ .. shaftN/ (1..1000)")
      ->check(numberIn(1, 1000, false, "in [1, 1000]"))->needs(t_opt)->excludes(prefix_opt)->group(g);
  auto budget = [&](const char* name, auto& var, const char* what) {
    return app.add_option(name, var, what)->check(numberIn(0.0, 1e300, false, ">= 0"))->needs(t_opt)->group(g);
  };
  budget("--max-late-p99-us", b_late_p99, "budget: tick lateness p99, worst HOIST_HEALTH window [us]");
  budget("--max-late-max-us", b_late_max, "budget: largest tick lateness [us]");
  budget("--max-misses", budgets.max_misses, "budget: deadline misses, summed over shafts (default 0)");
  budget("--max-step-p99-us", b_step_p99, "budget: model step time p99, worst HOIST_HEALTH window [us]");
  budget("--max-e2e-p99-us", b_e2e_p99, "budget: end-to-end latency p99, input publish -> cage output received [us]");
  budget("--max-rejected", budgets.max_rejected, "budget: inputs rejected by the daemon (default 0)");
  app.add_option("--report", report_path, "--timing-test: also write the Markdown report to FILE")
      ->needs(t_opt)->group(g);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  url = hoist::bus::resolveLcmUrl(url);
  if (timing) {
    hoist::replay::TimingTestOptions o;
    if (!(rate >= 1.0 && rate <= 1000.0)) {
      std::cerr << "hoist-replay: --rate: must be in [1, 1000] Hz for --timing-test (got " << rate << ")\n";
      return 2;
    }
    o.rate = rate;
    o.duration = duration;
    if (shafts > 0) {
      o.prefixes.clear();
      for (int i = 1; i <= shafts; ++i) o.prefixes.push_back("shaft" + std::to_string(i) + "/");
    } else if (!prefixes.empty()) {
      o.prefixes = prefixes;
    }
    for (std::size_t i = 0; i < o.prefixes.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (o.prefixes[i] == o.prefixes[j]) {
          std::cerr << "hoist-replay: --channel-prefix: '" << o.prefixes[i] << "' given twice\n";
          return 2;
        }
    if (app.count("--max-late-p99-us")) budgets.late_p99_us = b_late_p99;
    if (app.count("--max-late-max-us")) budgets.late_max_us = b_late_max;
    if (app.count("--max-step-p99-us")) budgets.step_p99_us = b_step_p99;
    if (app.count("--max-e2e-p99-us")) budgets.e2e_p99_us = b_e2e_p99;
    o.budgets = budgets;
    o.report_path = report_path;
    o.lcm_url = url;
    o.command = commandLine(argc, argv);
    o.quiet = quiet;
    o.progress = !quiet && isatty(STDERR_FILENO);
    if (!config_path.empty()) {
      // The trip must fit the daemon's shaft: from initial_length, at most
      // 250 m, staying 10 % clear of the bottom (else upward).
      try {
        const hoist::ShaftParams p = hoist::io::shaftParamsFromToml(hoist::io::loadTomlFile(config_path), config_path,
                                                                    {"service", "alarms"});
        o.l0 = p.l0;
        const double lmax = p.L - 2.0 * p.h;
        const double down = 0.9 * lmax - p.l0, up = p.l0 - 0.1 * lmax;
        o.travel = down >= up ? std::min(250.0, down) : -std::min(250.0, up);
        if (!(std::fabs(o.travel) >= 1.0)) {
          std::cerr << "hoist-replay: --config: the shaft leaves no room for a test trip from initial_length\n";
          return 2;
        }
      } catch (const std::exception& e) {
        std::cerr << "hoist-replay: " << e.what() << "\n";
        return 2;
      }
    }
    return hoist::replay::runTimingTest(o);
  }
  if (prefixes.size() > 1) {
    std::cerr << "hoist-replay: --channel-prefix: only one prefix without --timing-test\n";
    return 2;
  }
  const std::string prefix = prefixes.empty() ? std::string() : prefixes.front();
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << "hoist-replay: cannot open LCM at " << hoist::bus::describeLcmUrl(url) << "\n";
    return 1;
  }
  const std::string channel = hoist::bus::channel(prefix, hoist::bus::kChannelWinder);
  struct sigaction sa {};
  sa.sa_handler = onSignal;  // no SA_RESTART: interrupt the sleep
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  Progress progress(!quiet && isatty(STDERR_FILENO));
  const std::int64_t start_ns = monotonicNs();
  const std::int64_t start_utime = hoist::bus::wallUtime();
  long sent = 0, failed = 0;
  std::vector<std::uint8_t> buf(256);
  hoist::winder_t msg{};

  if (!log_path.empty()) {
    lcm::LogFile log(log_path, "r");
    if (!log.good()) {
      std::cerr << "hoist-replay: cannot open " << log_path << " as an LCM log\n";
      return 1;
    }
    std::int64_t first_ts = 0, first_utime = 0;
    bool first = true;
    while (const lcm::LogEvent* ev = log.readNextEvent()) {
      if (g_signal) break;
      if (!endsWith(ev->channel, std::string(hoist::bus::kChannelWinder))) continue;
      if (first) {
        first_ts = ev->timestamp;
        first = false;
      }
      const double t_rel = static_cast<double>(ev->timestamp - first_ts) * 1e-6;
      if (speed > 0.0 && !sleepUntil(start_ns + static_cast<std::int64_t>(t_rel / speed * 1e9))) break;
      const void* data = ev->data;
      int len = ev->datalen;
      if (restamp) {
        if (msg.decode(ev->data, 0, ev->datalen) != ev->datalen) {
          ++failed;
          continue;
        }
        if (sent == 0) first_utime = msg.utime;
        msg.utime = start_utime + (msg.utime - first_utime);
        len = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
        data = buf.data();
      }
      if (lcm.publish(channel, data, static_cast<unsigned>(len)) != 0) ++failed;
      else ++sent;
      progress.update(t_rel, 0.0, t_rel, sent);
    }
  } else {
    double l0 = 50.0;
    try {
      if (!config_path.empty())
        l0 = hoist::io::shaftParamsFromToml(hoist::io::loadTomlFile(config_path), config_path,
                                            {"service", "alarms"}).l0;
    } catch (const std::exception& e) {
      std::cerr << "hoist-replay: " << e.what() << "\n";
      return 2;
    }
    hoist::HoistProfile profile;
    try {
      profile = hoist::io::loadProfile(profile_arg.empty() ? std::string("paper") : profile_arg, l0);
    } catch (const std::exception& e) {
      std::cerr << "hoist-replay: " << e.what() << "\n";
      return 2;
    }
    const double t0 = profile.startTime(), t1 = profile.endTime();
    const double dt = 1.0 / rate;
    const long steps = std::lround((t1 - t0) / dt);
    for (long k = 0; k <= steps && !g_signal; ++k) {
      const double t = t0 + static_cast<double>(k) * dt;
      if (speed > 0.0 && !sleepUntil(start_ns + static_cast<std::int64_t>((t - t0) / speed * 1e9))) break;
      const hoist::Kinematics kin = profile.at(t);
      msg.utime = start_utime + std::llround((t - t0) * 1e6);
      msg.seq = k;
      msg.v = kin.v;
      msg.a = kin.a;
      msg.has_length = with_length;
      msg.length = with_length ? kin.l : 0.0;
      const int len = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
      if (len < 0 || lcm.publish(channel, buf.data(), static_cast<unsigned>(len)) != 0) ++failed;
      else ++sent;
      progress.update(t, t0, t1, sent);
    }
  }
  progress.done();
  if (g_signal) {
    std::cerr << "hoist-replay: stopped by signal after " << sent << " messages\n";
    return 128 + g_signal;
  }
  if (!quiet)
    std::cerr << "hoist-replay: published " << sent << " messages on " << channel
              << (failed ? " (" + std::to_string(failed) + " failed)" : std::string()) << "\n";
  return failed ? 1 : 0;
}
