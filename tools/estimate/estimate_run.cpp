// hoist-estimate's run: see estimate_run.hpp.
#include "estimate_run.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "estimate_rows.hpp"
#include "hoist/io/accel_offset_file.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/preload_verdict.hpp"
#include "hoist/trip_recorder.hpp"

namespace hoist::estimate {

namespace {

using Clock = std::chrono::steady_clock;

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

}  // namespace

int run(const Options& o, const Input& in, Clock::time_point t_start) {
  const hoist::ShaftParams& p = in.p;
  const hoist::EstimatorSettings& set = in.set;
  const double max_step = in.max_step;
  const std::vector<hoist::MeasurementSample>& samples = in.samples;
  const hoist::io::MeasurementColumns& cols = in.cols;
  const hoist::RecordedCalibration& cal = in.cal;
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


}  // namespace hoist::estimate
