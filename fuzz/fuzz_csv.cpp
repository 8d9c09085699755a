// libFuzzer target: the hoist profile CSV reader, hoist::io::readProfileCsv,
// and the measurement CSV reader of hoist-estimate / hoist-replay
// --measurements, hoist::io::readMeasurementsCsv (same text rules).
// Every input must either give a valid profile (at least two samples, time
// strictly increasing, every value finite) or throw ProfileError; and either
// valid measurements (at least two rows, t strictly increasing, l > 0, every
// present value finite, only known sensor bits) or throw MeasurementError.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "hoist/io/estimator_config.hpp"
#include "hoist/io/profile.hpp"

namespace {

void measurements(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  hoist::io::ProfileLimits lim;
  lim.max_rows = 100000;
  std::vector<hoist::MeasurementSample> m;
  try {
    m = hoist::io::readMeasurementsCsv(in, "fuzz.csv", lim);
  } catch (const hoist::io::MeasurementError& e) {
    if (!*e.what()) std::abort();
    return;
  }
  if (m.size() < 2) std::abort();
  const unsigned all = hoist::kSensorImuAccel | hoist::kSensorImuRate | hoist::kSensorRopeLoad;
  for (std::size_t i = 0; i < m.size(); ++i) {
    const auto& s = m[i];
    if (!std::isfinite(s.t) || !(s.k.l > 0) || !std::isfinite(s.k.l) || !std::isfinite(s.k.v) || !std::isfinite(s.k.a))
      std::abort();
    if (i > 0 && !(s.t > m[i - 1].t)) std::abort();
    if ((s.present & ~all) != 0) std::abort();
    if ((s.present & hoist::kSensorImuAccel) && !std::isfinite(s.z.f_y)) std::abort();
    if ((s.present & hoist::kSensorImuRate) && !std::isfinite(s.z.omega)) std::abort();
    if ((s.present & hoist::kSensorRopeLoad) && !std::isfinite(s.z.rope_load)) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  measurements(data, size);
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  hoist::io::ProfileLimits lim;
  lim.max_rows = 100000;
  hoist::HoistProfile p;
  try {
    p = hoist::io::readProfileCsv(in, "fuzz.csv", 50.0, lim);
  } catch (const hoist::io::ProfileError& e) {
    if (!*e.what()) std::abort();
    return 0;
  }
  const double t0 = p.startTime(), t1 = p.endTime();
  if (!(std::isfinite(t0) && std::isfinite(t1) && t1 > t0)) std::abort();
  for (int i = 0; i <= 16; ++i) {
    const auto k = p.at(t0 + (t1 - t0) * i / 16.0);
    if (!std::isfinite(k.l) || !std::isfinite(k.v) || !std::isfinite(k.a)) std::abort();
  }
  return 0;
}
