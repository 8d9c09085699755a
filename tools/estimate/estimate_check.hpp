// hoist-estimate's checks (tools/estimate/main.cpp: parse -> check -> run):
// the configuration, the measurement CSV, the calibration options and the
// offset file are read and checked before anything is estimated or written.
#pragma once

#include <string>
#include <vector>

#include "estimate_options.hpp"
#include "hoist/io/estimator_config.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/params.hpp"
#include "hoist/profile.hpp"

namespace hoist::estimate {

/// What the checks established: the run's whole input.
struct Input {
  hoist::ShaftParams p;                         ///< the shaft (--modes applied)
  hoist::EstimatorSettings set;                 ///< the estimator's settings, checked against the data
  double max_step = 0.0;                        ///< the substep [s]
  std::vector<hoist::MeasurementSample> samples;
  hoist::io::MeasurementColumns cols;           ///< the sensors present, the columns ignored
  hoist::RecordedCalibration cal;               ///< --known-load, --offset-in
};

/// Reads and checks everything the run needs (warnings about the data go to
/// stderr unless --quiet).  Throws UsageError (an option's value) or
/// hoist::io::InputError (a file, naming line and column): exit status 2.
Input check(const Options& o);

}  // namespace hoist::estimate
