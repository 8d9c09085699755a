// The timing test's command line: see timing_cli.hpp.
#include "hoist/version.hpp"
#include "timing_cli.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <iostream>

#include <tuple>

#include "cli_util.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/daemon_shaft.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "timing_test.hpp"

namespace hoist::replay {

namespace {

const char* kTimingHelp = R"(
Timing test: how a user checks a deployment machine.
  hoist-twind --rate 1000 & hoist-timing-test --rate 1000 --duration 600 --max-late-p99-us 200 --report timing.md
Feeds the RUNNING hoist-twind at --rate Hz (1..1000, default 100) for --duration s (default 60) with
the paper's trapezoid trip down and back up again, repeated, with the encoder length (the cage moves
the whole time; seq contiguous from 0, utime = wall clock), and listens to its HOIST_HEALTH and
HOIST_CAGE on the same --lcm-url (or --lcm-url-out, the daemon's lcm_url_out) and channel prefix.  Measured: deadline misses, tick lateness p99
(worst window) and max, model step time p99/max (from HOIST_HEALTH, as deltas over the test),
rejected and lost inputs, model faults, degraded outputs; the end-to-end latency input -> first
HOIST_CAGE answering it (input_seq) p50/p99/p99.9/max; the feeder's own lateness.  Budgets:
--max-misses (default 0), --max-rejected (default 0), --max-late-p99-us, --max-late-max-us,
--max-step-p99-us, --max-e2e-p99-us (unchecked unless given).  Several shafts: repeat
--channel-prefix, or --shafts N for shaft1/ .. shaftN/ (one input per shaft per period; misses and
counts summed, latencies worst case).  Prints a Markdown summary (--report FILE writes it too; its
first line is VERDICT: PASS|FAIL|INCONCLUSIVE); progress once a second on a terminal (not with -q).
Exit status: 0 PASS; 1 FAIL, or INCONCLUSIVE when the feeder itself was late (p99 over one period) and
only budgets a late feeder can explain were violated (a step-time budget, a restart or a stall of the
daemon is FAIL regardless), or no HOIST_HEALTH within --health-timeout (default 5 s); 2 bad options;
128+signal after Ctrl-C (the shortened run is still reported).  --config takes hoist-twind's whole
file; only its shaft is used (the other sections are ignored, said once on stderr).
)";

}  // namespace

const std::vector<std::string>& timingOnlyOptions() {
  static const std::vector<std::string> o = {"--duration",        "--shafts",           "--max-late-p99-us",
                                             "--max-late-max-us", "--max-misses",       "--max-step-p99-us",
                                             "--max-e2e-p99-us",  "--max-rejected",     "--report",
                                             "--lcm-url-out",     "--health-timeout"};
  return o;
}

