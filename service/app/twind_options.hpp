// hoist-twind's command line, in the order main() takes it: parse
// (addTwindOptions: every option into a TwindCommandLine), check
// (loadTwindShafts: the configurations; checkTwindRun: the LCM URLs, the
// paths, the test hooks), then run (main.cpp: the start-up budget, the log,
// the Daemon).  No state outlives the calls; nothing here runs in the loop.
#pragma once

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon.hpp"

namespace hoist::service::inline app {

/// hoist-twind's options as given (defaults: none given).
struct TwindCommandLine {
  std::vector<std::string> config_paths;  ///< --config (repeatable; empty: the paper's shaft)
  std::string lcm_url, clock, prefix, log_level = "info", cpus, report, state_dir, history_default;
  double rate = 0.0, duration = 0.0;
  int rt_priority = 0;
  bool print_config = false, mlock = false, force = false;
  bool rate_given = false, prefix_given = false, lcm_url_given = false;  ///< set by parsing
  // Test-only fault injection (tests/hardening); hidden from --help.
  double inject_fault_at = -1.0;
  int fail_publish_every = 0;
  double stall_at = -1.0;  ///< the loop thread hangs at this time: the systemd watchdog test
  /// One slow tick on purpose (the miss record's test): at this wall time
  /// the first shaft's step busy-waits this many milliseconds.
  double slow_tick_at = -1.0, slow_tick_ms = 0.0;
};

/// A command line or configuration that cannot run: the whole line to
/// print on stderr (it names the program and the option or key), exit 2.
struct TwindConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Adds every option of hoist-twind to `app`, parsed into `cl` (which must
/// outlive the parse).
void addTwindOptions(CLI::App& app, TwindCommandLine& cl);
/// After parsing: fills the *_given flags from `app`.
void noteGivenOptions(const CLI::App& app, TwindCommandLine& cl);

/// The shafts: each --config loaded, the command line applied and
/// validated, the prefixes and [service] lcm_url checked across them, into
/// opt.shafts, labels and history; `shaft_url` is the lcm_url they agree
/// on.  Throws TwindConfigError.
void loadTwindShafts(const TwindCommandLine& cl, DaemonOptions& opt, std::string& shaft_url);
/// The rest of the check before a run: the LCM URLs (input and output),
/// the state directory, the report path, the real-time and test options,
/// the command line for the report.  Throws TwindConfigError.
void checkTwindRun(const TwindCommandLine& cl, const std::string& shaft_url, int argc, char** argv,
                   DaemonOptions& opt);

}  // namespace hoist::service::app
