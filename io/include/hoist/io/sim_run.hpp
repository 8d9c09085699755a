// hoist/io/sim_run.hpp -- how hoist-sim's run options become a run: the
// shaft parameters with the option overrides applied, the end time, the
// in-shaft check of the part that is simulated, and the SimulationOptions.
// Called by hoist-sim (tools/sim) and by the Python module (python/), so
// that both turn the same options into the same numbers and the same errors.
// Pure functions of their arguments, no I/O; thread-safe.
#pragma once

#include <stdexcept>
#include <string>

#include "hoist/params.hpp"
#include "hoist/profile.hpp"
#include "hoist/scenario.hpp"
#include "hoist/simulator.hpp"

namespace hoist::io {

/// hoist-sim's options that change the run (not its files).  Empty strings
/// and negative/zero sentinels mean "as the configuration says".
struct SimRunOptions {
  double dt = 0.01;             ///< --dt, output step [s]
  double max_step = kDefaultMaxStep;  ///< --max-step [s], 0: integrate with dt
  double t_end = -1.0;          ///< --t-end [s], < 0: the profile's end
  double rho_inf = -1.0;        ///< --rho-inf, < 0: model.rho_inf
  int modes = 0;                ///< --modes, 0: model.modes
  std::string initial;          ///< --initial: "", "config", "static" or "rest"
  std::string method = "fast";  ///< --method: "fast" or "paper"
  std::string static_correction;  ///< --static-correction: "", "on" or "off"
};

/// A run option that cannot be honoured; what() starts with the option
/// ("--max-step: ...") or says "(from the command line)".
class OptionError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Apply the overrides of `o` to `p` (modes, initial, rho_inf, the method's
/// static correction) and validate the result.  Throws OptionError.
void applySimOverrides(ShaftParams& p, const SimRunOptions& o);

/// The run's end time: `t_end` (< 0: the profile's end).  Throws OptionError
/// ("--t-end ...") when it is not finite or not after the profile's start.
double simEndTime(const HoistProfile& profile, double t_end);

/// Throws ProfileError when the part of `profile` simulated up to `t_end`
/// (output step dt) leaves the shaft (checkProfileInShaft on that part).
void checkSimulatedPartInShaft(const HoistProfile& profile, const ShaftParams& p, double t_end, double dt,
                               const std::string& source);

/// hoist-sim --estop-at T: `profile` up to T (rounded to the nearest output
/// step dt, so the run equals the twin's e-stop forecast made at T), then the
/// forecast's "estop" scenario (hoist/scenario.hpp estopProfile: |a| builds up
/// at `jerk` to `decel` against the motion, holds, eases off; then rest),
/// sampled on the output grid up to max(t_end, the profile's end).  `stop`
/// (optional) receives the stop.  Throws OptionError ("--estop-at: ...",
/// "--estop-decel/--estop-jerk: ...").
HoistProfile estopRun(const HoistProfile& profile, double t_end, double estop_at, double decel, double jerk,
                      double dt, MotionProfile* stop = nullptr);

/// The simulator's options for this run; `substeps` receives the substeps
/// per output step.  Throws OptionError ("--max-step: ...").
SimulationOptions simulationOptions(const SimRunOptions& o, const ShaftParams& p, double t_end, int& substeps);

}  // namespace hoist::io
