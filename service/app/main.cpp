// hoist-twind -- the real-time digital twin daemon of the cable-guided hoist.
//
//   hoist-twind [--config FILE] [--lcm-url URL] [--clock wall|input] [--rate HZ]
//
// Subscribes to HOIST_WINDER (winder_t) and HOIST_ALARM_ACK (alarm_ack_t);
// publishes HOIST_CAGE, HOIST_GUIDE_SHAPE, HOIST_ALARM and HOIST_HEALTH (see
// msgs/*.lcm and docs/service.md).  Exit status: 0 after a clean stop
// (SIGINT/SIGTERM/--duration), 1 if LCM cannot be opened, 2 for a bad
// command line or configuration.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <spdlog/async.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "daemon.hpp"
#include "hoist/service/lcm_util.hpp"

int main(int argc, char** argv) {
  using namespace hoist::svc;
  CLI::App app{
      "hoist-twind: real-time digital twin of a cable-guided mine-shaft hoist.\n"
      "Follows the winder (LCM channel HOIST_WINDER) with the Wang et al. (2016) model and\n"
      "publishes the cage state (HOIST_CAGE), guide-rope shape (HOIST_GUIDE_SHAPE), clearance\n"
      "alarms (HOIST_ALARM; commands on HOIST_ALARM_ACK) and its own health (HOIST_HEALTH).\n"
      "Runs with the paper's shaft when given no --config."};
  std::string config_path, lcm_url, clock, prefix, log_level = "info";
  double rate = 0.0, duration = 0.0;
  bool print_config = false;
  app.add_option("--config", config_path,
                 "shaft TOML (+ [service], [alarms]); default: the paper's shaft")
      ->check(CLI::ExistingFile);
  app.add_option("--lcm-url", lcm_url,
                 "LCM URL; default: $LCM_DEFAULT_URL, else [service].lcm_url, else LCM's default");
  app.add_option("--clock", clock,
                 "wall: step on a timer from the latest input (default); input: step exactly to "
                 "each input's utime (deterministic replays)")
      ->check(CLI::IsMember({"wall", "input"}));
  app.add_option("--rate", rate, "model step rate with --clock wall [Hz], 1..1000 (default 100)");
  app.add_option("--channel-prefix", prefix, "prepended to every channel name (default [service].channel_prefix)");
  app.add_option("--duration", duration, "stop after this many seconds (default: run until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off (default info)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_flag("--print-config", print_config, "print the effective configuration as TOML and exit");
  // Test-only fault injection (tests/hardening); hidden from --help.
  double inject_fault_at = -1.0;
  int fail_publish_every = 0;
  app.add_option("--test-inject-fault-at", inject_fault_at)->group("");
  app.add_option("--test-fail-publish-every", fail_publish_every)->group("")->check(CLI::NonNegativeNumber);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  DaemonOptions opt;
  try {
    if (!config_path.empty()) opt.cfg = loadTwinConfig(config_path);
    if (!clock.empty()) opt.cfg.service.clock = clock == "input" ? ClockMode::Input : ClockMode::Wall;
    if (rate > 0.0) {
      opt.cfg.service.rate = rate;
      // Publish rates follow a lower --rate rather than failing validation.
      opt.cfg.service.cage_rate = std::min(opt.cfg.service.cage_rate, rate);
      opt.cfg.service.shape_rate = std::min(opt.cfg.service.shape_rate, rate);
    } else if (app.count("--rate")) {
      throw std::invalid_argument("--rate: must be in [1, 1000] Hz");
    }
    if (app.count("--channel-prefix")) opt.cfg.service.channel_prefix = prefix;
    try {
      opt.cfg.service.validate();
    } catch (const std::invalid_argument& e) {
      std::string what = e.what();
      if (what.rfind("service.rate", 0) == 0) what = "--rate: " + what;
      throw std::invalid_argument(what);
    }
    opt.cfg.shaft.validate();
  } catch (const std::exception& e) {
    std::cerr << "hoist-twind: configuration error: " << e.what() << "\n";
    return 2;
  }
  if (print_config) {
    std::cout << toToml(opt.cfg);
    return 0;
  }
  opt.lcm_url = resolveLcmUrl(lcm_url, opt.cfg.service.lcm_url);
  opt.duration = duration;
  opt.inject_fault_at = inject_fault_at;
  opt.fail_publish_every = fail_publish_every;

  // Asynchronous, non-blocking logger: a full queue drops the oldest line
  // instead of stalling the tick.
  spdlog::init_thread_pool(8192, 1);
  auto sink = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  auto log = std::make_shared<spdlog::async_logger>("hoist-twind", sink, spdlog::thread_pool(),
                                                    spdlog::async_overflow_policy::overrun_oldest);
  log->set_level(spdlog::level::from_str(log_level));
  log->set_pattern("%Y-%m-%d %H:%M:%S.%e [%^%l%$] %v");
  log->flush_on(spdlog::level::info);
  spdlog::register_logger(log);

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
