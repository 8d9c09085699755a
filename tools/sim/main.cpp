// hoist-sim -- run the cable-guided hoist model of Wang et al. (2016) over a
// whole hoist profile as fast as possible and write the cage response.
//
//   hoist-sim [--config FILE] --profile FILE|SPEC --out FILE.csv [--dt 0.01]
//             [--modes N] [--initial static|rest|config] [--method fast|paper]
//             [--static-correction on|off]
//             [--shape-out FILE.csv --shape-times 18,36,60]
//             [--write-measurements FILE.csv [--sensor-noise A,W,F] [--seed N]]
//   hoist-sim study ...        (runs hoist-study: the paper's parameter studies)
//
// Phases, each timed in the summary: load (config, profile), setup (mode
// integrals, solver), solve (time stepping), output (formatting and writing
// the rows, which are streamed to the file as they are computed: memory
// stays flat whatever --t-end).  Before a large run (over 1e7 rows, 1 GB or
// an estimated 30 s) one line states the estimated rows, size and time; a
// run whose output cannot fit the free space of --out's file system is
// refused.  Every file is written to its last byte or the run fails naming
// it (hoist/io/checked_file.hpp).
// --write-measurements: what a cage IMU and a rope load cell would read on
// this run (hoist::sensorModel on the solver's response, plus seeded
// Gaussian noise), in the measurement CSV of hoist-estimate
// (t,l,v,a,f_y,omega,rope_load; hoist/io/estimator_config.hpp).  The run's
// load is the config's: a "truth" config with another [load] makes data for
// hoist-estimate run with the real config.
// Exit status: 0 done, 2 bad input (config, profile, options), 1 the run
// failed (non-finite or implausible state -- the message names the time, the
// quantity and its value --, write error, out of memory).
#include "hoist/version.hpp"
#include <unistd.h>

#include <sys/stat.h>
#include <sys/statvfs.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <new>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "hoist/io/checked_file.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/estimator_config.hpp"
#include "hoist/io/profile.hpp"
#include "hoist/io/results.hpp"
#include "hoist/io/sim_run.hpp"
#include "hoist/scenario.hpp"
#include "hoist/shaft_model.hpp"
#include "hoist/plausibility.hpp"
#include "hoist/simulator.hpp"
#include "hoist/load_estimator.hpp"
#include <random>

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct Options {
  std::string config, profile = "paper", out, shape_out, shape_times = "18,36,60", write_profile;
  double dt = 0.01, max_step = 0.0025, t_end = -1.0, rho_inf = -1.0;
  double estop_at = std::nan(""), estop_decel = 3.0, estop_jerk = 10.0;
  int modes = 0, shape_points = 401;
  std::string initial, method = "fast", static_correction;
  bool quiet = false, print_config = false, progress = false;
  // --write-measurements (synthetic sensor data for hoist-estimate)
  std::string write_measurements, sensor_noise;
  std::uint64_t seed = 1;
};

/// The command line, for the messages of unexpected failures (out of memory).
std::string g_command_line;

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

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

/// --sensor-noise A,W,F: three finite standard deviations >= 0.
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

/// Progress on stderr: on a terminal one line rewritten in place; with
/// --progress and no terminal, one line per 10 % (a log stays readable).
class Progress {
 public:
  enum class Mode { Off, Terminal, Lines };
  explicit Progress(Mode m) : mode_(m), start_(Clock::now()) {}
  void update(double frac, double t_model) {
    if (mode_ == Mode::Off) return;
    const double el = secondsSince(start_);
    const double eta = frac > 0.01 ? el * (1.0 - frac) / frac : 0.0;
    if (mode_ == Mode::Lines) {
      const int decile = static_cast<int>(frac * 10.0 + 1e-9);
      if (decile <= last_decile_) return;
      last_decile_ = decile;
      std::fprintf(stderr, "hoist-sim: progress %3d %%  t = %.2f s  elapsed %.1f s  eta %.1f s\n", decile * 10,
                   t_model, el, eta);
      std::fflush(stderr);
      return;
    }
    const int width = 30, filled = static_cast<int>(frac * width);
    std::fprintf(stderr, "\r  [%.*s%*s] %3.0f%%  t = %7.2f s  elapsed %5.1f s  eta %5.1f s ", filled,
                 "==============================", width - filled, "", frac * 100.0, t_model, el, eta);
    std::fflush(stderr);
  }
  void done() {
    if (mode_ == Mode::Terminal) std::fprintf(stderr, "\r%*s\r", 90, "");
  }

