// hoist-estimate -- the load estimator on recorded data: the eccentric
// load's force Fa, offset b and moment M = Fa b, the cage state they imply
// and the model check (NIS, MODEL_MISMATCH), from a measurement CSV of the
// winder (t,l,v,a) and the sensors (f_y, omega, rope_load; any may be
// absent).  The same code as hoist-twind's live estimator
// (hoist::estimateRecorded, hoist/load_estimator.hpp): with the same
// configuration and `hoist-twind --clock input` both give the same numbers.
//
//   hoist-estimate --config FILE --measurements FILE.csv --out FILE.csv
//                  [--modes N] [--max-step S] [--progress] [-q]
//                  [--known-load T0,T1,FA,B]... [--offset-in FILE] [--offset-out FILE]
//
// The accelerometer's offset (docs/estimation.md): --known-load declares the
// load known over [T0, T1) (the operator's calibration: an empty conveyance,
// a test weight), so the data teach the offset; --offset-in starts from a
// learned one, --offset-out writes the last row's (hoist/io/accel_offset_file.hpp).
//
// --config: a shaft TOML or hoist-twind's configuration ([service],
// [alarms], [forecast], [sensors], [estimator] are accepted; [estimator]
// enabled is not needed here).  The substep length is --max-step, else the
// file's [service] max_step, else hoist::kDefaultMaxStep (0.0025 s, the daemon's default), so that
// the live and offline estimators agree.  The NIS window is sized for the
// file's rate: [estimator] max_rate is raised to the fastest row rate when
// that is higher (the daemon sizes it for its own rate).
// Output: one row per measurement row (kOutputHeader); a value that is not
// observed (sigma < 0 in the estimate, or its sensor not seen yet:
// fa_observed / moment_observed) is written as nan with its sigma.
// A one-paragraph summary goes to stdout (not with -q).
// Exit status: 0 done, 2 bad input (naming file, line, column or option),
// 1 the run failed (model domain, write error).
#include "hoist/cli/app.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <new>
#include <optional>
#include <sstream>
#include <vector>

#include <CLI/CLI.hpp>

#include "hoist/io/accel_offset_file.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/io/config.hpp"
#include "hoist/io/estimator_config.hpp"
#include "hoist/io/recorded_run.hpp"
#include "hoist/io/profile.hpp"
#include "hoist/io/results.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/profile.hpp"
#include "hoist/preload_verdict.hpp"
#include "hoist/trip_recorder.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string config, measurements, out;
  int modes = 0;
  double max_step = -1.0;
  bool progress = false, quiet = false, no_trips = false;
  std::vector<std::string> known_load;  // T0,T1,FA,B each
  std::string offset_in, offset_out;
};

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

constexpr const char* kOutputHeader =
    "t,l,Fa,b,moment,sigma_Fa,sigma_moment,y_c,theta,sigma_y_c,sigma_theta,"
    "lambda_0,lambda_1,lambda_2,lambda_3,lambda_4,nis,nis_window,mismatch,"
    "sigma_b,x_c,sigma_x_c,sigma_lambda_0,sigma_lambda_1,sigma_lambda_2,sigma_lambda_3,sigma_lambda_4,"
    "theta_open,nis_dof,nis_lower,nis_upper,nis_bound,drift,nis_exceeded,drift_exceeded,sensors,"
    "fa_observed,moment_observed,accepted,gated,load_changes,implausible,"
    "plausible,fault_imu_accel,fault_imu_rate,fault_rope_load,noise_imu_accel,noise_imu_rate,noise_rope_load,"
    "change_t,change_Fa,change_moment";

void num(std::string& s, double v) {
  if (std::isnan(v)) s += "nan";
  else hoist::io::appendNumber(s, v);
  s += ',';
}
void integer(std::string& s, long long v) {
  s += std::to_string(v);
  s += ',';
}

/// A value with its sigma; both nan when not observed (sigma < 0, or no
/// sample of its sensor yet: LoadEstimate then carries the prior).
void observed(double v, double sigma, bool seen, double& v_out, double& s_out) {
  const bool ok = seen && sigma >= 0.0;
  v_out = ok ? v : std::nan("");
  s_out = ok ? sigma : std::nan("");
}

