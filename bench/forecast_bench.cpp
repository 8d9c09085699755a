// Cost of one look-ahead forecast: one scenario integrated over a 20-s
// horizon from the paper trip's state at t = 20 s, exact (output step
// 0.01 s, 2.5-ms substeps, 401-point guide-rope envelope per output step)
// or economical (economicalForecast: the daemon's default).  The counter `ms_per_horizon_s` is the figure
// docs/lookahead.md reports: milliseconds of CPU per scenario per second of
// horizon.
//
//   build/bin/hoist-forecast-bench
//   build/bin/hoist-forecast-bench --benchmark_filter=Estop/50
//   build/bin/hoist-forecast-bench --benchmark_filter='/25/25/'   (exact vs economical at n = 25)
#include <benchmark/benchmark.h>

#include "bench_main.hpp"

#include <memory>

#include <cstdio>
#include <string>

#include "hoist/forecast.hpp"
#include "hoist/scenario.hpp"
#include "hoist/simulator.hpp"

namespace {

using namespace hoist;

enum class Kind { Estop, Continue, Plan };

void forecastBench(benchmark::State& state, Kind kind) {
  ShaftParams p;
  p.n = static_cast<int>(state.range(0));
  auto model = std::make_shared<const ShaftModel>(p);
  ForecastOptions o;
  o.horizon = 20.0;
  o.max_step = static_cast<double>(state.range(1)) * 1e-4;  // 25 -> 2.5 ms
  FastSolver s(model);
  SimulationOptions so;
  so.dt = o.dt;
  so.max_step = o.max_step;
  so.t_end = 20.0;
  simulate(s, HoistProfile::trapezoid(), so, {});
  FastSolverState st(p.n);
  s.saveState(st);
  // Third argument 1: the economical forecast (the daemon's default,
  // [forecast] exact = false) from the same snapshot.
  const bool economical = state.range(2) != 0;
  ForecastWorkspace ws(model, economical ? economicalForecast(o, p.n) : o);
  ForecastSummary out;
  for (auto _ : state) {
    MotionProfile sc;
    switch (kind) {
      case Kind::Estop: sc = estopProfile(st.t, st.kin, 3.0, 10.0); break;
      case Kind::Continue: sc = continueProfile(st.t, st.kin, 5.0, 1.0, p.maxRopeLength()); break;
      case Kind::Plan: planProfile(st.t, st.kin, TripPlan{300.0, 5.0, 1.0, 1.0}, p.maxRopeLength(), sc); break;
    }
    forecast(ws, st, sc, out);
    benchmark::DoNotOptimize(out.min_clearance);
  }
  state.counters["n"] = p.n;
  state.counters["modes"] = ws.forecastModes();
  state.counters["steps"] = static_cast<double>(ws.steps() * ws.substeps());
  // seconds per (scenario x horizon second), shown in ms by the factor.
  state.counters["ms_per_horizon_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * o.horizon / 1e3,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

/// The daemon's work per shaft and forecast instant: both scenarios (estop,
/// continue along the plan) from one snapshot, the snapshots alternating
/// between two instants (t = 20 s and 20.01 s) so that every pair starts
/// from a new state (the economical forecast projects it once per pair).
/// CPU time per iteration = CPU per second per shaft at [forecast] rate 1 Hz.
void BM_ForecastPair(benchmark::State& state) {
  ShaftParams p;
  p.n = static_cast<int>(state.range(0));
  auto model = std::make_shared<const ShaftModel>(p);
  ForecastOptions o;
  o.horizon = 20.0;
  FastSolver s(model);
  SimulationOptions so;
  so.dt = o.dt;
  so.max_step = o.max_step;
  so.t_end = 20.0;
  simulate(s, HoistProfile::trapezoid(), so, {});
  FastSolverState st[2] = {FastSolverState(p.n), FastSolverState(p.n)};
  s.saveState(st[0]);
  s.step(20.01, HoistProfile::trapezoid().at(20.01));
  s.saveState(st[1]);
  const bool economical = state.range(1) != 0;
  ForecastWorkspace ws(model, economical ? economicalForecast(o, p.n) : o);
  ForecastSummary e, c;
  MotionProfile plan;
  long i = 0;
  for (auto _ : state) {
    const FastSolverState& x = st[i++ & 1];
    forecast(ws, x, estopProfile(x.t, x.kin, 3.0, 10.0), e);
    planProfile(x.t, x.kin, TripPlan{300.0, 5.0, 1.0, 1.0}, p.maxRopeLength(), plan);
    forecast(ws, x, plan, c);
    benchmark::DoNotOptimize(e.min_clearance + c.min_clearance);
  }
  state.counters["n"] = p.n;
  state.counters["modes"] = ws.forecastModes();
}

void BM_ForecastEstop(benchmark::State& s) { forecastBench(s, Kind::Estop); }
void BM_ForecastContinue(benchmark::State& s) { forecastBench(s, Kind::Continue); }
void BM_ForecastPlan(benchmark::State& s) { forecastBench(s, Kind::Plan); }

// Args: n, max_step in 0.1 ms (25 = the daemon's default 2.5 ms; 100 = no
// substeps), economical (0: the exact forecast; 1: economicalForecast, which
// sets its own step, modes and envelope).
BENCHMARK(BM_ForecastEstop)->Args({20, 25, 0})->Args({50, 25, 0})->Args({50, 100, 0})->Unit(benchmark::kMillisecond);
// The converged setting for the tilt (README: n = 200); a few iterations suffice.
BENCHMARK(BM_ForecastEstop)->Args({200, 25, 0})->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_ForecastContinue)->Args({20, 25, 0})->Args({50, 25, 0})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ForecastPlan)->Args({50, 25, 0})->Unit(benchmark::kMillisecond);
// The converged setting (n = 25, static correction on), exact and
// economical side by side; and the example configuration's n = 50.
BENCHMARK(BM_ForecastEstop)->Args({25, 25, 0})->Args({25, 25, 1})->Args({50, 25, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ForecastPlan)->Args({25, 25, 0})->Args({25, 25, 1})->Args({50, 25, 1})->Unit(benchmark::kMillisecond);
// Both scenarios per instant (args: n, economical): CPU per second per shaft at 1 Hz.
BENCHMARK(BM_ForecastPair)->Args({25, 0})->Args({25, 1})->Args({50, 1})->Args({200, 1})->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return hoist::bench::runMain(argc, argv, "hoist-forecast-bench",
                               "The look-ahead forecast's cost (docs/lookahead.md).");
}
