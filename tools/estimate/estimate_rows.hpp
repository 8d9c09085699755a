// hoist-estimate's output rows: the CSV header and one row per estimate
// (a value that is not observed -- sigma < 0, or its sensor not seen yet --
// is written as nan with its sigma).
#pragma once

#include <string>

#include "hoist/load_estimator.hpp"

namespace hoist::estimate {

/// The output CSV's header line (without the newline).
extern const char* const kOutputHeader;

/// Appends one row (with its newline) for estimate `e` and counters `c` to `s`.
void appendRow(std::string& s, const hoist::LoadEstimate& e, const hoist::EstimatorCounters& c);

}  // namespace hoist::estimate
