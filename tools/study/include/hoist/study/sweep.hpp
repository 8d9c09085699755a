// hoist/study/sweep.hpp -- parameter sweeps of the shaft model: the paper's
// Section 3 studies (Figs. 2-13) and any config key, run in parallel threads.
// Pure numerics: no files, no printing (progress goes to a callback).
// One header per job; this one includes them all.
#pragma once

#include "hoist/study/parameters.hpp"  // the --param keys
#include "hoist/study/runner.hpp"      // RunSpec/RunResult, runOne, runAll, parallelFor
#include "hoist/study/stages.hpp"      // stageWindows, runMetrics
#include "hoist/study/studies.hpp"     // Study, paperStudy, sweepStudy
#include "hoist/study/trace.hpp"       // Trace, Shape
