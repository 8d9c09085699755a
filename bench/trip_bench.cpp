// The cost of one trip's preload identification (issue 32: at most 1 s of
// CPU per trip at n = 25): a 280 m trip at 8 m/s, 49 s of samples at 100 Hz,
// the twin's max_step 0.0025 s.  Run: build/bin/hoist-trip-bench
#include <benchmark/benchmark.h>

#include "bench_main.hpp"

#include <cstdio>
#include <random>
#include <string>

#include "hoist/preload_identification.hpp"

using namespace hoist;

static void BM_IdentifyPreloadTrip(benchmark::State& state) {
  ShaftParams twin;
  twin.n = static_cast<int>(state.range(0));
  const HoistProfile prof = HoistProfile::sCurve(50.0, 8.0, 1.0, 1.0, 280.0, 46.0, 0.01);
  std::vector<MeasurementSample> trip;
  for (int i = 0; i <= 4900; ++i) {
    MeasurementSample m;
    m.t = 0.01 * i;
    m.k = prof.at(m.t - 3.0);
    m.present = kSensorImuAccel | kSensorImuRate;
    trip.push_back(m);
  }
  // The data: the twin's own response to M = 900 N m at s = 0.8, with noise.
  std::vector<double> fy, om;
  unitMomentResponse(twin, 0.8, 0.0, 0.0025, trip, fy, om);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> N01;
  for (std::size_t i = 0; i < trip.size(); ++i) trip[i].z = {900.0 * fy[i] + 0.002 * N01(rng), 900.0 * om[i] + 1e-4 * N01(rng), 0.0};
  EstimatorSettings est;
  PreloadFitOptions opt;
  double cpu = 0.0;
  for (auto _ : state) {
    const PreloadFit f = identifyPreload(twin, est, opt, trip);
    benchmark::DoNotOptimize(f.id.scale);
    cpu = f.id.cpu_seconds;
  }
  state.counters["cpu_s_per_trip"] = cpu;
}
BENCHMARK(BM_IdentifyPreloadTrip)->Arg(25)->Arg(50)->Unit(benchmark::kMillisecond)->Iterations(3);

int main(int argc, char** argv) {
  return hoist::bench::runMain(argc, argv, "hoist-trip-bench",
                               "The guide-rope preload identification's cost per trip (docs/condition-identification.md).");
}
