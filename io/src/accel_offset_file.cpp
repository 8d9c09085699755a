// hoist/io/accel_offset_file.hpp: the learned accelerometer offset's file.
#include "hoist/io/accel_offset_file.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>

#include "hoist/io/checked_file.hpp"
#include "hoist/io/error.hpp"

namespace hoist::io {

void writeAccelOffsetFile(const std::string& path, const AccelOffsetRecord& r, const std::string& label) {
  CheckedFile f(path, label);
  f.printf("# hoist accelerometer offset (hoist-estimate --offset-out, hoist-twind's state)\n"
           "accel_offset = %.9g\nsigma = %.9g\n",
           r.offset, r.sigma);
  f.close(true);
}

AccelOffsetRecord readAccelOffsetFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "", "cannot open");
  AccelOffsetRecord r;
  bool have_offset = false, have_sigma = false;
  std::string line;
  int no = 0;
  while (std::getline(in, line)) {
    ++no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto eq = line.find('=');
    if (eq == std::string::npos) throw InputError(path, no, "", "expected 'key = value'");
    std::string key = line.substr(first, eq - first);
    key.erase(key.find_last_not_of(" \t") + 1);
    const std::string text = line.substr(eq + 1);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || text.find_first_not_of(" \t\r", end - text.c_str()) != std::string::npos ||
        !std::isfinite(v))
      throw InputError(path, no, key, "not a finite number");
    if (key == "accel_offset") {
      if (std::abs(v) > 1.0) throw InputError(path, no, key, "must be within +-1 m/s^2");
      r.offset = v;
      have_offset = true;
    } else if (key == "sigma") {
      if (v < 0.0 || v > 1.0) throw InputError(path, no, key, "must be in [0, 1] m/s^2");
      r.sigma = v;
      have_sigma = true;
    } else {
      throw InputError(path, no, key, "unknown key (accel_offset, sigma)");
    }
  }
  if (!have_offset) throw InputError(path, 0, "accel_offset", "missing");
  if (!have_sigma) throw InputError(path, 0, "sigma", "missing");
  return r;
}

}  // namespace hoist::io
