// hoist-twind's command line: see twind_options.hpp.
#include "twind_options.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <set>

#include "hoist/bus/lcm_util.hpp"
#include "hoist/history/config.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/service/cfg/config_file.hpp"
#include "hoist/service/cfg/history_config.hpp"

namespace hoist::service::inline app {

namespace {
/// The error line of a configuration that cannot run: "hoist-twind:
/// configuration error: " and what (which names the option or key).
TwindConfigError configError(const std::string& what) {
  return TwindConfigError("hoist-twind: configuration error: " + what);
}

/// The --config files ("" for the paper's shaft when none is given).
std::vector<std::string> configPaths(const TwindCommandLine& cl) {
  return cl.config_paths.empty() ? std::vector<std::string>{""} : cl.config_paths;
}
}  // namespace

void addTwindOptions(CLI::App& app, TwindCommandLine& cl) {
  app.add_option("--config", cl.config_paths,
                 "shaft TOML (+ [service], [alarms]); default: the paper's shaft.  Repeat it to host "
                 "several shafts in one process, each with its own [service].channel_prefix")
      ->check(CLI::ExistingFile);
  app.add_option("--lcm-url", cl.lcm_url,
                 "LCM URL; default: $LCM_DEFAULT_URL, else [service].lcm_url, else LCM's default");
  app.add_option("--clock", cl.clock,
                 "wall: step on a timer from the latest input (default); input: step exactly to "
                 "each input's utime (deterministic replays)")
      ->check(CLI::IsMember({"wall", "input"}));
  app.add_option("--rate", cl.rate, "model step rate with --clock wall [Hz], 1..1000 (default 100)");
  app.add_option("--channel-prefix", cl.prefix,
                 "prepended to every channel name (default [service].channel_prefix; one shaft only)");
  app.add_option("--duration", cl.duration, "stop after this many seconds (default: run until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--log-level", cl.log_level, "trace, debug, info, warn, error, critical or off (default info)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_option("--history-default", cl.history_default,
                 "the trip database when [history] url is empty (default: history.sqlite beside the "
                 "configuration; the installed service passes sqlite:///var/lib/hoist-twin/history.sqlite).  "
                 "Trips are recorded when a --config is given, unless [history] enabled = false");
  app.add_flag("--print-config", cl.print_config, "print the effective configuration as TOML and exit");
  app.add_flag("--force", cl.force,
               "run even when the start-up measurement says a tick cannot fit its period (exit 2 otherwise)");
  auto* rt = app.add_option_group("real time", "optional; each is reported at start-up and the daemon runs without it if refused");
  rt->add_flag("--mlockall", cl.mlock, "lock all memory (mlockall) so the loop never page-faults");
  rt->add_option("--rt-priority", cl.rt_priority, "run the loop thread SCHED_FIFO at this priority, 1..99")
      ->check(CLI::Range(1, 99));
  rt->add_option("--cpus", cl.cpus, "pin the loop thread to these CPUs, e.g. 1 or 2-3");
  app.add_option("--state-dir", cl.state_dir,
                 "keep state across restarts in DIR: each shaft's learned accelerometer offset (a calibration's "
                 "result; [estimator] enabled). Default: $STATE_DIRECTORY (systemd's StateDirectory=), else none");
  app.add_option("--report", cl.report,
                 "at stop, write a run report (JSON: step time and tick lateness histograms with "
                 "p50/p99/p99.9/max per shaft, deadline misses, counters, real-time settings) to FILE");
  app.add_option("--test-inject-fault-at", cl.inject_fault_at)->group("");
  app.add_option("--test-fail-publish-every", cl.fail_publish_every)->group("")->check(CLI::NonNegativeNumber);
  app.add_option("--test-stall-at", cl.stall_at)->group("")->check(CLI::NonNegativeNumber);
  app.add_option("--test-slow-tick-at", cl.slow_tick_at)->group("")->check(CLI::NonNegativeNumber);
  app.add_option("--test-slow-tick-ms", cl.slow_tick_ms)->group("")->check(CLI::Range(0.0, 10000.0));
}

void noteGivenOptions(const CLI::App& app, TwindCommandLine& cl) {
  cl.rate_given = app.count("--rate") > 0;
  cl.prefix_given = app.count("--channel-prefix") > 0;
  cl.lcm_url_given = app.count("--lcm-url") > 0;
}

void loadTwindShafts(const TwindCommandLine& cl, DaemonOptions& opt, std::string& shaft_url) {
  try {
    const std::vector<std::string> config_paths = configPaths(cl);
    if (config_paths.size() > 1 && cl.prefix_given)
      throw std::invalid_argument("--channel-prefix: only with a single --config (each shaft's file sets its own [service].channel_prefix)");
    std::set<std::string> prefixes;
    std::string first_url_from;
    for (std::size_t i = 0; i < config_paths.size(); ++i) {
      const std::string& path = config_paths[i];
      const std::string where = path.empty() ? "(paper defaults)" : path;
      TwinConfig cfg = path.empty() ? TwinConfig{} : loadTwinConfig(path);
      if (!cl.clock.empty()) cfg.service.clock = cl.clock == "input" ? ClockMode::Input : ClockMode::Wall;
      if (cl.rate > 0.0) {
        cfg.service.rate = cl.rate;
        // Publish rates follow a lower --rate rather than failing validation.
        cfg.service.cage_rate = std::min(cfg.service.cage_rate, cl.rate);
        cfg.service.shape_rate = std::min(cfg.service.shape_rate, cl.rate);
      } else if (cl.rate_given) {
        throw std::invalid_argument("--rate: must be in [1, 1000] Hz");
      }
      if (cl.prefix_given) cfg.service.channel_prefix = cl.prefix;
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
        throw std::invalid_argument(where + ": " + e.what() + (cl.rate > 0.0 ? " (with --rate)" : ""));
      }
      if (!prefixes.insert(cfg.service.channel_prefix).second)
        throw std::invalid_argument(where + ": service.channel_prefix: \"" + cfg.service.channel_prefix +
                                    "\" is already used by another --config (each shaft needs its own)");
      if (i == 0) {
        shaft_url = cfg.service.lcm_url;
        first_url_from = where;
      } else if (cfg.service.lcm_url != shaft_url && cl.lcm_url.empty()) {
        throw std::invalid_argument(where + ": service.lcm_url: \"" + cfg.service.lcm_url + "\" differs from \"" +
                                    shaft_url + "\" in " + first_url_from +
                                    " (one process has one LCM instance; give --lcm-url to override)");
      }
      std::string label;
      if (config_paths.size() > 1)
        label = cfg.service.channel_prefix.empty() ? std::filesystem::path(path).stem().string()
                                                   : cfg.service.channel_prefix;
      TripHistoryConfig hist = loadTripHistoryConfig(path);
      if (hist.store.url.empty() && !cl.history_default.empty()) {
        hist.store.url = cl.history_default;
        (void)hoist::history::parseDatabaseUrl(cl.history_default, "--history-default");  // names the option
      }
      opt.shafts.push_back(std::move(cfg));
      opt.labels.push_back(label);
      if (!label.empty()) hist.shaft = label;
      opt.history.push_back(std::move(hist));
    }
    if (!cl.cpus.empty()) opt.realtime.cpus = parseCpuList(cl.cpus, "--cpus");
  } catch (const std::exception& e) {
    throw configError(e.what());
  }
}

