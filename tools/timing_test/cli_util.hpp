// cli_util.hpp -- small command-line helpers shared by hoist-replay and
// hoist-timing-test (the parse itself: hoist/cli/app.hpp, every program's).
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace hoist::replay {

/// The command line as typed (arguments quoted for a shell where needed).
inline std::string commandLine(int argc, char** argv) {
  std::string out;
  for (int i = 0; i < argc; ++i) {
    std::string a = argv[i];
    if (i == 0) {
      const auto slash = a.rfind('/');
      if (slash != std::string::npos) a = a.substr(slash + 1);
    }
    const bool plain = !a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                         "0123456789-_./:=,+@%") == std::string::npos;
    if (!out.empty()) out += ' ';
    if (plain) {
      out += a;
    } else {
      out += '\'';
      for (char c : a) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
      out += '\'';
    }
  }
  return out;
}

/// A number check whose message reads well: "--opt: must be >= 0 (got -1)".
inline CLI::Validator numberIn(double lo, double hi, bool lo_open, const std::string& what) {
  return CLI::Validator(
      [=](std::string& in) -> std::string {
        double x = 0.0;
        std::size_t used = 0;
        try {
          x = std::stod(in, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != in.size() || in.empty() || !std::isfinite(x)) return "not a number: '" + in + "'";
        if ((lo_open ? !(x > lo) : !(x >= lo)) || !(x <= hi)) return "must be " + what + " (got " + in + ")";
        return std::string();
      },
      "NUMBER");
}

}  // namespace hoist::replay
