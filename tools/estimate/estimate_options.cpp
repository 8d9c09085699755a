// hoist-estimate's options: see estimate_options.hpp.
#include "estimate_options.hpp"

#include <cstdio>
#include <utility>

#include "hoist/params.hpp"
#include "hoist/profile.hpp"

namespace hoist::estimate {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

void addOptions(CLI::App& app, Options& o) {
  app.add_option("--config", o.config,
                 "shaft TOML or hoist-twind's configuration: the twin's shaft, [sensors] noise and [estimator] "
                 "tuning (enabled is not needed here); required")
      ->check(CLI::ExistingFile);
  app.add_option("--measurements", o.measurements, "measurement CSV (t,l,v,a[,f_y,omega,rope_load]); required")
      ->check(CLI::ExistingFile);
  app.add_option("--out", o.out, "estimate CSV to write (one row per measurement row); required");
  app.add_option("--modes", o.modes, "assumed modes per rope n (overrides model.modes)")
      ->check(CLI::Range(1, hoist::kMaxModes));
  app.add_option("--max-step", o.max_step,
                 "largest integration step [s] (default: the config's [service] max_step, else " +
                     fmt("%g", hoist::kDefaultMaxStep) + " as in hoist-twind; 0: one step per row)")
      ->check(CLI::Range(0.0, 10.0));
  app.add_option("--known-load", o.known_load,
                 "T0,T1,FA,B: the load is known to be FA [N] at B [m] from T0 to T1 [s] (the calibration: the "
                 "estimator learns the accelerometer's offset); repeatable")
      ->take_all()
      ->allow_extra_args(false);
  app.add_option("--offset-in", o.offset_in, "start from the accelerometer offset in FILE (written by --offset-out or hoist-twind)")
      ->check(CLI::ExistingFile);
  app.add_option("--offset-out", o.offset_out, "write the learned accelerometer offset and its sigma to FILE");
  app.add_flag("--progress", o.progress, "show progress on stderr");
  app.add_flag("--no-trips", o.no_trips,
               "do not state per trip whether the IMU could see a 30 % guide-rope preload loss, nor "
               "MODEL_MISMATCH's trip-end preload test (both identify the preload scale of each trip: about 1 s "
               "of CPU per trip at n = 25)");
  app.add_flag("-q,--quiet", o.quiet, "no summary and no warnings");
}

std::optional<std::string> missingRequired(const Options& o) {
  for (const auto& [given, what] : {std::pair{!o.config.empty(), "--config"},
                                    std::pair{!o.measurements.empty(), "--measurements"},
                                    std::pair{!o.out.empty(), "--out"}})
    if (!given) return std::string(what);
  return std::nullopt;
}

}  // namespace hoist::estimate
