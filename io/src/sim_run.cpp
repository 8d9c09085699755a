// hoist-sim's run options -> a run (hoist/io/sim_run.hpp).
#include "hoist/io/sim_run.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "hoist/io/profile.hpp"

namespace hoist::io {

namespace {
std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
}  // namespace

void applySimOverrides(ShaftParams& p, const SimRunOptions& o) {
  if (o.modes != 0) p.n = o.modes;
  if (!o.initial.empty() && o.initial != "config") p.initial = o.initial == "rest" ? InitialState::Rest : InitialState::Static;
  if (o.rho_inf >= 0.0) p.rho_inf = o.rho_inf;
  if (o.method == "paper") {
    // The paper's method is the paper's literal truncation.
    if (o.static_correction == "on")
      throw OptionError("--method paper has no static correction: use --static-correction off (or --method fast)");
    p.static_correction = false;
  } else if (!o.static_correction.empty()) {
    p.static_correction = o.static_correction == "on";
  }
  try {
    p.validate();
  } catch (const ParamError& e) {
    throw OptionError(std::string("invalid parameter (from the command line) ") + e.what());
  }
}

double simEndTime(const HoistProfile& profile, double t_end_opt) {
  const double t0 = profile.startTime();
  if (!std::isfinite(t_end_opt)) throw OptionError("--t-end " + num(t_end_opt) + ": must be a finite time in seconds");
  const double t_end = t_end_opt < 0 ? profile.endTime() : t_end_opt;
  if (!(t_end > t0))
    throw OptionError("--t-end " + num(t_end) + ": must be after the profile start (" + num(t0) + " s)");
  return t_end;
}

void checkSimulatedPartInShaft(const HoistProfile& profile, const ShaftParams& p, double t_end, double dt,
                               const std::string& source) {
  // Only the part that will be simulated must stay in the shaft.
  if (t_end + dt >= profile.endTime()) {
    checkProfileInShaft(profile, p, source);
    return;
  }
  std::vector<ProfileSample> part;
  for (const auto& s : profile.samples())
    if (s.t <= t_end + dt) part.push_back(s);
  if (part.size() >= 2) checkProfileInShaft(HoistProfile(part), p, source);
  else checkProfileInShaft(profile, p, source);
}

HoistProfile estopRun(const HoistProfile& profile, double t_end, double estop_at, double decel, double jerk,
                      double dt, MotionProfile* stop_out) {
  const double p_end = t_end < 0 ? profile.endTime() : t_end;
  if (!std::isfinite(estop_at) || estop_at < profile.startTime() || estop_at >= p_end)
    throw OptionError("--estop-at: " + std::to_string(estop_at) + " s is outside the run [" +
                      std::to_string(profile.startTime()) + ", " + std::to_string(p_end) + ") s");
  const double T = profile.startTime() + std::round((estop_at - profile.startTime()) / dt) * dt;
  MotionProfile stop;
  try {
    stop = estopProfile(T, profile.at(T), decel, jerk);
  } catch (const std::invalid_argument& e) {
    throw OptionError(std::string("--estop-decel/--estop-jerk: ") + e.what());
  }
  if (stop_out) *stop_out = stop;
  return spliceProfile(profile, T, stop, dt, std::max(p_end, profile.endTime()));
}

SimulationOptions simulationOptions(const SimRunOptions& o, const ShaftParams& p, double t_end, int& substeps) {
  SimulationOptions sim;
  sim.dt = o.dt;
  sim.max_step = o.max_step;
  sim.t_end = t_end;
  sim.method = o.method == "paper" ? Method::Paper : Method::Fast;
  sim.initial = p.initial;
  try {
    substeps = substepsFor(sim);
  } catch (const std::exception& e) {
    throw OptionError(std::string("--max-step: ") + e.what());
  }
  return sim;
}

}  // namespace hoist::io
