// hoist-sim's options: the parsed command line (Options), the CLI11
// definitions of every option with its help and range (addOptions), and the
// parsers of the list-valued ones (--shape-times, --sensor-noise), which
// throw UsageError naming the option.  Called by main.cpp (parse) and
// sim_run.cpp (check and run); see main.cpp for the program's contract.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "hoist/load_estimator.hpp"
#include "hoist/simulator.hpp"

namespace hoist::sim {

struct Options {
  std::string config, profile = "paper", out, shape_out, shape_times = "18,36,60", write_profile;
  double dt = 0.01, max_step = hoist::kDefaultMaxStep, t_end = -1.0, rho_inf = -1.0;
  double estop_at = std::nan(""), estop_decel = 3.0, estop_jerk = 10.0;
  int modes = 0, shape_points = 401;
  std::string initial, method = "fast", static_correction;
  bool quiet = false, print_config = false, progress = false;
  // --write-measurements (synthetic sensor data for hoist-estimate)
  std::string write_measurements, sensor_noise;
  std::uint64_t seed = 1;
};

/// Bad input found after parsing (exit status 2).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Every option of hoist-sim on `app`, stored into `o` (which must outlive
/// the parse).
void addOptions(CLI::App& app, Options& o);

/// --shape-times: comma-separated finite seconds, sorted; UsageError otherwise.
std::vector<double> parseTimes(const std::string& s);
/// --sensor-noise A,W,F: three finite standard deviations >= 0; UsageError otherwise.
SensorNoise parseSensorNoise(const std::string& s);

}  // namespace hoist::sim
