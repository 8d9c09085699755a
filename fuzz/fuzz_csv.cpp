// libFuzzer target: the hoist profile CSV reader, hoist::io::readProfileCsv.
// Every input must either give a valid profile (at least two samples, time
// strictly increasing, every value finite) or throw ProfileError.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "hoist/io/profile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
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
