// The checks of a recorded run (hoist/io/recorded_run.hpp).
#include "hoist/io/recorded_run.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hoist/io/profile.hpp"
#include "hoist/profile.hpp"

namespace hoist::io {

namespace {
std::string g(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
}  // namespace

EstimatorSettings checkRecordedRun(const std::vector<MeasurementSample>& samples, const ShaftParams& p,
                                   EstimatorSettings set, double max_step, const std::string& source) {
  {
    std::vector<ProfileSample> ps(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) ps[i] = {samples[i].t, samples[i].k};
    checkProfileInShaft(HoistProfile(std::move(ps)), p, source);
  }
  double min_dt = samples[1].t - samples[0].t;
  for (std::size_t i = 2; i < samples.size(); ++i) min_dt = std::min(min_dt, samples[i].t - samples[i - 1].t);
  const double rate = std::ceil(1.0 / min_dt - 1e-9);
  if (rate > set.max_rate) {
    if (rate > 100000.0 || set.nis_window * rate > 5.0e6)
      throw RecordedRunError(RecordedRunError::Option::Measurements,
                             "rows as close as " + g(min_dt) + " s apart (" + g(rate) +
                                 " Hz) are too fast for estimator.nis_window = " + g(set.nis_window) +
                                 " s (at most 5e6 window entries, 100 kHz)");
    set.max_rate = static_cast<int>(rate);
  }
  try {
    for (std::size_t i = 1; i < samples.size(); ++i) substepCount(samples[i].t - samples[i - 1].t, max_step);
  } catch (const std::invalid_argument& e) {
    throw RecordedRunError(RecordedRunError::Option::MaxStep, e.what());
  }
  return set;
}

}  // namespace hoist::io
