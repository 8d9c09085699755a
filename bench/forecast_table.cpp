// The look-ahead forecasts along the paper's trip on the demo shaft
// (service/config/demo.toml: the paper's shaft, gaps 16/16/30 mm, WARNING
// at 0.6 and CRITICAL at 0.9 of a gap), printed as the Markdown table of
// docs/lookahead.md: every `--every` seconds, the "estop" (3 m/s^2, 10 m/s^3)
// and "continue" (trip plan: 300 m, 5 m/s, 1 m/s^2, 1 m/s^3 jerk... the
// paper trip is a trapezoid, so the plan's S-curve differs from it) forecasts
// over a 20-s horizon.
//
//   build/bin/hoist-forecast-table [n] [every_s]
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "hoist/version.hpp"

#include "hoist/forecast.hpp"
#include "hoist/scenario.hpp"
#include "hoist/simulator.hpp"

using namespace hoist;

namespace {

const char* kUsage =
    "usage: hoist-forecast-table [N] [EVERY_S]\n"
    "The look-ahead forecasts along the paper's trip on the demo shaft, as the Markdown table of\n"
    "docs/lookahead.md.\n"
    "  N        assumed modes per rope, 1..1000 (default 50)\n"
    "  EVERY_S  seconds between forecasts along the trip, > 0 (default 5)\n"
    "  --help   this text;  --version  the version\n"
    "Exit status: 0 ok, 2 bad usage.\n";

int usageError(const std::string& what) {
  std::fprintf(stderr, "hoist-forecast-table: %s\n%s", what.c_str(), kUsage);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  ShaftParams p;
  p.n = 50;
  double every = 5.0;
  int positional = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (a == "--version") {
      std::printf("hoist-forecast-table %s\n", hoist::kVersionString);
      return 0;
    }
    char* end = nullptr;
    errno = 0;
    if (positional == 0) {
      const long n = std::strtol(a.c_str(), &end, 10);
      if (a.empty() || *end != '\0' || errno != 0) {
        if (a.size() > 1 && a[0] == '-' && !std::isdigit(static_cast<unsigned char>(a[1])))
          return usageError("unknown option '" + a + "'");
        return usageError("N: '" + a + "' is not an integer");
      }
      if (n < 1 || n > kMaxModes) return usageError("N: must be in 1..1000 (got " + a + ")");
      p.n = static_cast<int>(n);
    } else if (positional == 1) {
      every = std::strtod(a.c_str(), &end);
      if (a.empty() || *end != '\0' || errno != 0) {
        if (a.size() > 1 && a[0] == '-' && !std::isdigit(static_cast<unsigned char>(a[1])) && a[1] != '.')
          return usageError("unknown option '" + a + "'");
        return usageError("EVERY_S: '" + a + "' is not a number");
      }
      if (!(every > 0.0) || !std::isfinite(every)) return usageError("EVERY_S: must be > 0 (got " + a + ")");
    } else {
      if (a.size() > 1 && a[0] == '-') return usageError("unknown option '" + a + "'");
      return usageError("unexpected argument '" + a + "'");
    }
    ++positional;
  }
  auto model = std::make_shared<const ShaftModel>(p);
  ForecastOptions o;
  o.horizon = 20.0;
  o.limits = ClearanceLimits{0.016, 0.016, 0.030, 0.6, 0.9};
  ForecastWorkspace ws(model, o);
  const HoistProfile trip = HoistProfile::trapezoid();
  const double static_force = p.m * p.g + p.Fa;  // lambda_0 at rest (cage + eccentric load)
  std::printf("| t0 [s] | l, v, a | estop: lambda_0 min / max [N] | estop: slack margin | estop: min clear. [mm] at [s] | "
              "estop: WARN / CRIT [s] | continue: min clear. [mm] at [s] | continue: WARN / CRIT [s] |\n");
  std::printf("|---:|---|---|---:|---|---|---|---|\n");
  FastSolver s(model);
  FastSolverState st(p.n);
  ForecastSummary e, c;
  MotionProfile plan;
  for (double t0 = 0.0; t0 <= 55.0 + 1e-9; t0 += every) {
    SimulationOptions so;
    so.dt = o.dt;
    so.max_step = o.max_step;
    so.t_end = t0 > 0 ? t0 : 1e-9;
    if (t0 > 0) simulate(s, trip, so, {});
    else s.initialize(0.0, trip.at(0.0));
    s.saveState(st);
    forecast(ws, st, estopProfile(st.t, st.kin, 3.0, 10.0), e);
    const PlanCheck pc = planProfile(st.t, st.kin, TripPlan{300.0, 5.0, 1.0, 1.0}, p.maxRopeLength(), plan);
    if (pc.ok()) forecast(ws, st, plan, c);
    else forecast(ws, st, continueProfile(st.t, st.kin, 5.0, 1.0, p.maxRopeLength()), c);
    std::printf("| %.0f | %.1f m, %.1f m/s, %.1f m/s^2 | %.0f / %.0f | %.3f | %.2f at %.2f | %.2f / %.2f | %.2f at %.2f%s | "
                "%.2f / %.2f |\n",
                t0, st.kin.l, st.kin.v, st.kin.a, e.lambda0_min, e.lambda0_max, e.lambda0_min / static_force,
                e.min_clearance * 1e3, e.t_min_clearance, e.t_warning, e.t_critical, c.min_clearance * 1e3,
                c.t_min_clearance, pc.ok() ? "" : " (no plan)", c.t_warning, c.t_critical);
  }
  return 0;
}