void appendRow(std::string& s, const hoist::LoadEstimate& e, const hoist::EstimatorCounters& c) {
  double Fa, sFa, b, sb, M, sM;
  observed(e.Fa, e.sigma_Fa, e.fa_observed, Fa, sFa);
  observed(e.b, e.sigma_b, e.fa_observed && e.moment_observed, b, sb);
  observed(e.moment, e.sigma_moment, e.moment_observed, M, sM);
  num(s, e.t);
  num(s, e.kin.l);
  num(s, Fa);
  num(s, b);
  num(s, M);
  num(s, sFa);
  num(s, sM);
  num(s, e.y_c);
  num(s, e.theta);
  num(s, e.sigma_y_c);
  num(s, e.sigma_theta);
  for (double l : e.lambda) num(s, l);
  num(s, e.nis);
  num(s, e.nis_window);
  integer(s, e.mismatch ? 1 : 0);
  num(s, sb);
  num(s, e.x_c);
  num(s, e.sigma_x_c);
  for (double l : e.sigma_lambda) num(s, l);
  num(s, e.theta_open);
  integer(s, e.nis_dof);
  num(s, e.nis_lower);
  num(s, e.nis_upper);
  num(s, e.nis_bound);
  num(s, e.drift);
  integer(s, e.nis_exceeded ? 1 : 0);
  integer(s, e.drift_exceeded ? 1 : 0);
  integer(s, e.sensors);
  integer(s, e.fa_observed ? 1 : 0);
  integer(s, e.moment_observed ? 1 : 0);
  integer(s, c.accepted);
  integer(s, c.gated);
  integer(s, c.load_changes);
  integer(s, c.implausible);
  integer(s, e.plausible ? 1 : 0);
  integer(s, e.fault_imu_accel);
  integer(s, e.fault_imu_rate);
  integer(s, e.fault_rope_load);
  num(s, e.noise_imu_accel);
  num(s, e.noise_imu_rate);
  num(s, e.noise_rope_load);
  num(s, e.change_t);
  num(s, e.change_Fa);
  num(s, e.change_moment);
  s.back() = '\n';
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string withSigma(const char* name, double v, double sigma, bool seen, const char* unit, const char* f) {
  if (!seen || sigma < 0.0) return std::string(name) + " not observed";
  return std::string(name) + " = " + fmt(f, v) + " +- " + fmt(f, sigma) + " " + unit;
}

std::string sensorNames(unsigned bits) {
  std::string s;
  if (bits & hoist::kSensorImuAccel) s += "f_y";
  if (bits & hoist::kSensorImuRate) s += s.empty() ? "omega" : ", omega";
  if (bits & hoist::kSensorRopeLoad) s += s.empty() ? "rope_load" : ", rope_load";
  return s.empty() ? "none" : s;
}

int run(const Options& o) {
  const auto t_start = Clock::now();
  // ---- input ------------------------------------------------------------
  const toml::table tbl = hoist::io::loadTomlFile(o.config);
  hoist::ShaftParams p = hoist::io::shaftParamsFromToml(tbl, o.config, hoist::io::daemonSections());
  const hoist::io::EstimatorConfig ec = hoist::io::estimatorConfigFromToml(tbl, o.config);
  const double max_step = o.max_step >= 0.0 ? o.max_step : hoist::io::serviceMaxStep(tbl, o.config, hoist::kDefaultMaxStep);
  if (o.modes != 0) p.n = o.modes;
  try {
    p.validate();
  } catch (const hoist::ParamError& e) {
    throw UsageError(std::string("--modes: ") + e.what());
  }
  hoist::io::MeasurementColumns cols;
  const std::vector<hoist::MeasurementSample> samples =
      hoist::io::readMeasurementsCsvFile(o.measurements, {}, &cols);
  // The shaft, the NIS window's rate and the substeps: the checks hoist.estimate shares.
  hoist::EstimatorSettings set;
  try {
    set = hoist::io::checkRecordedRun(samples, p, ec.settings, max_step, o.measurements);
  } catch (const hoist::io::RecordedRunError& e) {
    throw UsageError(e.option == hoist::io::RecordedRunError::Option::MaxStep
                         ? "--max-step " + fmt("%g", max_step) + ": " + e.what()
                         : "--measurements " + o.measurements + ": " + e.what());
  }
  if (cols.sensors == 0 && !o.quiet)
    std::cerr << "hoist-estimate: warning: " << o.measurements
              << " has no sensor column (f_y, omega, rope_load): the estimate is the open-loop twin\n";
  if (!cols.ignored.empty() && !o.quiet) {
    std::string list;
    for (const auto& c : cols.ignored) list += (list.empty() ? "" : ", ") + c;
    std::cerr << "hoist-estimate: " << o.measurements << ": ignored columns: " << list << "\n";
  }
  hoist::RecordedCalibration cal;
  for (const std::string& k : o.known_load) {
    double v[4];
    char tail = 0;
    if (std::sscanf(k.c_str(), "%lf,%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &v[3], &tail) != 4 ||
        !(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) && std::isfinite(v[3])))
      throw UsageError("--known-load " + k + ": expected T0,T1,FA,B (four finite numbers: s, s, N, m)");
    if (!(v[1] > v[0])) throw UsageError("--known-load " + k + ": T1 must be after T0");
    if (v[2] < 0.0) throw UsageError("--known-load " + k + ": FA must be >= 0 N");
    if (std::abs(v[3]) > p.offsetLimit())
      throw UsageError("--known-load " + k + ": |B| beyond the conveyance's half-width " + fmt("%g", p.offsetLimit()) + " m");
    cal.known.push_back({v[0], v[1], v[2], v[3]});
  }
  if (!o.offset_in.empty()) {
    const hoist::io::AccelOffsetRecord r = hoist::io::readAccelOffsetFile(o.offset_in);
    cal.has_offset = true;
    cal.offset = r.offset;
    cal.offset_sigma = r.sigma;
  }
  hoist::io::CheckedFile out(o.out, "--out");

  // ---- estimate -----------------------------------------------------------
  out.write(std::string(kOutputHeader) + "\n");
  std::string line;
  line.reserve(1024);
  hoist::LoadEstimate last;
  hoist::EstimatorCounters counts;
  long rows = 0, mismatch_rows = 0, implausible_rows = 0;
  unsigned faults[3] = {0, 0, 0};  // every fault bit seen, per channel
  std::string first_implausible, changes;
  double last_change = -1.0;
  long n_changes = 0;
  constexpr long kShownChanges = 8;
  double first_mismatch = std::nan("");
  std::string first_why;  // what raised it first: the NIS window against its bound, or a drifting load
  int last_decile = 0;
  const bool tty = ::isatty(2);
  // Each trip of the data (departure to arrival, the daemon's TripRecorder)
  // and whether its IMU could see a 30 % guide-rope preload loss
  // (identifyPreload: about a second of CPU per trip at n = 25).  Only for
  // the summary: not with -q or --no-trips.
  std::optional<hoist::TripRecorder> trips;
  hoist::ConditionSettings trip_cond;
  trip_cond.accel_offset_sigma = set.accel_offset_sigma;
  long verdict_mismatches = 0;
  if (!o.quiet && !o.no_trips) trips.emplace(p, set, trip_cond, max_step);
  std::vector<std::string> trip_lines;
  std::size_t sample_index = 0;  // estimateRecorded reports once per sample, in order
  try {
    hoist::estimateRecorded(
        p, set, max_step, samples, cal,
        [&](const hoist::LoadEstimate& e, const hoist::EstimatorCounters& c) {
          if (trips && sample_index < samples.size() && trips->add(samples[sample_index], e)) {
            const hoist::TripRecord& r = trips->record();
            // MODEL_MISMATCH's trip-end preload test, as hoist-twind's trip room judges it.
            const hoist::PreloadVerdict v = hoist::judgeTripPreload(r.id, 1.0, trip_cond.model_check_sigma);
            char verdict[320];
            hoist::describe(v, verdict, sizeof verdict);
            if (v.mismatch) ++verdict_mismatches;
            trip_lines.push_back("trip " + std::to_string(r.trip) + " (" +
                                 (r.direction == hoist::TripDirection::Down ? "down " : "up ") +
                                 fmt("%.0f", r.depth_start) + " -> " + fmt("%.0f", r.depth_end) + " m, t = " +
                                 fmt("%.1f", r.t_start) + " .. " + fmt("%.1f", r.t_end) + " s): " + r.id.note +
                                 (v.judged ? std::string("; ") + verdict + (v.mismatch ? ": MODEL_MISMATCH" : "")
                                           : std::string()));
          }
          ++sample_index;
          line.clear();
          appendRow(line, e, c);
          out.write(line);
          ++rows;
          if (e.mismatch) {
            ++mismatch_rows;
            if (std::isnan(first_mismatch)) {
              first_mismatch = e.t;
              if (e.nis_exceeded)
                first_why = "window NIS " + fmt("%.1f", e.nis_window) + " over " + std::to_string(e.nis_dof) +
                            " dof > bound " + fmt("%.1f", e.nis_bound);
              if (e.drift_exceeded)
                first_why += (first_why.empty() ? "" : "; ") + std::string("load drift ") + fmt("%.1f", e.drift) +
                             " sigma during the trip";
            }
          }
          if (!e.plausible && implausible_rows++ == 0)
            first_implausible = "at t = " + fmt("%.2f", e.t) + " s (" + e.implausible + ")";
          faults[0] |= e.fault_imu_accel;
          faults[1] |= e.fault_imu_rate;
          faults[2] |= e.fault_rope_load;
          if (e.change_t >= 0.0 && e.change_t != last_change) {
            // The first kShownChanges by time; the rest counted (a config
            // whose noise is far below the data's makes hundreds).
            if (++n_changes <= kShownChanges) {
              if (!changes.empty()) changes += "; ";
              changes += "t = " + fmt("%.2f", e.change_t) + " s";
            }
            last_change = e.change_t;
          }
          last = e;
          counts = c;
        },
        [&](double f) {
          if (!o.progress) return;
          if (tty) {
            std::fprintf(stderr, "\rhoist-estimate: %3.0f %%", 100.0 * f);
          } else {
            const int decile = static_cast<int>(f * 10.0 + 1e-9);
            if (decile <= last_decile) return;
            last_decile = decile;
            std::fprintf(stderr, "hoist-estimate: progress %3d %%\n", decile * 10);
          }
          std::fflush(stderr);
        });
  } catch (const std::domain_error& e) {
    throw std::runtime_error(std::string("the model left its domain: ") + e.what());
  }
  if (o.progress && tty) std::fputc('\n', stderr);
  out.close();
  if (!o.offset_out.empty())
    hoist::io::writeAccelOffsetFile(o.offset_out, {last.accel_offset, last.sigma_accel_offset}, "--offset-out");
  const double secs = std::chrono::duration<double>(Clock::now() - t_start).count();
  if (!o.quiet) {
    std::ostringstream s;
    s << "hoist-estimate: " << rows << " rows from " << o.measurements << " (t = " << samples.front().t << " .. "
      << samples.back().t << " s, sensors: " << sensorNames(cols.sensors) << ") at n = " << p.n
      << ", max step " << max_step << " s, written to " << o.out << " in " << fmt("%.2f", secs)
      << " s. Final (t = " << last.t << " s): "
      << withSigma("Fa", last.Fa, last.sigma_Fa, last.fa_observed, "N", "%.1f") << ", "
      << withSigma("b", last.b, last.sigma_b, last.fa_observed && last.moment_observed, "m", "%.4f") << ", "
      << withSigma("M", last.moment, last.sigma_moment, last.moment_observed, "N m", "%.1f") << " (configured Fa = " << p.Fa
      << " N, b = " << p.b << " m), accelerometer offset " << fmt("%.5f", last.accel_offset) << " +- "
      << fmt("%.5f", last.sigma_accel_offset) << " m/s^2"
      << (cal.known.empty() && !cal.has_offset && last.sigma_accel_offset > 0.0
              ? " (uncalibrated: M's sigma includes it; calibrate with --known-load, keep it with --offset-out)"
              : "")
      << ". Updates accepted " << counts.accepted << ", gated " << counts.gated
      << ", load changes " << counts.load_changes << ", implausible " << counts.implausible
      << "; MODEL_MISMATCH in " << mismatch_rows << " rows, first "
      << (std::isnan(first_mismatch) ? std::string("none")
                                     : "at t = " + fmt("%.2f", first_mismatch) + " s (" + first_why + ")")
      << ". Not plausible in " << implausible_rows << " rows"
      << (first_implausible.empty() ? std::string("") : ", first " + first_implausible) << ".";
    const char* names[3] = {"f_y", "omega", "rope_load"};
    for (int i = 0; i < 3; ++i)
      if (faults[i]) s << " Sensor fault: " << names[i] << " " << hoist::sensorFaultReason(faults[i]) << ".";
    if (!changes.empty())
      s << " Load changes at " << changes
        << (n_changes > kShownChanges ? " and " + std::to_string(n_changes - kShownChanges) + " more" : std::string())
        << "; the last by " << fmt("%.1f", last.change_Fa) << " N and "
        << fmt("%.1f", last.change_moment) << " N m.";
    s << "\n";
    if (trips) {
      if (trip_lines.empty())
        s << "hoist-estimate: no whole trip in the data (rest, motion, rest): no preload detectability to state.\n";
      for (const std::string& t : trip_lines) s << "hoist-estimate: " << t << ".\n";
      if (verdict_mismatches > 0)
        s << "hoist-estimate: MODEL_MISMATCH's trip-end preload test fired on " << verdict_mismatches << " of "
          << trip_lines.size() << " trips (the MODEL_MISMATCH column holds the estimator's own tests only; "
          << "hoist-twind with [history] raises it after such a trip).\n";
    }
    std::cout << s.str();
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "hoist-estimate: estimate the eccentric load (Fa, b, M = Fa b), the cage state it implies and the\n"
      "model check (NIS, MODEL_MISMATCH) from recorded winder and sensor data -- the same estimator as\n"
      "hoist-twind's [estimator] (docs/estimation.md).\n"
      "Input CSV columns: t,l,v,a and optionally f_y [m/s^2], omega [rad/s], rope_load [N] (an absent\n"
      "column: no such sensor; an empty field: no sample in that row); hoist-sim --write-measurements\n"
      "writes such files.",
      "hoist-estimate"};
  hoist::cli::nameProgram(app, "hoist-estimate");  // usage, errors and --version name the program
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
                 "largest integration step [s] (default: the config's [service] max_step, else 0.0025 as in "
                 "hoist-twind; 0: one step per row)")
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
  if (const auto rc = hoist::cli::parse(app, argc, argv)) return *rc;
  // Required, but checked after parsing: CLI11 reports a missing option
  // before an unknown one, and an unknown option must be named.
  for (const auto& [given, what] : {std::pair{!o.config.empty(), "--config"},
                                    std::pair{!o.measurements.empty(), "--measurements"},
                                    std::pair{!o.out.empty(), "--out"}})
    if (!given) {
      std::cerr << "hoist-estimate: " << what << " is required\nRun with --help for more information.\n";
      return 2;
    }
  try {
    return run(o);
  } catch (const hoist::io::InputError& e) {
    std::cerr << "hoist-estimate: error: " << e.what() << "\n";
    return 2;
  } catch (const UsageError& e) {
    std::cerr << "hoist-estimate: error: " << e.what() << "\n";
    return 2;
  } catch (const hoist::io::WriteError& e) {
    std::cerr << "hoist-estimate: error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "hoist-estimate: error: out of memory (std::bad_alloc)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "hoist-estimate: error: " << e.what() << "\n";
    return 1;
  }
}