void checkTwindRun(const TwindCommandLine& cl, const std::string& shaft_url, int argc, char** argv,
                   DaemonOptions& opt) {
  const std::vector<std::string> config_paths = configPaths(cl);
  if (const std::string bad = hoist::bus::lcmUrlUsageError("hoist-twind", cl.lcm_url_given, cl.lcm_url, cl.lcm_url);
      !bad.empty())
    throw TwindConfigError(bad);
  opt.lcm_url = hoist::bus::resolveLcmUrl(cl.lcm_url, shaft_url);
  if (const std::string bad = hoist::bus::lcmUrlError(opt.lcm_url); !bad.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    const std::string from = !cl.lcm_url.empty()       ? "--lcm-url: "
                             : (env && *env)           ? "LCM_DEFAULT_URL: "
                             : config_paths[0].empty() ? ""
                                                       : config_paths[0] + ": service.lcm_url: ";
    throw configError(from + bad);
  }
  for (std::size_t i = 1; i < opt.shafts.size(); ++i)
    if (opt.shafts[i].service.lcm_url_out != opt.shafts[0].service.lcm_url_out)
      throw configError(config_paths[i] + ": service.lcm_url_out: \"" + opt.shafts[i].service.lcm_url_out +
                        "\" differs from \"" + opt.shafts[0].service.lcm_url_out + "\" in " + config_paths[0] +
                        " (one process has one output URL)");
  opt.lcm_url_out = opt.shafts[0].service.lcm_url_out;

  opt.duration = cl.duration;
  opt.hooks.inject_fault_at = cl.inject_fault_at;
  opt.hooks.fail_publish_every = cl.fail_publish_every;
  opt.test_stall_at = cl.stall_at;
  opt.hooks.slow_tick_at = cl.slow_tick_at;
  opt.hooks.slow_tick_ms = cl.slow_tick_ms;
  opt.realtime.mlockall = cl.mlock;
  opt.realtime.fifo_priority = cl.rt_priority;
  opt.report_path = cl.report;
  std::string state_dir = cl.state_dir;
  if (state_dir.empty()) {
    // systemd: StateDirectory= sets $STATE_DIRECTORY (colon-separated when several).
    if (const char* env = std::getenv("STATE_DIRECTORY"); env && *env) {
      state_dir = env;
      state_dir = state_dir.substr(0, state_dir.find(':'));
    }
  }
  if (!state_dir.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_directory(state_dir, ec)) throw configError("--state-dir " + state_dir + ": not a directory");
  }
  opt.state_dir = state_dir;
  if (const std::string bad = cl.report.empty() ? "" : hoist::io::outputPathError(cl.report, "--report"); !bad.empty())
    throw configError(bad);
  for (int i = 0; i < argc; ++i) opt.command_line += (i ? " " : "") + std::string(argv[i]);
}

}  // namespace hoist::service::app
