// hoist/io/accel_offset_file.hpp: the learned accelerometer offset's file.
#include "hoist/io/accel_offset_file.hpp"

#include <cmath>

#include "hoist/io/checked_file.hpp"
#include "hoist/io/error.hpp"
#include "hoist/io/key_value_file.hpp"

namespace hoist::io {

void writeAccelOffsetFile(const std::string& path, const AccelOffsetRecord& r, const std::string& label) {
  CheckedFile f(path, label);
  f.printf("# hoist accelerometer offset (hoist-estimate --offset-out, hoist-twind's state)\n"
           "accel_offset = %.9g\nsigma = %.9g\n",
           r.offset, r.sigma);
  f.close(true);
}

AccelOffsetRecord readAccelOffsetFile(const std::string& path) {
  AccelOffsetRecord r;
  bool have_offset = false, have_sigma = false;
  readKeyValueFile(path, [&](int no, const std::string& key, const std::string& text) {
    if (key == "accel_offset") {
      const double v = finiteValue(path, no, key, text);
      if (std::abs(v) > 1.0) throw InputError(path, no, key, "must be within +-1 m/s^2");
      r.offset = v;
      have_offset = true;
    } else if (key == "sigma") {
      const double v = finiteValue(path, no, key, text);
      if (v < 0.0 || v > 1.0) throw InputError(path, no, key, "must be in [0, 1] m/s^2");
      r.sigma = v;
      have_sigma = true;
    } else {
      throw InputError(path, no, key, "unknown key (accel_offset, sigma)");
    }
  });
  if (!have_offset) throw InputError(path, 0, "accel_offset", "missing");
  if (!have_sigma) throw InputError(path, 0, "sigma", "missing");
  return r;
}

}  // namespace hoist::io
