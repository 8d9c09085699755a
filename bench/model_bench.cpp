// Model speed: one step of each path against n, and the whole paper case.
//
//   build/bin/hoist-bench                          all
//   build/bin/hoist-bench --benchmark_filter=Step/50
//
// Steps are timed while the solver runs the paper's trapezoid (Fig. 2) at
// dt = 0.01 s, so every step sees a new l, v, a; the solver is re-initialized
// (untimed) when the trip ends.
#include <cstdio>
#include <string>

#include "hoist/version.hpp"
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <vector>

#include "hoist/fast_solver.hpp"
#include "longitudinal_reference.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/simulator.hpp"

namespace {

using namespace hoist;

void stepBench(benchmark::State& state, Method m, int corr = -1) {
  ShaftParams p;
  p.n = static_cast<int>(state.range(0));
  // The paper's method has no static correction; -1 = the default (on).
  if (m == Method::Paper) p.static_correction = false;
  if (corr >= 0) p.static_correction = corr != 0;
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
/// The fast step without (0) and with (1) the static correction, side by side.
void BM_FastStepCorrection(benchmark::State& state) {
  stepBench(state, Method::Fast, static_cast<int>(state.range(1)));
  state.counters["static_correction"] = static_cast<double>(state.range(1));
}
BENCHMARK(BM_FastStepCorrection)->ArgsProduct({{20, 50}, {0, 1}})->Unit(benchmark::kMicrosecond);

/// The longitudinal step: E built in one pass from the four constant matrices
/// (1, the solver's form) against the previous Ek build-apply-scale-add (0),
/// side by side on the longitudinal subsystem alone, where the two differ
/// (bench/longitudinal_reference.hpp; the test that both agree is
/// bench/longitudinal_reference_test.cpp).
void BM_FastStepLongitudinalFused(benchmark::State& state) {
  ShaftParams p;
  p.n = static_cast<int>(state.range(0));
  auto model = std::make_shared<const ShaftModel>(p);
  FastSolver s(model);
  hoist::bench::LongitudinalStep lon(model, state.range(1) != 0 ? hoist::bench::StepMatrix::Fused
                                                                 : hoist::bench::StepMatrix::Previous);
  const HoistProfile prof = HoistProfile::trapezoid();
  const double dt = 0.01;
  FastSolverState s0;
  s.initialize(0.0, prof.at(0.0));
  s.saveState(s0);
  lon.start(s0);
  long k = 0;
  for (auto _ : state) {
    if (++k * dt > 55.0) {
      state.PauseTiming();
      k = 1;
      lon.start(s0);
      state.ResumeTiming();
    }
    const double t = k * dt;
    lon.step(t, prof.at(t));
    benchmark::DoNotOptimize(lon.lambda0());
  }
  state.counters["fused"] = static_cast<double>(state.range(1));
}
BENCHMARK(BM_FastStepLongitudinalFused)->ArgsProduct({{20, 50, 200}, {0, 1}})->Unit(benchmark::kMicrosecond);

/// One daemon tick of the twin alone (0) and of the twin with the load
/// estimator (1): the sensitivity step, the prediction, an IMU and a rope-load
/// update and the NIS window; side by side at n.
void BM_TwinTickWithEstimator(benchmark::State& state) {
  ShaftParams p;
  p.n = static_cast<int>(state.range(0));
  const bool with = state.range(1) != 0;
  auto model = std::make_shared<const ShaftModel>(p);
  FastSolver s(model);
  EstimatorSettings es;
  // 1: a calibrated accelerometer (the one-state lateral filter); 2: the
  // default, the accelerometer's offset as a state.
  es.accel_offset_sigma = state.range(1) == 2 ? 0.005 : 0.0;
  LoadEstimator est(p, es);
  const HoistProfile prof = HoistProfile::trapezoid();
  const double dt = 0.01;
  s.initialize(0.0, prof.at(0.0));
  est.initialize(0.0, prof.at(0.0));
  long k = 0;
  for (auto _ : state) {
    ++k;
    if (k * dt > 55.0) {
      state.PauseTiming();
      k = 1;
      s.initialize(0.0, prof.at(0.0));
      est.initialize(0.0, prof.at(0.0));
      state.ResumeTiming();
    }
    const double t = k * dt;
    const Kinematics kin = prof.at(t);
    s.step(t, kin);
    if (with) {
      est.advance(t, kin, 1);
      est.predict(s.response());
      est.updateImu(0.0074, 1e-5);
      est.updateRopeLoad(8848.0);
      benchmark::DoNotOptimize(est.finish().theta);
    }
    benchmark::DoNotOptimize(s.response().lambda[1]);
  }
  state.counters["n"] = p.n;
  state.counters["estimator"] = static_cast<double>(state.range(1));
}
// Second argument: 0 the model step alone, 1 with the estimator (calibrated
// accelerometer), 2 with the accelerometer's offset estimated too.
BENCHMARK(BM_TwinTickWithEstimator)->ArgsProduct({{25, 50}, {0, 1, 2}})->Unit(benchmark::kMicrosecond);

BENCHMARK(BM_FastStep)->Arg(10)->Arg(25)->Arg(50)->Arg(100)->Arg(200)->Arg(400)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PaperStep)->Arg(10)->Arg(25)->Arg(50)->Arg(100)->Arg(200)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
// n = 400 costs seconds per step on the paper path: a few iterations only.
BENCHMARK(BM_PaperStep)->Arg(400)->Unit(benchmark::kMicrosecond)->Iterations(3);

/// Distribution of single fast steps over the paper's whole trip (5500 steps
/// per iteration): p50 / p99 / p99.9 / max in microseconds as counters.  The
/// benchmark time itself is the mean.
void BM_FastStepLatency(benchmark::State& state) {
  ShaftParams p;
  p.n = static_cast<int>(state.range(0));
  auto model = std::make_shared<const ShaftModel>(p);
  auto s = makeSolver(Method::Fast, model);
  const HoistProfile prof = HoistProfile::trapezoid();
  const double dt = 0.01;
  std::vector<double> us;
  us.reserve(1 << 20);
  for (auto _ : state) {
    state.PauseTiming();
    s->initialize(0.0, prof.at(0.0));
    state.ResumeTiming();
    for (long k = 1; k <= 5500; ++k) {
      const double t = k * dt;
      const auto kin = prof.at(t);
      const auto a = std::chrono::steady_clock::now();
      s->step(t, kin);
      const auto b = std::chrono::steady_clock::now();
      if (us.size() < us.capacity()) us.push_back(std::chrono::duration<double, std::micro>(b - a).count());
    }
    benchmark::DoNotOptimize(s->response().lambda[1]);
  }
  std::sort(us.begin(), us.end());
  auto q = [&](double f) { return us.empty() ? 0.0 : us[std::min(us.size() - 1, static_cast<std::size_t>(f * us.size()))]; };
  state.counters["p50_us"] = q(0.5);
  state.counters["p99_us"] = q(0.99);
  state.counters["p999_us"] = q(0.999);
  state.counters["max_us"] = us.empty() ? 0.0 : us.back();
  state.counters["steps"] = static_cast<double>(us.size());
}
BENCHMARK(BM_FastStepLatency)->Arg(50)->Arg(200)->Unit(benchmark::kMillisecond);

/// The paper's run: n = 50, 60 s with output every 0.01 s, static start,
/// including set-up (model precomputation) and initialization.  `max_step`
/// 0 integrates with dt = 0.01 s (6000 steps, as the paper); 0.0025 is
/// hoist-sim's default (24000 steps).
void paperCase(benchmark::State& state, double max_step) {
  const HoistProfile prof = HoistProfile::trapezoid();
  for (auto _ : state) {
    auto model = std::make_shared<const ShaftModel>(ShaftParams{});
    auto s = makeSolver(Method::Fast, model);
    SimulationOptions o;
    o.max_step = max_step;
    double acc = 0;
    simulate(*s, prof, o, [&](const CageResponse& r) { acc += r.y_c; });
    benchmark::DoNotOptimize(acc);
  }
}
void BM_PaperCaseFast(benchmark::State& state) { paperCase(state, 0.0); }
void BM_PaperCaseFastSubsteps(benchmark::State& state) { paperCase(state, 0.0025); }
BENCHMARK(BM_PaperCaseFast)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PaperCaseFastSubsteps)->Unit(benchmark::kMillisecond);

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

// BENCHMARK_MAIN() plus --version (from the one version header).
int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--version") {
      std::printf("hoist-bench %s\n", hoist::kVersionString);
      return 0;
    }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
