// Daemon configuration (plain structs and their validation): see
// hoist/service/core/config.hpp.  Reading and writing TOML
// lives in config_file.cpp.
#include "hoist/service/core/config.hpp"

#include <cctype>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace hoist::service::inline core {

const char* toString(ClockMode c) { return c == ClockMode::Wall ? "wall" : "input"; }

namespace {

[[noreturn]] void bad(const std::string& key, const std::string& why) {
  // validate() has no file position: the loader rethrows with one.
  throw std::invalid_argument(key + ": " + why);
}

void checkRange(const char* key, double v, double lo, double hi, bool lo_open = false,
                const char* section = "service.") {
  if (!std::isfinite(v) || v > hi || (lo_open ? !(v > lo) : v < lo)) {
    std::ostringstream os;
    os << "must be in " << (lo_open ? "(" : "[") << lo << ", " << hi << "], got " << v;
    bad(std::string(section) + key, os.str());
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
  checkRange("envelope_tolerance", envelope_tolerance, 0.0, 0.05);
  checkRange("log_rate_limit", log_rate_limit, 1, 1000);
  checkRange("fault_hold", fault_hold, 0.0, 3600.0);
  checkRange("accel_tolerance", accel_tolerance, 0.0, 100.0, true);
  checkRange("velocity_tolerance", velocity_tolerance, 0.0, 10.0);
  checkRange("consistency_window", consistency_window, 0.0, 60.0, true);
  checkRange("plausible_factor", plausible_factor, 2.0, 1e6);
  checkRange("max_catchup_periods", max_catchup_periods, 1, 1000);
  checkRange("max_commands_per_tick", max_commands_per_tick, 1, 1000);
  checkRange("max_starts_per_tick", max_starts_per_tick, 0, 100000);
  checkRange("max_exact_envelopes_per_tick", max_exact_envelopes_per_tick, 0, 100000);
  if (max_step > 0.0) {
    // Never clamp in silence: the longest interval one step may have to
    // cover (a tick's catch-up, or an input interval with --clock input)
    // must fit kMaxSubsteps substeps.
    const double longest = std::max(max_catchup_periods / rate, max_time_step);
    const double need = std::ceil(longest / max_step - 1e-9);
    if (need > kMaxSubsteps) {
      std::ostringstream os;
      os << max_step << " s would need " << need << " substeps for an interval of " << longest
         << " s (max_time_step or max_catchup_periods / rate); the limit is " << kMaxSubsteps
         << ": use max_step >= " << longest / kMaxSubsteps << " s or 0 (no substeps)";
      bad("service.max_step", os.str());
    }
  }
  if (!lcm_url_out.empty() && lcm_url_out.find("://") == std::string::npos)
    bad("service.lcm_url_out", "must be an LCM URL such as \"udpm://239.255.76.67:7668?ttl=0\" (or \"\" for lcm_url), got \"" +
                                   lcm_url_out + "\"");
  for (char c : channel_prefix)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '/'))
      bad("service.channel_prefix", "may contain only letters, digits and _ - . /");
  if (channel_prefix.size() > 64) bad("service.channel_prefix", "at most 64 characters");
}

void ForecastConfig::validate(double service_rate) const {
  const char* f = "forecast.";
  checkRange("rate", rate, 0.0, 10.0, true, f);
  if (std::isfinite(service_rate) && service_rate > 0.0 && rate > service_rate) {
    std::ostringstream os;
    os << "must be <= service.rate = " << service_rate << " Hz, got " << rate;
    bad("forecast.rate", os.str());
  }
  checkRange("horizon", horizon, 0.0, 600.0, true, f);
  if (std::isfinite(service_rate) && service_rate > 0.0 && horizon < 1.0 / service_rate) {
    std::ostringstream os;
    os << "must be at least one step (1 / service.rate = " << 1.0 / service_rate << " s), got " << horizon;
    bad("forecast.horizon", os.str());
  }
  checkRange("estop_decel", estop_decel, 0.0, 50.0, true, f);
  checkRange("estop_jerk", estop_jerk, 0.0, 1000.0, true, f);
  checkRange("vmax", vmax, 0.0, 100.0, true, f);
  checkRange("amax", amax, 0.0, 50.0, true, f);
  checkRange("jerk", jerk, 0.0, 1000.0, true, f);
  checkRange("plan_timeout", plan_timeout, 0.0, 3600.0, true, f);
  checkRange("workers", workers, 1, 16, false, f);
  checkRange("series_points", series_points, 1, 64, false, f);
  checkRange("modes", modes, 1, kMaxModes, false, f);
}

void EstimatorConfig::validate() const {
  checkRange("max_clock_offset", max_clock_offset, 0.0, 10.0, true, "sensors.");
  checkRange("clear_hold", clear_hold, 0.0, 60.0, false, "estimator.");
}

}  // namespace hoist::service::core
