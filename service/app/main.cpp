// hoist-twind -- the real-time digital twin daemon of the cable-guided hoist.
//
//   hoist-twind [--config FILE]... [--lcm-url URL] [--clock wall|input] [--rate HZ]
//               [--mlockall] [--rt-priority N] [--cpus LIST] [--report FILE]
//
// Several --config files host several shafts in one process (one loop), each
// with its own [service].channel_prefix.
// Subscribes to HOIST_WINDER (winder_t) and HOIST_ALARM_ACK (alarm_ack_t),
// HOIST_TRIP_PLAN with [forecast], HOIST_CAGE_IMU and HOIST_ROPE_LOAD with
// [estimator]; publishes HOIST_CAGE, HOIST_GUIDE_SHAPE, HOIST_ALARM and
// HOIST_HEALTH, HOIST_FORECAST and HOIST_ESTIMATE likewise (see
// msgs/*.lcm and docs/service.md).  Exit status: 0 after a clean stop
// (SIGINT/SIGTERM/--duration), 1 if a well-formed LCM URL cannot be opened,
// 2 for a bad command line, configuration or LCM URL.
#include "hoist/version.hpp"
#include <CLI/CLI.hpp>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <sys/stat.h>
#include <unistd.h>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>
#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "daemon.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/service/budget.hpp"
#include "hoist/service/config_file.hpp"

namespace {
/// True when stderr is the systemd journal's stream: systemd sets
/// JOURNAL_STREAM=<device>:<inode> of the socket it connects stdout/stderr to.
bool stderrIsJournal() {
  const char* js = std::getenv("JOURNAL_STREAM");
  if (!js || !*js) return false;
  unsigned long long dev = 0, ino = 0;
  if (std::sscanf(js, "%llu:%llu", &dev, &ino) != 2) return false;
  struct stat st {};
  if (fstat(STDERR_FILENO, &st) != 0) return false;
  return static_cast<unsigned long long>(st.st_dev) == dev && static_cast<unsigned long long>(st.st_ino) == ino;
}

/// spdlog flag %* -> "<N>" (sd-daemon(3) priority prefix) from the line's level.
class SyslogPriorityFlag : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&, spdlog::memory_buf_t& dest) override {
    static constexpr const char* kPrefix[] = {"<7>", "<7>", "<6>", "<4>", "<3>", "<2>", ""};  // trace..off
    const char* p = kPrefix[static_cast<int>(msg.level) < 7 ? static_cast<int>(msg.level) : 6];
    dest.append(p, p + std::strlen(p));
  }
  std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<SyslogPriorityFlag>(); }
};
}  // namespace

