// hoist/forecast.hpp -- look-ahead forecast: from a copy of the
// twin's solver state, integrate one scenario (a winder motion, see
// scenario.hpp) to a horizon with the same solver and step, and summarize
// what will happen: the smallest clearance and when, the first WARNING and
// CRITICAL threshold crossings, peak sway, tilt and sleeve forces, the range
// of the hoisting-rope force lambda_0, and a short series for dashboards.
//
// Shape (Pinocchio style): the model (ShaftModel) is immutable; a
// ForecastWorkspace holds every buffer (its own FastSolver, the guide-rope
// envelope table), sized once at construction; the algorithm is the free
// function forecast(ws, start, scenario, out), which allocates nothing.
//
// Stepping is the daemon's (service TwinCore::advance): output steps of
// `dt` (the daemon's tick, 1 / [service] rate) from the start time, the
// scenario sampled at each output time, each output step split into
// ceil(dt / max_step) equal substeps whose kinematics interpolate the two
// samples (cubic Hermite in l, linear v and a -- the same interpolation as
// HoistProfile::at, so hoist-sim on a spliced profile gives the same run).
// Clearance is evaluated at each output step (as the daemon does), with a
// GuideRopeEnvelope of `envelope_points` depths.
//
// Reads from the model: n, h, L - 2h.  Writes: ws.solver (its state is the
// forecast's end state afterwards), ws.envelope, `out`.
#pragma once

#include <array>
#include <memory>

#include "hoist/clearance.hpp"
#include "hoist/fast_solver.hpp"
#include "hoist/guide_rope_envelope.hpp"
#include "hoist/profile.hpp"
#include "hoist/scenario.hpp"

namespace hoist {

struct ForecastOptions {
  double horizon = 20.0;     ///< [s] ([forecast] horizon)
  double dt = 0.01;          ///< output step [s]: the daemon's tick, 1 / [service] rate
  double max_step = kDefaultMaxStep;  ///< largest integration substep [s] ([service] max_step; 0: dt itself)
  int envelope_points = 401; ///< guide-rope depth samples ([service] envelope_points)
  int series_points = 50;    ///< decimated series length, 1..ForecastSummary::kMaxSeries
  /// Modes per rope of the forecast's own model (0: the model's n, the exact
  /// forecast).  1..n-1: a reduced model of the same shaft; the start state
  /// is projected onto it (see forecast()).  Must be <= the model's n.
  int modes = 0;
  /// The guide-rope envelope as GuideRopeEnvelope::evaluateBounded with this
  /// tolerance [m] (an upper bound of the deflection, at most this much
  /// above it: clearances err on the safe side); 0: evaluated exactly at
  /// every output step.
  double envelope_tolerance = 0.0;
  ClearanceLimits limits;    ///< gaps and alarm fractions ([alarms])
  /// Throws std::invalid_argument naming the field at fault.
  void validate() const;
};

/// The economical forecast (the daemon's default, `[forecast] exact =
/// false`): output step 0.01 s without substeps, min(model_modes, modes)
/// modes per rope, min(101, exact.envelope_points) envelope depths bounded to
/// 0.1 mm (an upper bound: clearances err on the safe side by at most that).
/// Keeps the horizon, limits and series of `exact`; changes only the fidelity.
/// Checked against the exact forecast by tests/model/forecast_fidelity_test.cpp
/// (docs/lookahead.md, "Cost").
ForecastOptions economicalForecast(const ForecastOptions& exact, int model_modes, int modes = 10);

enum class ForecastStatus {
  Ok = 0,        ///< integrated to the horizon
  LeftShaft,     ///< the scenario's rope length left (0, L - 2h): stopped there
  NonFinite,     ///< the model state became non-finite: stopped there
};
const char* toString(ForecastStatus s);

/// What one forecast found.  Times are seconds after the start (t_start);
/// -1 means "not within the horizon".  Fixed size, trivially copyable.
struct ForecastSummary {
  static constexpr int kMaxSeries = 64;

  ForecastStatus status = ForecastStatus::Ok;
  double t_start = 0.0;       ///< model time the forecast starts from [s]
  double horizon = 0.0;       ///< requested horizon [s]
  double t_reached = 0.0;     ///< seconds integrated (== horizon unless stopped early)
  long steps = 0;             ///< output steps integrated

