// hoist/io/recorded_run.hpp -- the checks of a recorded run before the load
// estimator runs over it, shared by hoist-estimate (tools/estimate) and
// hoist.estimate (python/src/estimate_py.cpp) so that both accept, refuse and
// size exactly alike.
//
// checkRecordedRun: the rows' (t, l) stay inside the shaft
// (checkProfileInShaft: io::ProfileError naming `source`); [estimator]
// max_rate is raised to the fastest row rate (the NIS window holds one entry
// per sample), refused beyond 100 kHz or 5e6 window entries; every row
// interval splits into max_step substeps.  Returns the settings to run with.
// A refusal is RecordedRunError: what() is the reason without the option's
// name, `option` says which option the caller names in its message.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "hoist/load_estimator.hpp"
#include "hoist/params.hpp"

namespace hoist::io {

class RecordedRunError : public std::invalid_argument {
 public:
  enum class Option { Measurements, MaxStep };
  RecordedRunError(Option o, const std::string& why) : std::invalid_argument(why), option(o) {}
  Option option;
};

EstimatorSettings checkRecordedRun(const std::vector<MeasurementSample>& samples, const ShaftParams& p,
                                   EstimatorSettings set, double max_step, const std::string& source);

}  // namespace hoist::io
