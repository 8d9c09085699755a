// hoist-estimate's checks: see estimate_check.hpp.
#include "estimate_check.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <utility>

#include "hoist/io/accel_offset_file.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/recorded_run.hpp"

namespace hoist::estimate {

Input check(const Options& o) {
  // ---- input ------------------------------------------------------------
  const toml::table tbl = hoist::io::loadTomlFile(o.config);
  hoist::ShaftParams p = hoist::io::shaftParamsFromToml(tbl, o.config, hoist::io::daemonSections());
  const hoist::io::EstimatorConfig ec = hoist::io::estimatorConfigFromToml(tbl, o.config);
  const double max_step = o.max_step >= 0.0 ? o.max_step : hoist::io::serviceMaxStep(tbl, o.config, hoist::kDefaultMaxStep);
  if (o.modes != 0) p.n = o.modes;
  try {
    p.validate();
  } catch (const hoist::ParamError& e) {
    throw UsageError(std::string("--modes: ") + e.what());
  }
  hoist::io::MeasurementColumns cols;
  std::vector<hoist::MeasurementSample> samples =
      hoist::io::readMeasurementsCsvFile(o.measurements, {}, &cols);
  // The shaft, the NIS window's rate and the substeps: the checks hoist.estimate shares.
  hoist::EstimatorSettings set;
  try {
    set = hoist::io::checkRecordedRun(samples, p, ec.settings, max_step, o.measurements);
  } catch (const hoist::io::RecordedRunError& e) {
    throw UsageError(e.option == hoist::io::RecordedRunError::Option::MaxStep
                         ? "--max-step " + fmt("%g", max_step) + ": " + e.what()
                         : "--measurements " + o.measurements + ": " + e.what());
  }
  if (cols.sensors == 0 && !o.quiet)
    std::cerr << "hoist-estimate: warning: " << o.measurements
              << " has no sensor column (f_y, omega, rope_load): the estimate is the open-loop twin\n";
  if (!cols.ignored.empty() && !o.quiet) {
    std::string list;
    for (const auto& c : cols.ignored) list += (list.empty() ? "" : ", ") + c;
    std::cerr << "hoist-estimate: " << o.measurements << ": ignored columns: " << list << "\n";
  }
  hoist::RecordedCalibration cal;
  for (const std::string& k : o.known_load) {
    double v[4];
    char tail = 0;
    if (std::sscanf(k.c_str(), "%lf,%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &v[3], &tail) != 4 ||
        !(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) && std::isfinite(v[3])))
      throw UsageError("--known-load " + k + ": expected T0,T1,FA,B (four finite numbers: s, s, N, m)");
    if (!(v[1] > v[0])) throw UsageError("--known-load " + k + ": T1 must be after T0");
    if (v[2] < 0.0) throw UsageError("--known-load " + k + ": FA must be >= 0 N");
    if (std::abs(v[3]) > p.offsetLimit())
      throw UsageError("--known-load " + k + ": |B| beyond the conveyance's half-width " + fmt("%g", p.offsetLimit()) + " m");
    cal.known.push_back({v[0], v[1], v[2], v[3]});
  }
  if (!o.offset_in.empty()) {
    const hoist::io::AccelOffsetRecord r = hoist::io::readAccelOffsetFile(o.offset_in);
    cal.has_offset = true;
    cal.offset = r.offset;
    cal.offset_sigma = r.sigma;
  }
  return Input{std::move(p), set, max_step, std::move(samples), std::move(cols), std::move(cal)};
}

}  // namespace hoist::estimate