  double min_clearance = 0.0;    ///< smallest remaining clearance over [0, t_reached] [m]
  double t_min_clearance = 0.0;  ///< when [s after start]
  double t_warning = -1.0;       ///< first WARNING threshold crossing [s after start], -1 none
  double t_critical = -1.0;      ///< first CRITICAL threshold crossing [s after start], -1 none

  double peak_y_c = 0.0;                   ///< max |y_c| [m]
  double peak_theta = 0.0;                 ///< max |theta| [rad]
  std::array<double, 4> peak_lambda{};     ///< max |lambda_1..4| [N]
  double lambda0_min = 0.0, lambda0_max = 0.0;  ///< range of lambda_0 [N]

  /// Decimated series: the output steps k = 0..steps are split into
  /// series_count consecutive buckets of (nearly) equal length; bucket b
  /// ends at series_t[b] [s after start] and holds the smallest clearance
  /// and the range of lambda_0 over its steps.
  int series_count = 0;
  std::array<double, kMaxSeries> series_t{};
  std::array<double, kMaxSeries> series_min_clearance{};
  std::array<double, kMaxSeries> series_lambda0_min{};
  std::array<double, kMaxSeries> series_lambda0_max{};
};

/// Every buffer a forecast needs, sized once (allocates here, never later).
class ForecastWorkspace {
 public:
  ForecastWorkspace(std::shared_ptr<const ShaftModel> model, const ForecastOptions& opt);

  const ForecastOptions& options() const { return opt_; }
  const ShaftModel& model() const { return solver_.model(); }
  /// Output steps to the horizon, and substeps per output step.
  long steps() const { return steps_; }
  int substeps() const { return substeps_; }
  /// The forecast's solver (holds the end state after forecast()); its model
  /// has options().modes modes when those are fewer than the model's n.
  const FastSolver& solver() const { return solver_; }
  /// Modes per rope of the snapshots forecast() accepts (the model's n).
  int startModes() const { return n_start_; }
  /// Modes per rope the forecast integrates (n, or options().modes).
  int forecastModes() const { return solver_.model().n(); }

 private:
  friend void forecast(ForecastWorkspace&, const FastSolverState&, const MotionProfile&, ForecastSummary&);
  /// Reduced model: start -> red_ (the reduced model's equilibrium at the
  /// start kinematics plus the start's deviation from the full model's).
  void project(const FastSolverState& start);
  ForecastOptions opt_;
  int n_start_ = 0;
  bool reduced_ = false;
  FastSolver solver_;
  GuideRopeEnvelope envelope_;
  // reduced model only (empty otherwise): the full model's equilibrium
  // solver and state, the projected state, workspaces
  std::unique_ptr<FastSolver> full_;
  FastSolverState ref_, red_;
  // the last start projected and its projection (both scenarios of one
  // snapshot share it: the two static solves are made once)
  FastSolverState last_start_, projected_;
  VectorXd dev_, q_, sa_, sb_, zm_, wm_, fa_, fb_, zn_, wn_;
  long steps_ = 0;
  int substeps_ = 1;
};

/// Runs one scenario from `start` (saved by FastSolver::saveState on a model
/// with the same parameters) to the horizon and fills `out`.  The scenario
/// should start at start.t from start.kin (estopProfile / planProfile /
/// continueProfile(start.t, start.kin, ...)); its kinematics at start.t are
/// not used (the state's own are).  With options().modes < n the forecast
/// runs on the reduced model from the projected start: the reduced model's
/// static equilibrium at start.kin (FastSolver::initialize, Static) plus the
/// start's deviation from the full model's equilibrium there, truncated to
/// the first `modes` sine coordinates of each rope (guide ropes through
/// their modal bases; cage coordinates and sleeve forces as they are), both
/// equilibria under the start's load (start.Fa, start.moment).  The
/// step-0 record is the start's own response.  Allocation-free; throws
/// std::invalid_argument only if `start` does not fit the workspace.
void forecast(ForecastWorkspace& ws, const FastSolverState& start, const MotionProfile& scenario,
              ForecastSummary& out);

}  // namespace hoist
