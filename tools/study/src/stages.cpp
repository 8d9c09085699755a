// Trip stages and per-run metrics: see hoist/study/stages.hpp.
#include "hoist/study/stages.hpp"

#include <cmath>
#include <string>
#include <utility>

namespace hoist::study {

std::vector<Window> stageWindows(const HoistProfile& profile) {
  const auto& smp = profile.samples();
  double best = 0.0, b0 = 0.0, b1 = 0.0;
  std::size_t i = 0;
  while (i < smp.size()) {
    auto cruising = [&](std::size_t k) {
      return std::abs(smp[k].k.a) < 1e-9 && std::abs(smp[k].k.v) > 1e-6;
    };
    if (!cruising(i)) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j + 1 < smp.size() && cruising(j + 1)) ++j;
    if (smp[j].t - smp[i].t > best) {
      best = smp[j].t - smp[i].t;
      b0 = smp[i].t;
      b1 = smp[j].t;
    }
    i = j + 1;
  }
  if (!(best > 0.0) || !(profile.endTime() > b1)) return paperWindows();
  // The sampled profile reaches a = 0 one sample after the corner; round the
  // stage ends to the nearest 0.1 s so the paper's profile gives 5-50 / 50-60 s.
  auto r = [](double t) { return std::round(t * 10.0) / 10.0; };
  return {{"trip", -1e300, 1e300}, {"uniform", r(b0), r(b1)}, {"decel", r(b1), profile.endTime()}};
}

MetricSet runMetrics(const RunResult& r, const std::vector<Window>& windows,
                     const FrequencyOptions& fopt) {
  MetricSet m;
  const Trace& tr = r.trace;
  const std::vector<double> exc = tr.excursion(r.spec.params.h);
  const std::vector<std::pair<std::string, const std::vector<double>*>> sig = {
      {"y_c", &tr.y_c},           {"theta", &tr.theta},       {"excursion", &exc},
      {"lambda_0", &tr.lambda[0]}, {"lambda_1", &tr.lambda[1]}, {"lambda_2", &tr.lambda[2]},
      {"lambda_3", &tr.lambda[3]}, {"lambda_4", &tr.lambda[4]}};
  for (const auto& w : windows) {
    const std::string suf = w.name == "trip" ? "" : "_" + w.name;
    for (const auto& [name, y] : sig) m.set("peak_" + name + suf, peakAbs(tr.t, *y, w.t0, w.t1));
  }
  for (const auto& [name, y] : sig) m.set("rms_" + name, rms(tr.t, *y, -1e300, 1e300));
  for (const auto& w : windows) {
    if (w.name == "trip") continue;
    for (const auto& [name, y] : sig) {
      if (name != "y_c" && name != "theta" && name != "lambda_1") continue;
      m.set("f_" + name + "_" + w.name, dominantFrequencyFFT(tr.t, *y, w.t0, w.t1, fopt));
      m.set("fc_" + name + "_" + w.name, spectralCentroid(tr.t, *y, w.t0, w.t1, fopt));
      m.set("fzc_" + name + "_" + w.name,
            zeroCrossingFrequency(tr.t, *y, w.t0, w.t1, fopt.detrend_degree));
      m.set("osc_" + name + "_" + w.name, oscillationAmplitude(tr.t, *y, w.t0, w.t1, fopt.detrend_degree));
    }
  }
  return m;
}

}  // namespace hoist::study
