// run_study.hpp -- running one study: the runs, their metrics, the CSV
// files, the summary table on stdout and the figures.
#pragma once

#include "cli.hpp"
#include "hoist/study/studies.hpp"
#include "plots.hpp"

namespace hoist::study::cli {

/// Run `s` into c.out_dir/<name>/.  Returns 0, or 1 if a run failed.
int runStudy(const Study& s, const Common& c, const ShaftParams& base, const HoistProfile& profile,
             PlotState& ps);

}  // namespace hoist::study::cli
