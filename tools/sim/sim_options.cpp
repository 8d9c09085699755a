// hoist-sim's options: see sim_options.hpp.
#include "sim_options.hpp"

#include <algorithm>
#include <sstream>

#include "hoist/io/profile.hpp"
#include "hoist/shaft_model.hpp"

namespace hoist::sim {

void addOptions(CLI::App& app, Options& o) {
  app.add_option("--config", o.config, "shaft TOML; missing keys take the paper's values (--print-config lists every key)")
      ->check(CLI::ExistingFile);
  app.add_option("--profile", o.profile, std::string("hoist profile CSV or SPEC (default: paper)\n") +
                                             hoist::io::profileSpecHelp());
  app.add_option("--out", o.out, "result CSV to write");
  app.add_option("--dt", o.dt, "output time step [s]")->capture_default_str()->check(CLI::Range(1e-6, 1.0));
  app.add_option("--max-step", o.max_step,
                 "largest integration step [s]; each --dt is split into equal substeps no longer than this "
                 "(0: integrate with --dt). The default keeps the constraint forces within 0.5 % for a rest start")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--t-end", o.t_end, "stop at this time [s] (default: the profile's end)");
  app.add_option("--modes", o.modes, "assumed modes per rope n (overrides model.modes)")
      ->check(CLI::Range(1, hoist::kMaxModes));
  // --initial: the same values, meaning and default as in hoist-study.
  app.add_option("--initial", o.initial,
                 "initial state: static (equilibrium at t = 0), rest (q = 0: the eccentric load acts as a step, as in the "
                 "paper's figures) or config (the config's model.initial, static unless set); default: config")
      ->check(CLI::IsMember({"static", "rest", "config"}));
  app.add_option("--method", o.method,
                 "fast: structured KKT solver (default); paper: the paper's literal partition, Eqs. (18)-(24)")
      ->capture_default_str()
      ->check(CLI::IsMember({"fast", "paper"}));
  app.add_option("--static-correction", o.static_correction,
                 "residual flexibility of the guide ropes at the sleeves (overrides model.static_correction, "
                 "default on; off = the paper's truncation, required by --method paper)")
      ->check(CLI::IsMember({"on", "off"}));
  app.add_option("--rho-inf", o.rho_inf, "generalized-alpha spectral radius (overrides model.rho_inf)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--shape-out", o.shape_out, "guide-rope shape CSV (t,x,y1,y2) at --shape-times");
  app.add_option("--shape-times", o.shape_times, "comma-separated times [s] for --shape-out")->capture_default_str();
  app.add_option("--shape-points", o.shape_points, "depth samples per shape")
      ->capture_default_str()
      ->check(CLI::Range(2, 100000));
  app.add_option("--estop-at", o.estop_at,
                 "emergency stop at this time [s] (rounded to an output step): the profile up to it, then the "
                 "look-ahead forecast's 'estop' scenario -- |a| builds up at --estop-jerk to --estop-decel against "
                 "the motion, holds, eases off so that v and a reach 0 together, then rest");
  app.add_option("--estop-decel", o.estop_decel, "emergency-stop deceleration for --estop-at [m/s^2]")
      ->capture_default_str()
      ->check(CLI::Range(1e-6, 100.0));
  app.add_option("--estop-jerk", o.estop_jerk,
                 "emergency-stop jerk for --estop-at [m/s^3] (brake build-up: decel/jerk = 0.3 s by default)")
      ->capture_default_str()
      ->check(CLI::Range(1e-6, 1e6));
  app.add_option("--write-profile", o.write_profile, "also write the profile used as CSV t,l,v,a");
  auto* write_meas = app.add_option(
      "--write-measurements", o.write_measurements,
      "also write what a cage IMU and a rope load cell read on this run (t,l,v,a,f_y,omega,rope_load; input of "
      "hoist-estimate): the sensor model on the response plus seeded Gaussian noise; --out may then be left out");
  app.add_option("--sensor-noise", o.sensor_noise,
                 "A,W,F: noise standard deviations of f_y [m/s^2], omega [rad/s] and rope_load [N] for "
                 "--write-measurements (default: the config's [sensors], else 0.002,0.0001,20)")
      ->needs(write_meas);
  app.add_option("--seed", o.seed, "seed of --write-measurements' noise (default 1)")->needs(write_meas);
  app.add_flag("--print-config", o.print_config, "print the effective shaft configuration as TOML and exit");
  app.add_flag("-q,--quiet", o.quiet,
               "no progress, estimate or summary (a long run, e.g. --method paper, then shows nothing for "
               "minutes: add --progress)");
  app.add_flag("--progress", o.progress,
               "show progress on stderr even with -q or without a terminal (then one line per 10 %)");
}

std::vector<double> parseTimes(const std::string& s) {
  std::vector<double> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t pos = 0;
    double v = 0;
    try {
      v = std::stod(item, &pos);
    } catch (...) {
      pos = 0;
    }
    while (pos < item.size() && item[pos] == ' ') ++pos;
    if (item.empty() || pos != item.size() || !std::isfinite(v))
      throw UsageError("--shape-times: expected comma-separated seconds, got '" + item + "'");
    out.push_back(v);
  }
  if (out.empty()) throw UsageError("--shape-times: no times given");
  std::sort(out.begin(), out.end());
  return out;
}

hoist::SensorNoise parseSensorNoise(const std::string& s) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t pos = 0;
    double x = 0;
    try {
      x = std::stod(item, &pos);
    } catch (...) {
      pos = 0;
    }
    while (pos < item.size() && item[pos] == ' ') ++pos;
    if (item.empty() || pos != item.size() || !std::isfinite(x) || x < 0.0)
      throw UsageError("--sensor-noise: expected three standard deviations >= 0 (f_y [m/s^2], omega [rad/s], "
                       "rope_load [N]), got '" + item + "'");
    v.push_back(x);
  }
  if (v.size() != 3)
    throw UsageError("--sensor-noise: expected three comma-separated values A,W,F (f_y [m/s^2], omega [rad/s], "
                     "rope_load [N]), got " + std::to_string(v.size()));
  hoist::SensorNoise n;
  n.imu_accel = v[0];
  n.imu_rate = v[1];
  n.rope_load = v[2];
  return n;
}

}  // namespace hoist::sim