 private:
  Mode mode_;
  Clock::time_point start_;
  int last_decile_ = 0;
};

/// Human-readable byte count.
std::string bytesText(double b) {
  char buf[64];
  if (b >= 1e12) std::snprintf(buf, sizeof buf, "%.1f TB", b / 1e12);
  else if (b >= 1e9) std::snprintf(buf, sizeof buf, "%.1f GB", b / 1e9);
  else if (b >= 1e6) std::snprintf(buf, sizeof buf, "%.1f MB", b / 1e6);
  else std::snprintf(buf, sizeof buf, "%.0f kB", b / 1e3);
  return buf;
}

std::string secondsText(double s) {
  char buf[64];
  if (s >= 86400.0) std::snprintf(buf, sizeof buf, "%.1f days", s / 86400.0);
  else if (s >= 3600.0) std::snprintf(buf, sizeof buf, "%.1f h", s / 3600.0);
  else if (s >= 60.0) std::snprintf(buf, sizeof buf, "%.1f min", s / 60.0);
  else std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Size of a result row: 12 columns of shortest round-trip doubles, about 15
// bytes each with the separator (measured: 164 B/row at rest, 181 B/row on
// the paper trip).
constexpr double kBytesPerRow = 12 * 15.0;
// A run over any of these gets the estimate line before it starts.
constexpr double kLargeRows = 1e7, kLargeBytes = 1e9, kLargeSeconds = 30.0;
// More output steps than this are refused (1e12 rows are 180 TB).
constexpr double kMaxOutputSteps = 1e12;

/// Free bytes on the file system that would hold `path` (plus the size of
/// the file it would replace), or < 0 when unknown or not a regular file
/// (a device such as /dev/null, a pipe).
double freeBytesFor(const std::string& path) {
  struct stat st {};
  double existing = 0.0;
  if (::stat(path.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode)) return -1.0;
    existing = static_cast<double>(st.st_size);
  }
  std::string dir = path;
  const auto slash = dir.find_last_of('/');
  dir = slash == std::string::npos ? std::string(".") : dir.substr(0, slash == 0 ? 1 : slash);
  struct statvfs vf {};
  if (::statvfs(dir.c_str(), &vf) != 0) return -1.0;
  return static_cast<double>(vf.f_bavail) * static_cast<double>(vf.f_frsize) + existing;
}

/// Step cost [us per integration step] of this configuration, measured on
/// a scratch solver over at most 200 steps or 0.2 s; < 0 if it failed.
double measureStepUs(const std::shared_ptr<const hoist::ShaftModel>& model, hoist::Method method,
                     const hoist::HoistProfile& profile, double t0, double h, hoist::InitialState init) {
  try {
    auto s = hoist::makeSolver(method, model);
    s->initialize(t0, profile.at(t0), init);
    const auto start = Clock::now();
    int n = 0;
    while (n < 200) {
      const double t = t0 + static_cast<double>(n + 1) * h;
      s->step(t, profile.at(t));
      ++n;
      if (secondsSince(start) > 0.2) break;
    }
    return 1e6 * secondsSince(start) / n;
  } catch (const std::exception&) {
    return -1.0;
  }
}

struct Peak {
  double value = 0.0, t = 0.0;
  void see(double v, double t_) {
    if (std::abs(v) > value) {
      value = std::abs(v);
      t = t_;
    }
  }
};

