// python/src/run.hpp -- one simulation run of the Python module, without
// Python: hoist-sim's run (hoist/io/sim_run.hpp, hoist::simulate) with the
// rows kept in column vectors instead of a CSV.  Called by simulate_py.cpp
// from worker threads with the GIL released: it touches no Python object.
// Thread-safe (each call owns its solver; the inputs are read only).
#pragma once

#include <array>
#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

#include "hoist/io/sim_run.hpp"
#include "hoist/params.hpp"
#include "hoist/profile.hpp"

namespace hoist::python {

/// hoist-sim's CSV columns, in its order (hoist/io/results.hpp kResultHeader).
inline constexpr std::array<const char*, 12> kResultColumns = {
    "t", "l", "v", "a", "x_c", "y_c", "theta", "lambda_0", "lambda_1", "lambda_2", "lambda_3", "lambda_4"};
/// hoist-sim's shape CSV columns (kShapeHeader).
inline constexpr std::array<const char*, 4> kShapeColumns = {"t", "x", "y1", "y2"};

/// Where the profile comes from: hoist-sim's --profile argument (a CSV path
/// or a SPEC), or arrays t, v, a[, l] given as a CSV text read by the same
/// reader (same checks, same l integration).
struct ProfileSource {
  std::string arg;       ///< --profile (when csv_text is empty)
  std::string csv_text;  ///< the arrays as CSV
  std::string name() const { return csv_text.empty() ? arg : std::string("<profile arrays>"); }
  HoistProfile load(double l0) const;
};

struct RunSpec {
  ShaftParams params;          ///< the configuration's shaft (before the options)
  io::SimRunOptions options;   ///< hoist-sim's options
  std::vector<double> shape_times;  ///< --shape-times (empty: no shapes)
  int shape_points = 401;           ///< --shape-points
  bool estop = false;               ///< --estop-at given
  double estop_at = 0.0, estop_decel = 3.0, estop_jerk = 10.0;  ///< --estop-at, --estop-decel, --estop-jerk
};

struct RunResult {
  std::array<std::vector<double>, 12> columns;  ///< kResultColumns
  std::array<std::vector<double>, 4> shapes;    ///< kShapeColumns
  ShaftParams params;                           ///< the shaft as run (options applied)
  int substeps = 1;
};

/// The run stopped because the state became non-finite or implausible
/// (hoist-sim's exit status 1; the message is hoist-sim's).
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The run was stopped through `cancel`.
struct Cancelled {};

/// One run.  `cancel` is polled every output step (throws Cancelled);
/// `steps` (optional) counts the output steps done.  Throws io::InputError
/// (config, profile), io::OptionError (options), RunError, std::exception.
RunResult runSimulation(const RunSpec& spec, const ProfileSource& profile, const std::atomic<bool>& cancel,
                        std::atomic<long>* steps = nullptr);

/// The output rows a run of `spec` on `profile` will have (for progress).
long expectedRows(const RunSpec& spec, const ProfileSource& profile);

}  // namespace hoist::python
