// The look-ahead forecasts along the paper's trip on the demo shaft
// (service/config/demo.toml: the paper's shaft, gaps 16/16/30 mm, WARNING
// at 0.6 and CRITICAL at 0.9 of a gap), printed as the Markdown table of
// docs/lookahead.md: every `--every` seconds, the "estop" (3 m/s^2, 10 m/s^3)
// and "continue" (trip plan: 300 m, 5 m/s, 1 m/s^2, 1 m/s^3 jerk... the
// paper trip is a trapezoid, so the plan's S-curve differs from it) forecasts
// over a 20-s horizon.
//
//   build/bin/hoist-forecast-table [n] [every_s]
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "hoist/forecast.hpp"
#include "hoist/scenario.hpp"
#include "hoist/simulator.hpp"

using namespace hoist;

int main(int argc, char** argv) {
  ShaftParams p;
  p.n = argc > 1 ? std::atoi(argv[1]) : 50;
  const double every = argc > 2 ? std::atof(argv[2]) : 5.0;
  if (p.n < 1 || p.n > kMaxModes || !(every > 0.0)) {
    std::fprintf(stderr, "usage: hoist-forecast-table [n 1..1000] [every_s > 0]\n");
    return 2;
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