/// Runs `hoist-study` (next to this executable) with the remaining arguments.
int runStudy(int argc, char** argv) {
  std::string self(4096, '\0');
  const ssize_t n = ::readlink("/proc/self/exe", self.data(), self.size() - 1);
  std::string dir = n > 0 ? self.substr(0, static_cast<std::size_t>(n)) : std::string(argv[0]);
  dir = dir.substr(0, dir.find_last_of('/') + 1);
  const std::string study = dir + "hoist-study";
  std::vector<char*> args;
  args.push_back(const_cast<char*>(study.c_str()));
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  ::execv(study.c_str(), args.data());
  std::cerr << "hoist-sim: cannot run " << study << ": " << std::strerror(errno) << "\n";
  return 2;
}

int run(const Options& o) {
  const auto t_load = Clock::now();
  // ---- load -------------------------------------------------------------
  hoist::ShaftParams p;
  // A daemon configuration (shaft + [service]/[alarms]/...) is accepted as
  // well; hoist-twind validates those sections, except [sensors] and
  // [estimator], read here: [sensors] is --write-measurements' default noise.
  hoist::SensorNoise noise;
  if (!o.config.empty()) {
    const toml::table tbl = hoist::io::loadTomlFile(o.config);
    p = hoist::io::shaftParamsFromToml(tbl, o.config, hoist::io::daemonSections());
    noise = hoist::io::estimatorConfigFromToml(tbl, o.config).settings.noise;
  }
  if (!o.sensor_noise.empty()) noise = parseSensorNoise(o.sensor_noise);
  if (!o.write_measurements.empty() && o.method == "paper")
    throw UsageError("--write-measurements needs the cage's rates, which only --method fast computes");
  // The run options -> parameters, end time, in-shaft check and simulator
  // options: hoist/io/sim_run.hpp, shared with the Python module.
  hoist::io::SimRunOptions ro;
  ro.dt = o.dt;
  ro.max_step = o.max_step;
  ro.t_end = o.t_end;
  ro.rho_inf = o.rho_inf;
  ro.modes = o.modes;
  ro.initial = o.initial;
  ro.method = o.method;
  ro.static_correction = o.static_correction;
  hoist::io::applySimOverrides(p, ro);
  if (o.print_config) {
    std::cout << hoist::io::toToml(p);
    return 0;
  }
  hoist::HoistProfile profile = hoist::io::loadProfile(o.profile, p.l0);
  if (!std::isnan(o.estop_at)) {
    // The forecast's "estop" scenario (hoist/scenario.hpp) from T: the profile
    // up to T, then the jerk-limited stop from its (l, v, a) at T, sampled on
    // the output grid.  T is rounded to the nearest output step (the forecast
    // starts at a step of the twin), so the run equals the twin's e-stop
    // forecast made at T.
    hoist::MotionProfile stop;
    profile = hoist::io::estopRun(profile, o.t_end, o.estop_at, o.estop_decel, o.estop_jerk, o.dt, &stop);
    const double T = stop.startTime();
    if (!o.quiet)
      std::cerr << "hoist-sim: emergency stop at t = " << T << " s from l = " << stop.start().l
                << " m, v = " << stop.start().v << " m/s, a = " << stop.start().a << " m/s^2: rest at t = "
                << stop.endTime() << " s, l = " << stop.end().l << " m\n";
  }
  if (!o.write_profile.empty()) {
    hoist::io::CheckedFile pf(o.write_profile, "--write-profile");
    hoist::io::writeProfileCsv(pf, profile);
    pf.close();
    if (!o.quiet) std::cerr << "hoist-sim: profile written to " << o.write_profile << "\n";
    if (o.out.empty() && o.write_measurements.empty()) return 0;
  }
  if (o.out.empty() && o.write_measurements.empty())
    throw UsageError("--out FILE.csv is required (or --write-measurements, or --write-profile / --print-config alone)");
  const double t0 = profile.startTime();
  const double t_end = hoist::io::simEndTime(profile, o.t_end);
  // How much output this is, before anything is allocated or written.
  const double steps_d = std::round((t_end - t0) / o.dt);
  const std::string t_end_opt = "--t-end " + num(t_end) + (o.t_end < 0 ? " (the profile's end)" : "");
  if (steps_d > kMaxOutputSteps)
    throw UsageError(t_end_opt + ": " + num(steps_d) + " output steps at --dt " + num(o.dt) + " s, more than " +
                     num(kMaxOutputSteps) + " (" + bytesText(kMaxOutputSteps * kBytesPerRow) +
                     " of CSV); shorten --t-end or raise --dt");
  hoist::io::checkSimulatedPartInShaft(profile, p, t_end, o.dt, o.profile);
  int sub = 1;
  const hoist::SimulationOptions sim = hoist::io::simulationOptions(ro, p, t_end, sub);
  std::vector<double> shape_times;
  if (!o.shape_out.empty()) {
    shape_times = parseTimes(o.shape_times);
    for (double ts : shape_times)
      if (ts < t0 - 1e-9 || ts > t_end + 1e-9)
        throw UsageError("--shape-times: " + std::to_string(ts) + " s is outside the run [" + std::to_string(t0) +
                         ", " + std::to_string(t_end) + "] s");
  }
  const double rows_est = steps_d + 1.0;
  const double shape_bytes_est =
      static_cast<double>(shape_times.size()) * std::max(2, o.shape_points) * 4 * 15.0;
  const double bytes_est = rows_est * kBytesPerRow;
  // A run that cannot fit the disk is refused now, not after hours.
  if (const double free = o.out.empty() ? -1.0 : freeBytesFor(o.out); free >= 0.0 && bytes_est > free)
    throw UsageError(t_end_opt + ": the output would be about " + bytesText(bytes_est) + " (" + num(rows_est) +
                     " rows of about " + num(kBytesPerRow) + " B at --dt " + num(o.dt) + " s), but only " +
                     bytesText(free) + " are free for --out " + o.out + "; shorten --t-end or raise --dt");
  // Open outputs before the long part so a bad path fails at once; rows are
  // streamed into them as they are computed.
  hoist::io::CheckedFile out;
  if (!o.out.empty()) out = hoist::io::CheckedFile(o.out, "--out");
  hoist::io::CheckedFile meas_file;
  if (!o.write_measurements.empty()) meas_file = hoist::io::CheckedFile(o.write_measurements, "--write-measurements");
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  hoist::MeasurementSample meas;
  meas.present = hoist::kSensorImuAccel | hoist::kSensorImuRate | hoist::kSensorRopeLoad;
  hoist::io::CheckedFile shape_file;
  if (!o.shape_out.empty()) shape_file = hoist::io::CheckedFile(o.shape_out, "--shape-out");
  const double load_s = secondsSince(t_load);

  // ---- setup ------------------------------------------------------------
  const auto t_setup = Clock::now();
  auto model = std::make_shared<const hoist::ShaftModel>(p);
  auto solver = hoist::makeSolver(sim.method, model);
  double step_us = -1.0;
  if (!o.quiet) step_us = measureStepUs(model, sim.method, profile, t0, o.dt / sub, p.initial);
  const double setup_s = secondsSince(t_setup);

  const long steps = static_cast<long>(steps_d);
  if (!o.quiet) {
    std::cerr << "hoist-sim: " << hoist::toString(sim.method) << " path, n = " << p.n << ", initial = "
              << hoist::toString(p.initial) << ", static correction "
              << (p.static_correction ? "on" : "off") << ", t = " << t0 << " .. " << t_end << " s, dt = " << o.dt << " s ("
              << sub << " substep" << (sub > 1 ? "s" : "") << " of " << o.dt / sub << " s), " << steps
              << " output steps\n";
    const double secs_est = step_us > 0.0 ? step_us * 1e-6 * steps_d * sub : 0.0;
    if (rows_est > kLargeRows || bytes_est + shape_bytes_est > kLargeBytes || secs_est > kLargeSeconds)
      std::cerr << "hoist-sim: large run: about " << num(rows_est) << " rows, " << bytesText(bytes_est + shape_bytes_est)
                << " to " << o.out << ", about "
                << (step_us > 0.0 ? secondsText(secs_est) + " of computing (" + num(step_us) + " us per step measured)"
                                  : std::string("? of computing (step cost not measured)"))
                << "\n";
  }

  // ---- solve --------------------------------------------------------------
  const hoist::VectorXd xs = hoist::VectorXd::LinSpaced(std::max(2, o.shape_points), 0.0, p.L);
  hoist::VectorXd y1(xs.size()), y2(xs.size());
  std::size_t next_shape = 0;
  Peak pk_y, pk_th, pk_x, pk_l[5];
  const Progress::Mode pmode = o.progress ? (::isatty(2) ? Progress::Mode::Terminal : Progress::Mode::Lines)
                               : (!o.quiet && ::isatty(2)) ? Progress::Mode::Terminal
                                                           : Progress::Mode::Off;
  Progress progress(pmode);
  if (out.isOpen()) out.write(std::string(hoist::io::kResultHeader) + "\n");
  if (meas_file.isOpen()) meas_file.write(std::string(hoist::io::kMeasurementHeader) + "\n");
  if (shape_file.isOpen()) shape_file.write(std::string(hoist::io::kShapeHeader) + "\n");
  std::string line;
  line.reserve(512);
  std::size_t rows = 0;
  double out_s = 0.0;
  const auto t_solve = Clock::now();
  bool failed = false;
  double fail_t = 0;
  // Finite is not enough: a state that leaves the plausible range
  // (hoist/plausibility.hpp, lateral limit 1 m) stops the run too.
  const hoist::PlausibilityBounds bounds = hoist::plausibilityBounds(p, 1.0);
  const char* implausible_what = nullptr;
  double implausible_value = 0.0, implausible_limit = 0.0;
  struct Diverged {};
  try {
    hoist::simulate(
        *solver, profile, sim,
        [&](const hoist::CageResponse& r) {
          if (!solver->finite() || !std::isfinite(r.y_c) || !std::isfinite(r.theta) || !std::isfinite(r.x_c)) {
            failed = true;
            fail_t = r.t;
            throw Diverged{};
          }
          implausible_what = hoist::implausible(r, p.h, bounds, implausible_value, implausible_limit);
          if (implausible_what) {
            failed = true;
            fail_t = r.t;
            throw Diverged{};
          }
          const auto tw = Clock::now();
          line.clear();
          hoist::io::appendResultRow(line, r);
          if (out.isOpen()) out.write(line);
          if (meas_file.isOpen()) {
            // The sensor model on this response plus noise, drawn in a fixed order (reproducible by --seed).
            const hoist::SensorValues z = hoist::sensorModel(r, p.g);
            meas.t = r.t;
            meas.k = r.kin;
            meas.z.f_y = z.f_y + noise.imu_accel * n01(rng);
            meas.z.omega = z.omega + noise.imu_rate * n01(rng);
            meas.z.rope_load = z.rope_load + noise.rope_load * n01(rng);
            line.clear();
            hoist::io::appendMeasurementRow(line, meas);
            meas_file.write(line);
          }
          ++rows;
          pk_x.see(r.x_c, r.t);
          pk_y.see(r.y_c, r.t);
          pk_th.see(r.theta, r.t);
          for (int k = 0; k < 5; ++k) pk_l[k].see(r.lambda[static_cast<std::size_t>(k)], r.t);
          while (next_shape < shape_times.size() && r.t >= shape_times[next_shape] - 0.5 * o.dt) {
            solver->guideRopeShapes(xs, y1, y2);
            line.clear();
            hoist::io::appendShapeRows(line, r.t, xs, y1, y2);
            shape_file.write(line);
            ++next_shape;
          }
          out_s += secondsSince(tw);
        },
        [&](double f) { progress.update(f, t0 + f * (t_end - t0)); });
  } catch (const Diverged&) {
  } catch (const std::domain_error& e) {
    progress.done();
    throw std::runtime_error(std::string("the model left its domain: ") + e.what());
  } catch (...) {
    progress.done();
    throw;
  }
  progress.done();
  const double solve_s = secondsSince(t_solve) - out_s;
  if (failed && implausible_what) {
    std::cerr << "hoist-sim: error: implausible state at t = " << fail_t << " s: " << implausible_what << " = "
              << implausible_value << " (plausible: |" << implausible_what << "| <= " << implausible_limit
              << "; valid rope lengths are [" << hoist::validLengthRange(p).lo << ", "
              << hoist::validLengthRange(p).hi << "] m). " << rows << " good rows are written.\n";
  } else if (failed) {
    std::cerr << "hoist-sim: error: the state became non-finite at t = " << fail_t
              << " s (unstable parameters or step; try a smaller --dt / --max-step). " << rows
              << " good rows are written.\n";
  }

  // ---- output: the last bytes -------------------------------------------
  const auto t_out = Clock::now();
  out.close();
  shape_file.close();
  meas_file.close();
  out_s += secondsSince(t_out);

  if (!o.quiet) {
    const double total_steps = rows == 0 ? 0.0 : static_cast<double>(rows - 1) * sub;
    std::fprintf(stderr,
                 "hoist-sim: wrote %zu rows to %s%s%s\n"
                 "  peak |x_c|      = %.4e m    at t = %.2f s\n"
                 "  peak |y_c|      = %.4e m    at t = %.2f s\n"
                 "  peak |theta|    = %.4e rad  at t = %.2f s\n"
                 "  peak |lambda_0| = %.4e N    at t = %.2f s\n",
                 rows, o.out.empty() ? o.write_measurements.c_str() : o.out.c_str(), o.shape_out.empty() ? "" : ", shapes to ", o.shape_out.c_str(), pk_x.value,
                 pk_x.t, pk_y.value, pk_y.t, pk_th.value, pk_th.t, pk_l[0].value, pk_l[0].t);
    for (int k = 1; k < 5; ++k)
      std::fprintf(stderr, "  peak |lambda_%d| = %.4e N    at t = %.2f s\n", k, pk_l[k].value, pk_l[k].t);
    std::fprintf(stderr,
                 "  time: load %.3f s, setup %.3f s, solve %.3f s (%.0f steps/s, %.2f us/step), output %.3f s\n",
                 load_s, setup_s, solve_s, total_steps / std::max(solve_s, 1e-9),
                 1e6 * solve_s / std::max(total_steps, 1.0), out_s);
  }
  return failed ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "study") return runStudy(argc, argv);
  Options o;
  CLI::App app{
      "hoist-sim: lateral, torsional and longitudinal vibration of a cable-guided hoist\n"
      "(Wang, Cao, Zhu, Peng & Li 2016) over a whole hoist profile, as fast as possible.\n"
      "Writes t,l,v,a,x_c,y_c,theta,lambda_0..lambda_4 per output step.\n"
      "Also: 'hoist-sim study NAME ...' runs the paper's parameter studies (hoist-study --help).",
      "hoist-sim"};
  app.name("hoist-sim");  // usage lines name the program, not the path it was run by
  app.failure_message([](const CLI::App* a, const CLI::Error& e) { return a->get_name() + ": " + CLI::FailureMessage::simple(a, e); });  // errors name the program
  app.set_version_flag("--version", std::string("hoist-sim ") + hoist::kVersionString);
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  for (int i = 0; i < argc; ++i) {
    if (i) g_command_line += ' ';
    g_command_line += i == 0 ? std::string("hoist-sim") : std::string(argv[i]);
  }
  try {
    return run(o);
  } catch (const hoist::io::InputError& e) {
    std::cerr << "hoist-sim: error: " << e.what() << "\n";
    return 2;
  } catch (const UsageError& e) {
    std::cerr << "hoist-sim: error: " << e.what() << "\n";
    return 2;
  } catch (const hoist::io::OptionError& e) {
    std::cerr << "hoist-sim: error: " << e.what() << "\n";
    return 2;
  } catch (const hoist::io::WriteError& e) {
    // Names the option and the file, with the errno text.
    std::cerr << "hoist-sim: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "hoist-sim: error: out of memory (std::bad_alloc) in: " << g_command_line
              << "\n  (the memory grows with --modes, --shape-points and the profile's length; the output rows are "
                 "streamed and cost none)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "hoist-sim: error: " << e.what() << "\n  in: " << g_command_line << "\n";
    return 1;
  } catch (...) {
    std::cerr << "hoist-sim: error: unexpected failure in: " << g_command_line << "\n";
    return 1;
  }
}
