// bench/bench_main.hpp -- BENCHMARK_MAIN() for hoist's benchmark programs,
// plus --version (from the one version header) and a usage line that names
// the program, as every hoist program has (tests/deploy/cli_test.py).
// Header-only; include it from one .cpp per program and return
// hoist::bench::runMain(argc, argv, "hoist-x-bench", "what it measures").
#pragma once

#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

#include "hoist/version.hpp"

namespace hoist::bench {

inline int runMain(int argc, char** argv, const char* program, const char* about) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--version") {
      std::printf("%s %s\n", program, hoist::kVersionString);
      return 0;
    }
    if (a == "--help" || a == "-h") {
      std::printf("usage: %s [Google Benchmark options]\n%s  Options:\n", program, about);
      std::fflush(stdout);
    }
  }
  benchmark::Initialize(&argc, argv);  // --help: prints Google Benchmark's options, exits 0
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace hoist::bench
