// hoist-sim's run: see sim_run.hpp.
#include "sim_run.hpp"

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

namespace hoist::sim {

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

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

}  // namespace

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
            // Stamped as a sensor clock stamps it, in whole microseconds:
            // hoist-replay's utime then carries this very t to hoist-twind,
            // so the live estimator sees the times hoist-estimate reads (r.t
            // is a sum of steps, 0.35000000000000003 for 0.35 s).
            meas.t = std::round(r.t * 1e6) / 1e6;
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

}  // namespace hoist::sim