int main(int argc, char** argv) {
  using namespace hoist::svc;
  CLI::App app{
      "hoist-twind: real-time digital twin of a cable-guided mine-shaft hoist.\n"
      "Follows the winder (LCM channel HOIST_WINDER) with the Wang et al. (2016) model and\n"
      "publishes the cage state (HOIST_CAGE), guide-rope shape (HOIST_GUIDE_SHAPE), clearance\n"
      "alarms (HOIST_ALARM; commands on HOIST_ALARM_ACK) and its own health (HOIST_HEALTH).\n"
      "With [forecast] enabled: the look-ahead (HOIST_FORECAST) along the winder's plan\n"
      "(HOIST_TRIP_PLAN).  With [estimator] enabled: the load estimate (HOIST_ESTIMATE) from the\n"
      "cage IMU (HOIST_CAGE_IMU) and the rope load cell (HOIST_ROPE_LOAD).  Every channel name\n"
      "takes the shaft's channel_prefix.  Runs with the paper's shaft when given no --config."};
  app.name("hoist-twind");  // usage lines name the program, not the path it was run by
  app.failure_message([](const CLI::App* a, const CLI::Error& e) { return a->get_name() + ": " + CLI::FailureMessage::simple(a, e); });  // errors name the program
  app.set_version_flag("--version", std::string("hoist-twind ") + hoist::kVersionString);
  std::vector<std::string> config_paths;
  std::string lcm_url, clock, prefix, log_level = "info", cpus, report, state_dir;
  double rate = 0.0, duration = 0.0;
  int rt_priority = 0;
  bool print_config = false, mlock = false, force = false;
  std::string history_default;
  app.add_option("--config", config_paths,
                 "shaft TOML (+ [service], [alarms]); default: the paper's shaft.  Repeat it to host "
                 "several shafts in one process, each with its own [service].channel_prefix")
      ->check(CLI::ExistingFile);
  app.add_option("--lcm-url", lcm_url,
                 "LCM URL; default: $LCM_DEFAULT_URL, else [service].lcm_url, else LCM's default");
  app.add_option("--clock", clock,
                 "wall: step on a timer from the latest input (default); input: step exactly to "
                 "each input's utime (deterministic replays)")
      ->check(CLI::IsMember({"wall", "input"}));
  app.add_option("--rate", rate, "model step rate with --clock wall [Hz], 1..1000 (default 100)");
  app.add_option("--channel-prefix", prefix,
                 "prepended to every channel name (default [service].channel_prefix; one shaft only)");
  app.add_option("--duration", duration, "stop after this many seconds (default: run until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, critical or off (default info)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_option("--history-default", history_default,
                 "the trip database when [history] url is empty (default: history.sqlite beside the "
                 "configuration; the installed service passes sqlite:///var/lib/hoist-twin/history.sqlite).  "
                 "Trips are recorded when a --config is given, unless [history] enabled = false");
  app.add_flag("--print-config", print_config, "print the effective configuration as TOML and exit");
  app.add_flag("--force", force,
               "run even when the start-up measurement says a tick cannot fit its period (exit 2 otherwise)");
  auto* rt = app.add_option_group("real time", "optional; each is reported at start-up and the daemon runs without it if refused");
  rt->add_flag("--mlockall", mlock, "lock all memory (mlockall) so the loop never page-faults");
  rt->add_option("--rt-priority", rt_priority, "run the loop thread SCHED_FIFO at this priority, 1..99")
      ->check(CLI::Range(1, 99));
  rt->add_option("--cpus", cpus, "pin the loop thread to these CPUs, e.g. 1 or 2-3");
  app.add_option("--state-dir", state_dir,
                 "keep state across restarts in DIR: each shaft's learned accelerometer offset (a calibration's "
                 "result; [estimator] enabled). Default: $STATE_DIRECTORY (systemd's StateDirectory=), else none");
  app.add_option("--report", report,
                 "at stop, write a run report (JSON: step time and tick lateness histograms with "
                 "p50/p99/p99.9/max per shaft, deadline misses, counters, real-time settings) to FILE");
  // Test-only fault injection (tests/hardening); hidden from --help.
  double inject_fault_at = -1.0;
  int fail_publish_every = 0;
  app.add_option("--test-inject-fault-at", inject_fault_at)->group("");
  app.add_option("--test-fail-publish-every", fail_publish_every)->group("")->check(CLI::NonNegativeNumber);
  double stall_at = -1.0;  // the loop thread hangs at this time: the systemd watchdog test
  app.add_option("--test-stall-at", stall_at)->group("")->check(CLI::NonNegativeNumber);
  // One slow tick on purpose (the miss record's test): at this wall time the
  // first shaft's step busy-waits this many milliseconds.
  double slow_tick_at = -1.0, slow_tick_ms = 0.0;
  app.add_option("--test-slow-tick-at", slow_tick_at)->group("")->check(CLI::NonNegativeNumber);
  app.add_option("--test-slow-tick-ms", slow_tick_ms)->group("")->check(CLI::Range(0.0, 10000.0));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  DaemonOptions opt;
  std::string shaft_url;  // the one [service].lcm_url all shafts agree on
  try {
    if (config_paths.empty()) config_paths.push_back("");
    if (config_paths.size() > 1 && app.count("--channel-prefix"))
      throw std::invalid_argument("--channel-prefix: only with a single --config (each shaft's file sets its own [service].channel_prefix)");
    std::set<std::string> prefixes;
    std::string first_url_from;
    for (std::size_t i = 0; i < config_paths.size(); ++i) {
      const std::string& path = config_paths[i];
      const std::string where = path.empty() ? "(paper defaults)" : path;
      TwinConfig cfg = path.empty() ? TwinConfig{} : loadTwinConfig(path);
      if (!clock.empty()) cfg.service.clock = clock == "input" ? ClockMode::Input : ClockMode::Wall;
      if (rate > 0.0) {
        cfg.service.rate = rate;
        // Publish rates follow a lower --rate rather than failing validation.
        cfg.service.cage_rate = std::min(cfg.service.cage_rate, rate);
        cfg.service.shape_rate = std::min(cfg.service.shape_rate, rate);
      } else if (app.count("--rate")) {
        throw std::invalid_argument("--rate: must be in [1, 1000] Hz");
      }
      if (app.count("--channel-prefix")) cfg.service.channel_prefix = prefix;
      try {
        cfg.service.validate();
      } catch (const std::invalid_argument& e) {
        std::string what = e.what();
        if (what.rfind("service.rate", 0) == 0) what = "--rate: " + what;
        throw std::invalid_argument(what);
      }
      cfg.shaft.validate();
      // [forecast] against the effective [service] rate (--rate may have lowered it).
      try {
        cfg.forecast.validate(cfg.service.rate);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(where + ": " + e.what() + (rate > 0.0 ? " (with --rate)" : ""));
      }
      if (!prefixes.insert(cfg.service.channel_prefix).second)
        throw std::invalid_argument(where + ": service.channel_prefix: \"" + cfg.service.channel_prefix +
                                    "\" is already used by another --config (each shaft needs its own)");
      if (i == 0) {
        shaft_url = cfg.service.lcm_url;
        first_url_from = where;
      } else if (cfg.service.lcm_url != shaft_url && lcm_url.empty()) {
        throw std::invalid_argument(where + ": service.lcm_url: \"" + cfg.service.lcm_url + "\" differs from \"" +
                                    shaft_url + "\" in " + first_url_from +
                                    " (one process has one LCM instance; give --lcm-url to override)");
      }
      std::string label;
      if (config_paths.size() > 1)
        label = cfg.service.channel_prefix.empty() ? std::filesystem::path(path).stem().string()
                                                   : cfg.service.channel_prefix;
      TripHistoryConfig hist = loadTripHistoryConfig(path);
      if (hist.store.url.empty() && !history_default.empty()) {
        hist.store.url = history_default;
        (void)hoist::history::parseDatabaseUrl(history_default, "--history-default");  // names the option
      }
      opt.shafts.push_back(std::move(cfg));
      opt.labels.push_back(label);
      if (!label.empty()) hist.shaft = label;
      opt.history.push_back(std::move(hist));
    }
    if (!cpus.empty()) opt.realtime.cpus = parseCpuList(cpus, "--cpus");
  } catch (const std::exception& e) {
    std::cerr << "hoist-twind: configuration error: " << e.what() << "\n";
    return 2;
  }
  if (print_config) {
    for (std::size_t i = 0; i < opt.shafts.size(); ++i) {
      if (opt.shafts.size() > 1) std::cout << (i ? "\n" : "") << "# ---- --config " << config_paths[i] << "\n";
      std::cout << toToml(opt.shafts[i]) << "\n" << toToml(opt.history[i]);
    }
    return 0;
  }
  if (const std::string bad = hoist::bus::lcmUrlUsageError("hoist-twind", app.count("--lcm-url") > 0, lcm_url, lcm_url); !bad.empty()) { std::cerr << bad << "\n"; return 2; }
  opt.lcm_url = hoist::bus::resolveLcmUrl(lcm_url, shaft_url);
  if (const std::string bad = hoist::bus::lcmUrlError(opt.lcm_url); !bad.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    const std::string from = !lcm_url.empty()          ? "--lcm-url: "
                             : (env && *env)           ? "LCM_DEFAULT_URL: "
                             : config_paths[0].empty() ? ""
                                                       : config_paths[0] + ": service.lcm_url: ";
    std::cerr << "hoist-twind: configuration error: " << from << bad << "\n";
    return 2;
  }
  for (std::size_t i = 1; i < opt.shafts.size(); ++i)
    if (opt.shafts[i].service.lcm_url_out != opt.shafts[0].service.lcm_url_out) {
      std::cerr << "hoist-twind: configuration error: " << config_paths[i] << ": service.lcm_url_out: \""
                << opt.shafts[i].service.lcm_url_out << "\" differs from \"" << opt.shafts[0].service.lcm_url_out
                << "\" in " << config_paths[0] << " (one process has one output URL)\n";
      return 2;
    }
  opt.lcm_url_out = opt.shafts[0].service.lcm_url_out;
  // Can this configuration run?  Measure a tick of each shaft on a scratch
  // model; refuse (exit 2) when the loop cannot keep up, unless --force.
  std::string budget_line, budget_parts;
  bool budget_warn = false;
  {
    double use = 0.0;
    std::string too_slow;  // shafts whose slowest tick (one with the exact envelope) exceeds the period
    bool tight = false;    // ... or takes more than half of it
    for (std::size_t i = 0; i < opt.shafts.size(); ++i) {
      TickBudget b;
      try {
        b = measureTickBudget(opt.shafts[i]);
      } catch (const std::exception& e) {
        std::cerr << "hoist-twind: configuration error: " << e.what() << "\n";
        return 2;
      }
      use += b.use;
      char line[320];
      if (b.worst_us > 0.5 * b.period_us && b.worst_us <= b.period_us) tight = true;
      if (b.worst_us > b.period_us) {
        std::snprintf(line, sizeof line, "%s%sa tick that needs the exact guide-rope envelope takes %.0f us, more than "
                      "the period of %.0f us", too_slow.empty() ? "" : "; ",
                      opt.labels[i].empty() ? "" : (opt.labels[i] + ": ").c_str(), b.worst_us, b.period_us);
        too_slow += line;
      }
      std::snprintf(line, sizeof line, "%s%s%.1f us per tick of %.0f us (%.1f %%, n = %d, %d substeps of max_step)",
                    budget_line.empty() ? "" : "; ", opt.labels[i].empty() ? "" : (opt.labels[i] + ": ").c_str(),
                    b.tick_us, b.period_us, 100.0 * b.use, opt.shafts[i].shaft.n,
                    opt.shafts[i].service.max_step > 0.0
                        ? static_cast<int>(std::ceil(1.0 / opt.shafts[i].service.rate / opt.shafts[i].service.max_step - 1e-9))
                        : 1);
      budget_line += line;
      budget_parts += (budget_parts.empty() ? "" : "; ") +
                      (opt.labels[i].empty() ? std::string() : opt.labels[i] + ": ") +
                      describeBudget(b, opt.shafts[i]);
    }
    char total[96];
    std::snprintf(total, sizeof total, " -> budget use %.1f %% of one core", 100.0 * use);
    budget_line = "measured start-up budget: " + budget_line + total;
    if (!too_slow.empty()) budget_line += "; " + too_slow;
    const bool over = use > 1.0 || !too_slow.empty();
    if (over && !force) {
      std::cerr << "hoist-twind: configuration cannot run in real time: " << budget_line
                << ".  A whole tick with the cage moving, largest part first: " << budget_parts
                << ".  Lower the keys of the largest parts ([model] modes, [service] rate, envelope_points, "
                   "shape_rate, shape_points, cage_rate), raise [service] max_step or envelope_tolerance, or host "
                   "fewer shafts; --force runs anyway (deadline misses, degraded outputs).\n";
      return 2;
    }
    if (over) budget_line += " -- OVER BUDGET, running because of --force";
    else if (use > 0.5 || tight)
      budget_line += use > 0.5 ? " -- more than half the period: little margin for jitter"
                               : " -- a tick that needs the exact guide-rope envelope takes more than half the period";
    if (over || use > 0.5 || tight) budget_line += " (" + budget_parts + ")";
    budget_warn = over || use > 0.5 || tight;
  }
  opt.duration = duration;
  opt.hooks.inject_fault_at = inject_fault_at;
  opt.hooks.fail_publish_every = fail_publish_every;
  opt.test_stall_at = stall_at;
  opt.hooks.slow_tick_at = slow_tick_at;
  opt.hooks.slow_tick_ms = slow_tick_ms;
  opt.realtime.mlockall = mlock;
  opt.realtime.fifo_priority = rt_priority;
  opt.report_path = report;
  if (state_dir.empty()) {
    // systemd: StateDirectory= sets $STATE_DIRECTORY (colon-separated when several).
    if (const char* env = std::getenv("STATE_DIRECTORY"); env && *env) {
      state_dir = env;
      state_dir = state_dir.substr(0, state_dir.find(':'));
    }
  }
  if (!state_dir.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_directory(state_dir, ec)) {
      std::cerr << "hoist-twind: configuration error: --state-dir " << state_dir << ": not a directory\n";
      return 2;
    }
  }
  opt.state_dir = state_dir;
  if (const std::string bad = report.empty() ? "" : hoist::io::outputPathError(report, "--report"); !bad.empty()) { std::cerr << "hoist-twind: configuration error: " << bad << "\n"; return 2; }
  for (int i = 0; i < argc; ++i) opt.command_line += (i ? " " : "") + std::string(argv[i]);

  // The loop thread never writes to the terminal itself: its lines go
  // through RtLog's ring to a writer thread (daemon.hpp).
  auto sink = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  auto log = std::make_shared<spdlog::logger>("hoist-twind", sink);
  log->set_level(spdlog::level::from_str(log_level));
  if (stderrIsJournal()) {
    // Under systemd (hoist-twind@.service) stderr is the journal, which
    // stamps every line itself: no second timestamp, and a <N> syslog
    // priority prefix so `journalctl -p warning` selects by level.
    auto f = std::make_unique<spdlog::pattern_formatter>();
    f->add_flag<SyslogPriorityFlag>('*').set_pattern("%*%v");
    log->set_formatter(std::move(f));
  } else {
    log->set_pattern("%Y-%m-%d %H:%M:%S.%e [%^%l%$] %v");
  }
  log->flush_on(spdlog::level::info);
  spdlog::register_logger(log);

  // SIGINT/SIGTERM must reach the loop thread: block them here, before the
  // Daemon starts its helper threads (LCM's receive thread, the log writer),
  // which inherit the mask; Daemon::start() unblocks them on the loop thread.
  // Otherwise the kernel may deliver a signal to a helper thread that a
  // SCHED_FIFO loop pinned to the same CPU starves when overloaded, and the
  // stop request would never be seen.
  // The same for the other signals the loop handles (daemon.hpp); SIGPIPE
  // (a dead log reader), SIGTTOU/SIGTTIN (a background terminal) are ignored.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  for (int sig : {SIGINT, SIGTERM, SIGQUIT, SIGHUP, SIGUSR1, SIGUSR2}) sigaddset(&stop_signals, sig);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  for (int sig : {SIGPIPE, SIGTTOU, SIGTTIN}) std::signal(sig, SIG_IGN);
  if (budget_warn) log->warn("{}", budget_line);
  else log->info("{}", budget_line);

  int rc = 0;
  try {
    Daemon d(std::move(opt), log);
    rc = d.run();
  } catch (const std::exception& e) {
    log->critical("fatal: {}", e.what());
    rc = 1;
  }
  log->flush();
  spdlog::shutdown();
  return rc;
}
