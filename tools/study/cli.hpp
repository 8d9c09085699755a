// cli.hpp -- hoist-study's command line: the options every subcommand shares,
// value parsing, and the configuration and profile they name.
#pragma once

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hoist/params.hpp"
#include "hoist/profile.hpp"
#include "hoist/study/runner.hpp"

namespace hoist::study::cli {

/// A usage or configuration error: exit status 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Common {
  std::string out_dir = "study-out";
  std::string config;
  std::string profile;
  int modes = 0;
  double dt = 0.01;
  double max_step = kDefaultMaxStep;
  std::string initial = "config";  // as hoist-sim: model.initial unless given
  std::string static_correction;  // "" -> off for the paper's studies, config (default on) for sweep/advise
  int jobs = 0;
  bool no_plots = false;
};

/// "%g" (or `f`) of v.
std::string fmtg(double v, const char* f = "%g");

/// Readable replacements for CLI::PositiveNumber / NonNegativeNumber (whose
/// messages print DBL_MAX).
CLI::Validator numberAbove(double lo, bool inclusive);
/// The options of Common on a subcommand (`paper`: one of the paper's studies, whose --static-correction default is off).
void addCommon(CLI::App* sub, Common& c, bool advisor, bool paper);
/// "1,2,3" or "start:stop:count" (evenly spaced, count >= 2).  Throws UsageError.
std::vector<double> parseValues(const std::string& s);
/// "MIN:MAX" for option `opt`.  Throws UsageError.
std::pair<double, double> parseRange(const std::string& opt, const std::string& s);

/// The shaft of --config (the paper's by default) with --modes/--initial applied.
ShaftParams loadParams(const Common& c);
/// The profile of --profile (the paper's trapezoid by default).
HoistProfile loadProfile(const Common& c, const ShaftParams& p);
/// Rows a run's trace holds in memory (all runs' traces are kept until the
/// study is written): at most kMaxRunRows per run, kMaxStudyRows in all.
inline constexpr double kMaxRunRows = 1e7;     // 12 doubles a row: about 1 GB
inline constexpr double kMaxStudyRows = 2e7;   // about 2 GB for a whole study
/// Throws UsageError naming --dt (and --values when `runs` > 1) when the
/// traces of `runs` runs of `profile` at --dt would exceed those limits.
void checkTraceSize(const Common& c, const HoistProfile& profile, std::size_t runs);
/// Simulation options of --dt/--max-step for `p`.
RunOptions runOptions(const Common& c, const ShaftParams& p);

}  // namespace hoist::study::cli
