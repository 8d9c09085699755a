// advise.hpp -- the preload advisor subcommand: search, CSVs, figure, report.
#pragma once

#include <string>

#include "cli.hpp"
#include "plots.hpp"

namespace hoist::study::cli {

struct AdviseArgs {
  double clearance = 0.0;
  double max_force = 0.0;
  std::string split_range = "0.3:0.7";
  std::string total_range = "1e4:5e5";
  int samples = 12;
};

/// Returns 0 (a recommendation), 3 (infeasible in the range); throws UsageError.
int runAdvisor(const AdviseArgs& a, const Common& c, const ShaftParams& base, const HoistProfile& profile,
               PlotState& ps);

}  // namespace hoist::study::cli
