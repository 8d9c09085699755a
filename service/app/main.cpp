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
//
// main() is parse -> check -> run: the options and their checks are in
// twind_options.*, the start-up budget's verdict in startup_budget.*.
#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <sys/stat.h>
#include <unistd.h>
#include <cstdio>
#include <iostream>
#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "daemon.hpp"
#include "hoist/cli/app.hpp"
#include "startup_budget.hpp"
#include "twind_options.hpp"
#include "hoist/service/cfg/config_file.hpp"

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
  using namespace hoist::service;
  // ---- parse ----
  CLI::App app{
      "hoist-twind: real-time digital twin of a cable-guided mine-shaft hoist.\n"
      "Follows the winder (LCM channel HOIST_WINDER) with the Wang et al. (2016) model and\n"
      "publishes the cage state (HOIST_CAGE), guide-rope shape (HOIST_GUIDE_SHAPE), clearance\n"
      "alarms (HOIST_ALARM; commands on HOIST_ALARM_ACK) and its own health (HOIST_HEALTH).\n"
      "With [forecast] enabled: the look-ahead (HOIST_FORECAST) along the winder's plan\n"
      "(HOIST_TRIP_PLAN).  With [estimator] enabled: the load estimate (HOIST_ESTIMATE) from the\n"
      "cage IMU (HOIST_CAGE_IMU) and the rope load cell (HOIST_ROPE_LOAD).  Every channel name\n"
      "takes the shaft's channel_prefix.  Runs with the paper's shaft when given no --config."};
  hoist::cli::nameProgram(app, "hoist-twind");  // usage, errors and --version name the program
  TwindCommandLine cl;
  addTwindOptions(app, cl);
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  noteGivenOptions(app, cl);

  // ---- check (exit 2 naming the option or key) ----
  DaemonOptions opt;
  try {
    std::string shaft_url;  // the one [service].lcm_url all shafts agree on
    loadTwindShafts(cl, opt, shaft_url);
    if (cl.print_config) {
      for (std::size_t i = 0; i < opt.shafts.size(); ++i) {
        if (opt.shafts.size() > 1) std::cout << (i ? "\n" : "") << "# ---- --config " << cl.config_paths[i] << "\n";
        std::cout << toToml(opt.shafts[i]) << "\n" << toToml(opt.history[i]);
      }
      return 0;
    }
    checkTwindRun(cl, shaft_url, argc, argv, opt);
  } catch (const TwindConfigError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  // Can this configuration run?  Measure a tick of each shaft on a scratch
  // model; refuse (exit 2) when the loop cannot keep up, unless --force.
  StartupBudget budget;
  try {
    budget = measureStartupBudget(opt, cl.force);
  } catch (const std::exception& e) {
    std::cerr << "hoist-twind: configuration error: " << e.what() << "\n";
    return 2;
  }
  if (budget.over && !cl.force) {
    std::cerr << "hoist-twind: configuration cannot run in real time: " << budget.line
              << ".  A whole tick with the cage moving, largest part first: " << budget.parts
              << ".  Lower the keys of the largest parts ([model] modes, [service] rate, envelope_points, "
                 "shape_rate, shape_points, cage_rate), raise [service] max_step or envelope_tolerance, or host "
                 "fewer shafts; --force runs anyway (deadline misses, degraded outputs).\n";
    return 2;
  }

  // ---- run ----
  // The loop thread never writes to the terminal itself: its lines go
  // through RtLog's ring to a writer thread (daemon.hpp).
  auto sink = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  auto log = std::make_shared<spdlog::logger>("hoist-twind", sink);
  log->set_level(spdlog::level::from_str(cl.log_level));
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
  if (budget.warn) log->warn("{}", budget.line);
  else log->info("{}", budget.line);

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
