// hoist/cli/app.hpp -- the command-line preamble every hoist program shares
// (CLI11), so that each program behaves alike:
//   * usage lines and error messages name the program ("hoist-sim: ..."),
//     not the path it was run by;
//   * --version prints "<program> <project version>" (with the commit when
//     built from a git checkout: hoist/version.hpp);
//   * --help and --version exit 0; a usage error exits 2 after CLI11 printed
//     the message naming the option (the project's rule: exit 2 = bad input).
// Called by every program's main, hoist-twind's too (header only; the target hoist_cli links
// CLI11 and the version header).  Nothing here outlives the call.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "hoist/version.hpp"

namespace hoist::cli {

/// Name `app` after `program` (usage lines, errors) and add --version.
inline void nameProgram(CLI::App& app, const std::string& program) {
  app.name(program);
  app.failure_message([](const CLI::App* a, const CLI::Error& e) {
    return a->get_name() + ": " + CLI::FailureMessage::simple(a, e);
  });
  app.set_version_flag("--version", program + " " + hoist::kVersionString);
}

/// Parse the command line.  Returns the exit status when the program should
/// stop now (0 after --help or --version, 2 after a usage error, CLI11 having
/// printed the text), std::nullopt when it should go on.
inline std::optional<int> parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return std::nullopt;
}

}  // namespace hoist::cli
