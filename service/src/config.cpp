// Daemon configuration (plain structs and their validation): see
// hoist/service/config.hpp.  Reading and writing TOML
// lives in config_file.cpp.
#include "hoist/service/config.hpp"

#include <cctype>
#include <cmath>
#include <sstream>

namespace hoist::svc {

const char* toString(ClockMode c) { return c == ClockMode::Wall ? "wall" : "input"; }

namespace {

[[noreturn]] void bad(const std::string& key, const std::string& why) {
  // validate() has no file position: the loader rethrows with one.
  throw std::invalid_argument(key + ": " + why);
}

void checkRange(const char* key, double v, double lo, double hi, bool lo_open = false) {
  if (!std::isfinite(v) || v > hi || (lo_open ? !(v > lo) : v < lo)) {
    std::ostringstream os;
    os << "must be in " << (lo_open ? "(" : "[") << lo << ", " << hi << "], got " << v;
    bad(std::string("service.") + key, os.str());
  }
}

}  // namespace

void ServiceConfig::validate() const {
  checkRange("rate", rate, 1.0, 1000.0);
  checkRange("cage_rate", cage_rate, 0.0, rate);
  checkRange("shape_rate", shape_rate, 0.0, rate);
  checkRange("health_rate", health_rate, 0.0, 10.0, true);
  checkRange("max_speed", max_speed, 0.0, 1e3, true);
  checkRange("max_accel", max_accel, 0.0, 1e4, true);
  checkRange("max_length_jump", max_length_jump, 0.0, 1e4, true);
  checkRange("max_time_step", max_time_step, 0.0, 3600.0, true);
  checkRange("stale_timeout", stale_timeout, 0.0, 3600.0, true);
  checkRange("stale_periods", stale_periods, 0.0, 1000.0);
  checkRange("stale_min", stale_min, 0.0, 3600.0);
  checkRange("max_step", max_step, 0.0, 10.0);
  checkRange("shape_points", shape_points, 2, 2001);
  checkRange("envelope_points", envelope_points, 2, 20001);
  checkRange("log_rate_limit", log_rate_limit, 1, 1000);
  checkRange("fault_hold", fault_hold, 0.0, 3600.0);
  for (char c : channel_prefix)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '/'))
      bad("service.channel_prefix", "may contain only letters, digits and _ - . /");
}

}  // namespace hoist::svc
