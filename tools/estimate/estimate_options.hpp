// hoist-estimate's command line (tools/estimate/main.cpp: parse -> check ->
// run): the options, their CLI11 definitions and the usage error that
// names one.  The checks that need the files are in estimate_run.hpp.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace hoist::estimate {

struct Options {
  std::string config, measurements, out;
  int modes = 0;
  double max_step = -1.0;  ///< < 0: the config's [service] max_step, else hoist::kDefaultMaxStep
  bool progress = false, quiet = false, no_trips = false;
  std::vector<std::string> known_load;  ///< T0,T1,FA,B each
  std::string offset_in, offset_out;
};

/// A bad option or input value: exit status 2, the message names it.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Defines every option of hoist-estimate on `app`, writing into `o` (which
/// must outlive the parse).
void addOptions(CLI::App& app, Options& o);

/// printf-style formatting of one number (fmt("%.2f", v)), for the
/// messages, the help and the summary.
std::string fmt(const char* f, double v);

/// The first required option not given ("--config", ...), or nullopt.
/// Checked after parsing: CLI11 reports a missing option before an unknown
/// one, and an unknown option must be named.
std::optional<std::string> missingRequired(const Options& o);

}  // namespace hoist::estimate