int timingTestMain(int argc, char** argv, const std::string& program) {
  CLI::App app{program +
               ": a soft-real-time check of a RUNNING hoist-twind (a deployment machine): feeds it at --rate\n"
               "for --duration, listens to its HOIST_HEALTH and HOIST_CAGE, and judges deadline misses, tick\n"
               "lateness, step time, end-to-end latency and rejected inputs against budgets (see the end)."};
  app.footer(kTimingHelp);
  app.name(program);
  app.failure_message([](const CLI::App* a, const CLI::Error& e) { return a->get_name() + ": " + CLI::FailureMessage::simple(a, e); });  // errors name the program
  app.set_version_flag("--version", program + " " + hoist::kVersionString);
  std::string url, config_path, report_path;
  std::vector<std::string> prefixes;
  double rate = 100.0, duration = 60.0, health_timeout = 5.0;
  bool quiet = false;
  int shafts = 0;
  Budgets budgets;
  double b_late_p99 = 0, b_late_max = 0, b_step_p99 = 0, b_e2e_p99 = 0;
  app.add_option("--rate", rate, "inputs per second per shaft (default 100)")
      ->check(numberIn(1.0, 1000.0, false, "in [1, 1000] Hz"));
  app.add_option("--lcm-url", url, "LCM URL; default: $LCM_DEFAULT_URL, else LCM's default");
  std::string url_out;
  app.add_option("--lcm-url-out", url_out,
                 "where the daemon publishes (its [service] lcm_url_out): HOIST_HEALTH and HOIST_CAGE are read "
                 "there; default: --lcm-url");
  auto* prefix_opt = app.add_option("--channel-prefix", prefixes,
                                    "prepended to HOIST_WINDER, HOIST_HEALTH, HOIST_CAGE; repeat it to test "
                                    "several shafts")
                         ->allow_extra_args(false);
  app.add_option("--config", config_path,
                 "shaft TOML: the test trip starts at hoisting_rope.initial_length and fits the shaft")
      ->check(CLI::ExistingFile);
  app.add_flag("-q,--quiet", quiet, "no progress display");
  app.add_option("--duration", duration, "how long to feed [s] (default 60)")
      ->check(numberIn(0.0, 7 * 86400.0, true, "> 0 and at most 604800 s"));
  app.add_option("--health-timeout", health_timeout,
                 "how long to wait for every shaft's first HOIST_HEALTH before feeding [s] (default 5)")
      ->check(numberIn(0.0, 3600.0, true, "> 0 and at most 3600 s"));
  app.add_option("--shafts", shafts, "shafts with prefixes shaft1/ .. shaftN/ (1..1000)")
      ->check(numberIn(1, 1000, false, "in [1, 1000]"))
      ->excludes(prefix_opt);
  auto budget = [&](const char* name, auto& var, const char* what) {
    return app.add_option(name, var, what)->check(numberIn(0.0, 1e300, false, ">= 0"));
  };
  budget("--max-late-p99-us", b_late_p99, "budget: tick lateness p99, worst HOIST_HEALTH window [us]");
  budget("--max-late-max-us", b_late_max, "budget: largest tick lateness [us]");
  budget("--max-misses", budgets.max_misses, "budget: deadline misses, summed over shafts (default 0)");
  budget("--max-step-p99-us", b_step_p99, "budget: model step time p99, worst HOIST_HEALTH window [us]");
  budget("--max-e2e-p99-us", b_e2e_p99, "budget: end-to-end latency p99, input publish -> cage output received [us]");
  budget("--max-rejected", budgets.max_rejected, "budget: inputs rejected by the daemon (default 0)");
  app.add_option("--report", report_path, "also write the Markdown report to FILE");
  if (const auto rc = parseCommandLine(app, argc, argv)) return *rc;
  for (const auto& [opt, given, value, resolved] :
       {std::tuple{"--lcm-url", app.count("--lcm-url") > 0, url, hoist::bus::resolveLcmUrl(url)},
        std::tuple{"--lcm-url-out", app.count("--lcm-url-out") > 0, url_out, url_out}})
    if (const std::string bad = hoist::bus::lcmUrlUsageError(program, given, value, resolved, opt); !bad.empty()) {
      std::cerr << bad << "\n";
      return 2;
    }
  url = hoist::bus::resolveLcmUrl(url);

  TimingTestOptions o;
  if (!(rate >= 1.0 && rate <= 1000.0)) {
    std::cerr << program << ": --rate: must be in [1, 1000] Hz (got " << rate << ")\n";
    return 2;
  }
  o.rate = rate;
  o.duration = duration;
  o.health_timeout = health_timeout;
  if (shafts > 0) {
    o.prefixes.clear();
    for (int i = 1; i <= shafts; ++i) o.prefixes.push_back("shaft" + std::to_string(i) + "/");
  } else if (!prefixes.empty()) {
    o.prefixes = prefixes;
  }
  for (std::size_t i = 0; i < o.prefixes.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (o.prefixes[i] == o.prefixes[j]) {
        std::cerr << program << ": --channel-prefix: '" << o.prefixes[i] << "' given twice\n";
        return 2;
      }
  if (app.count("--max-late-p99-us")) budgets.late_p99_us = b_late_p99;
  if (app.count("--max-late-max-us")) budgets.late_max_us = b_late_max;
  if (app.count("--max-step-p99-us")) budgets.step_p99_us = b_step_p99;
  if (app.count("--max-e2e-p99-us")) budgets.e2e_p99_us = b_e2e_p99;
  o.budgets = budgets;
  o.report_path = report_path;
  o.lcm_url = url;
  o.lcm_url_out = url_out;
  {
    // As typed: the alias shows "hoist-replay --timing-test ...".
    const std::string typed = commandLine(argc, argv);
    const auto sp = typed.find(' ');
    o.command = program + (sp == std::string::npos ? std::string() : typed.substr(sp));
  }
  o.quiet = quiet;
  o.progress = !quiet && isatty(STDERR_FILENO);
  if (!config_path.empty()) {
    // The trip must fit the daemon's shaft: from initial_length, at most
    // 250 m, staying 10 % clear of the bottom (else upward).
    try {
      // hoist-twind's whole file is accepted; only the shaft is used here.
      std::string note;
      const hoist::ShaftParams p = hoist::io::loadDaemonShaft(config_path, program, &note);
      if (!note.empty() && !quiet) std::cerr << note << "\n";
      o.l0 = p.l0;
      const double lmax = p.L - 2.0 * p.h;
      const double down = 0.9 * lmax - p.l0, up = p.l0 - 0.1 * lmax;
      o.travel = down >= up ? std::min(250.0, down) : -std::min(250.0, up);
      if (!(std::fabs(o.travel) >= 1.0)) {
        std::cerr << program << ": --config: the shaft leaves no room for a test trip from initial_length\n";
        return 2;
      }
    } catch (const std::exception& e) {
      std::cerr << program << ": " << e.what() << "\n";
      return 2;
    }
  }
  return runTimingTest(o);
}

}  // namespace hoist::replay
