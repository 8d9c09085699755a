// hoist-study -- the paper's Section 3 studies (Figs. 2-13) in one command,
// any parameter sweep, and the preload advisor.  A thin shell around the
// hoist_study library: options, files, gnuplot, progress.
//
//   hoist-study NAME [--out-dir DIR] [--config FILE] [--profile FILE|SPEC]
//                    [--modes N] [--dt S] [--max-step S] [--initial static|rest|config]
//                    [--static-correction on|off] [--jobs N] [--no-plots]
//   NAME: response | preload | tension-difference | eccentric-load | mass | all
//         | sweep --param KEY --values V1,V2,... | advise --clearance M ...
//
// Exit status: 0 success, 1 a run failed or a file could not be written,
// 2 usage or configuration error, 3 (advise) target infeasible in the range.
#include "hoist/version.hpp"
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "advise.hpp"
#include "cli.hpp"
#include "hoist/study/studies.hpp"
#include "hoist/study/parameters.hpp"
#include "output.hpp"
#include "plots.hpp"
#include "run_study.hpp"

using namespace hoist;
using namespace hoist::study;
using namespace hoist::study::cli;

int main(int argc, char** argv) {
  CLI::App app{
      "hoist-study: the studies of Wang et al. (2016), Section 3 (Figs. 2-13), parameter sweeps and\n"
      "a guide-rope preload advisor, on the hoist-twin model.  Each study writes one CSV per run\n"
      "(t,l,v,a,x_c,y_c,theta,lambda_0..4), a summary.csv of per-run metrics (peaks, RMS, dominant\n"
      "frequencies of y_c/theta/lambda_1 in the uniform-velocity and deceleration/rest stages) and\n"
      "PNG figures rendered by gnuplot (with the .gp script next to each PNG).\n"
      "Exit status: 0 ok, 1 run or file failure, 2 usage/config error, 3 advise: infeasible."};
  app.name("hoist-study");  // usage lines name the program, not the path it was run by
  app.failure_message([](const CLI::App* a, const CLI::Error& e) { return a->get_name() + ": " + CLI::FailureMessage::simple(a, e); });  // errors name the program
  app.set_version_flag("--version", std::string("hoist-study ") + hoist::kVersionString);
  app.require_subcommand(1, 1);
  app.fallthrough(false);
  Common c;
  std::vector<std::pair<CLI::App*, std::string>> studies;
  for (const auto& [name, help] : std::vector<std::pair<std::string, std::string>>{
           {"response", "baseline run: Figs. 2 (profile), 3 (x_c, y_c, theta), 4 (guide-rope shapes at 18/36/60 s), 5 (lambda_1..4)"},
           {"preload", "total preload 4.8e4/5.4e4/6e4 N, Tb1 = Tb2: Figs. 6-7"},
           {"tension-difference", "Tb1 + Tb2 = 6e4 N, dT = Tb2 - Tb1 = 0/5000/10000 N: Figs. 8-9"},
           {"eccentric-load", "Fa = 1000/2000/3000 N: Figs. 10-11"},
           {"mass", "(m, J) = (800, 870), (1200, 1305), (1600, 1740): Figs. 12-13"},
           {"all", "all of the paper's studies (response, preload, tension-difference, eccentric-load, mass)"}}) {
    auto* sub = app.add_subcommand(name, help);
    addCommon(sub, c, false, true);
    studies.emplace_back(sub, name);
  }
  std::string key, values;
  auto* sweep = app.add_subcommand("sweep", "sweep one config key over values (same outputs as a paper study)");
  sweep->add_option("--param", key, "Dotted config key, one of:\n" + parameterHelp())->required();
  sweep->add_option("--values", values, "Comma-separated values, or START:STOP:COUNT")->required();
  addCommon(sweep, c, false, false);
  AdviseArgs aa;
  auto* advise = app.add_subcommand(
      "advise",
      "preload advisor: smallest total preload Tb1 + Tb2 and best split keeping the cage's peak lateral\n"
      "excursion max|y_c -+ h theta| within --clearance (and peak |lambda_1..4| within --max-sleeve-force)");
  advise->add_option("--clearance", aa.clearance, "Allowed peak lateral excursion of the cage [m]")
      ->required()
      ->check(numberAbove(0, false));
  advise->add_option("--max-sleeve-force", aa.max_force, "Allowed peak sleeve force |lambda_1..4| [N]")
      ->check(numberAbove(0, false));
  advise->add_option("--split-range", aa.split_range, "Range of Tb1 / (Tb1 + Tb2) searched")->capture_default_str();
  advise->add_option("--total-range", aa.total_range, "Range of Tb1 + Tb2 searched [N]")->capture_default_str();
  advise->add_option("--samples", aa.samples, "Log-spaced totals sampled (curve, monotonicity check)")
      ->capture_default_str()
      ->check(CLI::Range(2, 200));
  addCommon(advise, c, true, false);

  // CLI11 says "A subcommand is required" for an unknown one: name it and the known ones.
  auto known = [&app](const char* name) {
    try {
      return app.get_subcommand(name) != nullptr;
    } catch (const CLI::OptionNotFound&) {
      return false;
    }
  };
  if (argc > 1 && argv[1][0] != '-' && !known(argv[1])) {
    std::fprintf(stderr, "hoist-study: unknown subcommand '%s': the first argument is the study: response, preload, "
                         "tension-difference, eccentric-load, mass, all, sweep or advise (see --help)\n",
                 argv[1]);
    return 2;
  }
  // CLI11 says "A subcommand is required" before naming an unknown option.
  if (argc > 1 && argv[1][0] == '-') {
    const std::string a = argv[1];
    if (a != "-h" && a != "--help" && a != "--version") {
      std::fprintf(stderr, "hoist-study: unknown option '%s' (the first argument is the study: response, preload, "
                           "tension-difference, eccentric-load, mass, all, sweep or advise; see --help)\n", a.c_str());
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  // The paper's studies reproduce its figures: the paper's truncation unless asked otherwise.
  if (c.static_correction.empty() && !advise->parsed() && !sweep->parsed()) c.static_correction = "off";
  PlotState ps;
  ps.enabled = !c.no_plots;
  ps.gnuplot = ps.enabled ? out::findGnuplot() : "";
  try {
    const ShaftParams base = loadParams(c);
    const HoistProfile profile = loadProfile(c, base);
    if (advise->parsed()) {
      checkTraceSize(c, profile, 1);
      const int rc = runAdvisor(aa, c, base, profile, ps);
      reportPlots(ps);
      return rc;
    }
    std::vector<Study> todo;
    if (sweep->parsed()) {
      try {
        todo.push_back(sweepStudy(key, parseValues(values), base));
      } catch (const ParamError& e) {
        throw UsageError(std::string("--param/--values: ") + e.what());
      }
    } else {
      for (const auto& [sub, name] : studies) {
        if (!sub->parsed()) continue;
        if (name == "all") {
          for (const auto& n : paperStudyNames()) todo.push_back(*paperStudy(n, base));
        } else {
          todo.push_back(*paperStudy(name, base));
        }
      }
    }
    std::size_t runs = 0;
    for (const auto& s : todo) runs = std::max(runs, s.runs.size());  // one study's traces at a time
    checkTraceSize(c, profile, runs);
    int rc = 0;
    for (const auto& s : todo) rc = std::max(rc, runStudy(s, c, base, profile, ps));
    reportPlots(ps);
    return rc;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "hoist-study: error: %s\n", e.what());
    return 2;
  } catch (const ParamError& e) {
    std::fprintf(stderr, "hoist-study: error: invalid parameter %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hoist-study: error: %s\n", e.what());
    return 1;
  }
}
