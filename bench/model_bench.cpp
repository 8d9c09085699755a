// Model speed: one step of each path against n, and the whole paper case.
//
//   build/bin/hoist-bench                          all
//   build/bin/hoist-bench --benchmark_filter=Step/50
//
// Steps are timed while the solver runs the paper's trapezoid (Fig. 2) at
// dt = 0.01 s, so every step sees a new l, v, a; the solver is re-initialized
// (untimed) when the trip ends.
#include <benchmark/benchmark.h>

#include <memory>

#include "hoist/simulator.hpp"

namespace {

using namespace hoist;

void stepBench(benchmark::State& state, Method m) {
  ShaftParams p;
  p.n = static_cast<int>(state.range(0));
  auto model = std::make_shared<const ShaftModel>(p);
  auto s = makeSolver(m, model);
  const HoistProfile prof = HoistProfile::trapezoid();
  const double dt = 0.01;
  s->initialize(0.0, prof.at(0.0));
  long k = 0;
  for (auto _ : state) {
    ++k;
    if (k * dt > 55.0) {
      state.PauseTiming();
      k = 1;
      s->initialize(0.0, prof.at(0.0));
      state.ResumeTiming();
    }
    const double t = k * dt;
    s->step(t, prof.at(t));
    benchmark::DoNotOptimize(s->response().lambda[1]);
  }
  state.counters["n"] = p.n;
}

void BM_FastStep(benchmark::State& state) { stepBench(state, Method::Fast); }
void BM_PaperStep(benchmark::State& state) { stepBench(state, Method::Paper); }

BENCHMARK(BM_FastStep)->Arg(10)->Arg(25)->Arg(50)->Arg(100)->Arg(200)->Arg(400)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PaperStep)->Arg(10)->Arg(25)->Arg(50)->Arg(100)->Arg(200)->Unit(benchmark::kMicrosecond)->MinTime(0.5);

/// The paper's run: n = 50, dt = 0.01 s, 60 s (6000 steps), static start,
/// including set-up (model precomputation) and initialization.
void BM_PaperCaseFast(benchmark::State& state) {
  const HoistProfile prof = HoistProfile::trapezoid();
  for (auto _ : state) {
    auto model = std::make_shared<const ShaftModel>(ShaftParams{});
    auto s = makeSolver(Method::Fast, model);
    SimulationOptions o;
    double acc = 0;
    simulate(*s, prof, o, [&](const CageResponse& r) { acc += r.y_c; });
    benchmark::DoNotOptimize(acc);
  }
}
BENCHMARK(BM_PaperCaseFast)->Unit(benchmark::kMillisecond);

/// Model set-up (closed-form integrals, eigen-decomposition of the guide ropes).
void BM_ModelSetup(benchmark::State& state) {
  ShaftParams p;
  p.n = static_cast<int>(state.range(0));
  for (auto _ : state) {
    auto model = std::make_shared<const ShaftModel>(p);
    benchmark::DoNotOptimize(model.get());
  }
}
BENCHMARK(BM_ModelSetup)->Arg(50)->Arg(200)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
