// hoist/study/sweep.hpp -- parameter sweeps of the shaft model: the paper's
// Section 3 studies (Figs. 2-13) and any config key, run in parallel threads.
// Pure numerics: no files, no printing (progress goes to a callback).
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hoist/params.hpp"
#include "hoist/profile.hpp"
#include "hoist/simulator.hpp"
#include "hoist/study/metrics.hpp"

namespace hoist::study {

// ---- sweepable parameters -------------------------------------------------

/// Keys accepted by applyParameter(): the TOML keys of INTERFACES.md plus
/// derived ones (see parameterHelp()).
const std::vector<std::string>& sweepableKeys();
/// One line per key: "key  meaning".
std::string parameterHelp();

/// Set `key` to `value` in `p` (e.g. "cage.mass", "guide_ropes.preload" = total
/// preload split equally, "guide_ropes.preload_difference" = Tb2 - Tb1 at the
/// current total).  Throws ParamError(key, ...) for an unknown key or a value
/// of the wrong kind (e.g. a non-integer model.modes); does not validate the
/// whole set (call p.validate()).
void applyParameter(ShaftParams& p, const std::string& key, double value);
/// Current value of `key` in `p` (the inverse of applyParameter()).
double parameterValue(const ShaftParams& p, const std::string& key);

// ---- one run ------------------------------------------------------------

/// One run's time series (struct of arrays; rows as in hoist-sim's CSV).
struct Trace {
  std::vector<double> t, l, v, a, x_c, y_c, theta;
  std::array<std::vector<double>, 5> lambda;
  void append(const CageResponse& r);
  void reserve(std::size_t n);
  std::size_t size() const { return t.size(); }
  /// Cage lateral excursion at the top and bottom sleeves, max(|y_c - h theta|,
  /// |y_c + h theta|), per sample.
  std::vector<double> excursion(double h) const;
};

/// Lateral shape of both guide ropes at one instant.
struct Shape {
  double t = 0.0;   ///< requested time
  double l = 0.0;   ///< rope length (cage top) at that instant
  std::vector<double> x, y1, y2;
};

struct RunSpec {
  std::string label;    ///< e.g. "Tb1+Tb2=48000"
  double value = 0.0;   ///< swept value (0 for the single baseline run)
  ShaftParams params;
};

struct RunOptions {
  SimulationOptions sim;              ///< dt, max_step, method, initial (overrides params.initial)
  std::vector<double> shape_times;    ///< record guide-rope shapes at these t (nearest step)
  int shape_points = 401;
};

struct RunResult {
  RunSpec spec;
  Trace trace;
  std::vector<Shape> shapes;
  double wall_seconds = 0.0;
  std::string error;  ///< non-empty if the run failed (then trace may be partial)
  bool ok() const { return error.empty(); }
};

/// Simulate one run (thread-safe: builds its own model and solver).
/// `progress` (optional) receives this run's fraction done.
RunResult runOne(const RunSpec& spec, const HoistProfile& profile, const RunOptions& opt,
                 const std::function<void(double)>& progress = {});

/// Run independent specs on `jobs` threads (<= 0: hardware concurrency).
/// `progress(done_fraction)` (optional) is called, serialized, as the runs
/// advance.  Results are in the order of `specs`; failures are reported in
/// RunResult::error, never thrown.
std::vector<RunResult> runAll(const std::vector<RunSpec>& specs, const HoistProfile& profile,
                              const RunOptions& opt, int jobs,
                              const std::function<void(double)>& progress = {});

/// Run `f(i)` for i in [0, count) on `jobs` threads (<= 0: hardware
/// concurrency).  The first exception thrown by any f is rethrown.
void parallelFor(int count, int jobs, const std::function<void(int)>& f);

// ---- studies ------------------------------------------------------------

/// A set of runs that differ in one parameter.
struct Study {
  std::string name;     ///< "preload", "sweep", ...
  std::string title;    ///< human-readable
  std::string figures;  ///< the paper's figures it reproduces, e.g. "6-7"
  std::string key;      ///< swept key ("" for the single baseline run)
  std::vector<RunSpec> runs;
};

/// The paper's studies, in paper order.
const std::vector<std::string>& paperStudyNames();  // response, preload, tension-difference, eccentric-load, mass
/// The named paper study on top of `base` (nullopt for an unknown name).
/// The tension-difference study sets the total preload to 6e4 N first.
std::optional<Study> paperStudy(const std::string& name, const ShaftParams& base);
/// A sweep of `key` over `values` on top of `base`; throws ParamError for a bad
/// key or a value that makes the parameters invalid (naming the key).
Study sweepStudy(const std::string& key, const std::vector<double>& values,
                 const ShaftParams& base);

/// The stages of a profile for the frequency analysis: "trip" (all), "uniform"
/// (the longest stretch with a = 0 and v != 0) and "decel" (from its end to the
/// end of the profile).  For the paper's Fig. 2 profile: 5-50 s and 50-60 s.
/// Falls back to paperWindows() if the profile has no uniform-velocity stage.
std::vector<Window> stageWindows(const HoistProfile& profile);

/// The summary metrics of one run: peaks and RMS of y_c, theta, the excursion
/// and lambda_0..4 over the trip and each window, and the dominant frequency
/// (FFT and zero crossings) of y_c, theta and lambda_1 in each non-"trip"
/// window.  Names: peak_y_c, rms_theta, peak_lambda_1_uniform, f_y_c_uniform,
/// fzc_theta_decel, osc_y_c_uniform, ... (see metrics.cpp).
MetricSet runMetrics(const RunResult& r, const std::vector<Window>& windows = paperWindows(),
                     const FrequencyOptions& fopt = {});

}  // namespace hoist::study
