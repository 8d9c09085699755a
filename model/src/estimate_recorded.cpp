// estimateRecorded (hoist/load_estimator.hpp): hoist-estimate's run of the
// estimator over recorded samples, the sequence the daemon runs live.
#include <memory>

#include "hoist/load_estimator.hpp"

namespace hoist {

void estimateRecorded(const ShaftParams& twin, const EstimatorSettings& settings, double max_step,
                      const std::vector<MeasurementSample>& samples,
                      const std::function<void(const LoadEstimate&, const EstimatorCounters&)>& sink,
                      const std::function<void(double)>& progress) {
  if (samples.empty()) return;
  auto model = std::make_shared<const ShaftModel>(twin);
  FastSolver solver(model);
  LoadEstimator est(twin, settings);
  auto apply = [&](const MeasurementSample& m) {
    est.predict(solver.response());
    const bool a = m.present & kSensorImuAccel, w = m.present & kSensorImuRate;
    if (a && w) est.updateImu(m.z.f_y, m.z.omega);
    else if (a) est.updateImuAccel(m.z.f_y);
    else if (w) est.updateImuRate(m.z.omega);
    if (m.present & kSensorRopeLoad) est.updateRopeLoad(m.z.rope_load);
    sink(est.finish(), est.counters());
  };
  const MeasurementSample& first = samples.front();
  solver.initialize(first.t, first.k, twin.initial);
  est.initialize(first.t, first.k);
  apply(first);
  const std::size_t every = std::max<std::size_t>(1, samples.size() / 100);
  for (std::size_t i = 1; i < samples.size(); ++i) {
    const MeasurementSample& prev = samples[i - 1];
    const MeasurementSample& m = samples[i];
    const double h = m.t - prev.t;
    const int n = h > 0.0 ? substepCount(h, max_step) : 1;
    for (int j = 1; j < n; ++j) {
      const double u = static_cast<double>(j) / n;
      solver.step(prev.t + u * h, interpolate(prev.k, m.k, h, u));
    }
    solver.step(m.t, m.k);
    est.advance(m.t, m.k, n);
    apply(m);
    if (progress && i % every == 0) progress(static_cast<double>(i) / samples.size());
  }
  if (progress) progress(1.0);
}

}  // namespace hoist
