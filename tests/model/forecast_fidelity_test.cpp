// The economical forecast (economicalForecast: a reduced-mode model from the
// projected start, 10-ms steps without substeps, 101 bounded envelope
// depths) against the exact forecast (the twin's model, dt 0.01 s, 2.5-ms
// substeps, 401 depths): its smallest clearance within 2 % of the gap, its
// lambda_0 range within 2 % of the static rope force, on the paper trip
// (forecasts started accelerating, cruising, braking and at rest) for the
// e-stop and the continue-along-the-plan scenarios.  docs/lookahead.md, "Cost".
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "hoist/fast_solver.hpp"
#include "hoist/forecast.hpp"
#include "hoist/scenario.hpp"

using namespace hoist;

namespace {

struct Worst {
  double clearance = 0.0, lambda0_min = 0.0, lambda0_max = 0.0;  // fractions of the gap / static force
  int forecasts = 0;
};

/// The twin's state at each of `instants` along the paper trip (the
/// daemon's step: 0.01 s ticks in 2.5-ms substeps).
std::vector<FastSolverState> snapshots(const std::shared_ptr<const ShaftModel>& model,
                                       const std::vector<double>& instants, double load_scale = 1.0) {
  const HoistProfile trip = HoistProfile::trapezoid();
  FastSolver s(model);
  const ShaftParams& p = model->params();
  s.setLoad(load_scale * p.Fa, load_scale * p.Fa * p.b);  // the state carries it (a forecast from the load estimate)
  s.initialize(0.0, trip.at(0.0));
  std::vector<FastSolverState> out;
  long k = 0;
  for (double t0 : instants) {
    for (; k * 0.0025 < t0 - 1e-9;) {
      ++k;
      s.step(k * 0.0025, trip.at(k * 0.0025));
    }
    out.emplace_back(model->n());
    s.saveState(out.back());
  }
  return out;
}

/// Both scenarios from every snapshot, `cheap` against `exact`.
Worst compare(const std::shared_ptr<const ShaftModel>& model, const std::vector<FastSolverState>& snaps,
              const ForecastOptions& exact, const ForecastOptions& cheap) {
  const ShaftParams& p = model->params();
  const double gap = std::min({exact.limits.gap_pos_y, exact.limits.gap_neg_y, exact.limits.guide_rope_gap});
  const double static_force = p.m * p.g + p.Fa;
  ForecastWorkspace wx(model, exact), wc(model, cheap);
  Worst w;
  for (const FastSolverState& st : snaps) {
    for (int sc = 0; sc < 2; ++sc) {
      MotionProfile m;
      if (sc == 0) m = estopProfile(st.t, st.kin, 3.0, 10.0);
      else if (!planProfile(st.t, st.kin, TripPlan{300.0, 5.0, 1.0, 1.0}, p.maxRopeLength(), m).ok())
        m = continueProfile(st.t, st.kin, 5.0, 1.0, p.maxRopeLength());
      ForecastSummary a, b;
      forecast(wx, st, m, a);
      forecast(wc, st, m, b);
      const std::string where = "n = " + std::to_string(p.n) + ", t0 = " + std::to_string(st.t) +
                                (sc == 0 ? ", estop" : ", continue");
      EXPECT_EQ(a.status, ForecastStatus::Ok) << where;
      EXPECT_EQ(b.status, a.status) << where;
      EXPECT_NEAR(b.t_reached, a.t_reached, 1e-9) << where;
      w.clearance = std::max(w.clearance, std::abs(a.min_clearance - b.min_clearance) / gap);
      w.lambda0_min = std::max(w.lambda0_min, std::abs(a.lambda0_min - b.lambda0_min) / static_force);
      w.lambda0_max = std::max(w.lambda0_max, std::abs(a.lambda0_max - b.lambda0_max) / static_force);
      ++w.forecasts;
    }
  }
  return w;
}

ForecastOptions exactOptions() {
  ForecastOptions o;  // the daemon's: dt 0.01, max_step 0.0025, 401 depths, the model's n
  o.horizon = 20.0;
  o.limits = ClearanceLimits{0.016, 0.016, 0.030, 0.6, 0.9};  // the demo shaft (service/config/demo.toml)
  return o;
}

std::shared_ptr<const ShaftModel> model(int n) {
  ShaftParams p;
  p.n = n;  // static correction on (the default)
  return std::make_shared<const ShaftModel>(p);
}

}  // namespace

TEST(ForecastFidelity, EconomicalWithinTwoPercentOfTheExactOnThePaperTrip) {
  // n = 25: the converged setting.  t0: accelerating (0, 2), cruising (5,
  // 20, 35), braking (50, 52.5), at rest on the landing (55).
  auto m = model(25);
  const ForecastOptions ex = exactOptions();
  const ForecastOptions ec = economicalForecast(ex, 25);
  ASSERT_EQ(ec.modes, 10);
  ASSERT_EQ(ec.max_step, 0.0);
  const Worst w = compare(m, snapshots(m, {0.0, 2.0, 5.0, 20.0, 35.0, 50.0, 52.5, 55.0}), ex, ec);
  EXPECT_EQ(w.forecasts, 16);
  EXPECT_LE(w.clearance, 0.02);
  EXPECT_LE(w.lambda0_min, 0.02);
  EXPECT_LE(w.lambda0_max, 0.02);
  std::printf("n = 25: largest differences: min clearance %.3f %% of the gap, lambda_0 min %.3f %%, max %.3f %% "
              "of the static rope force\n",
              100 * w.clearance, 100 * w.lambda0_min, 100 * w.lambda0_max);
}

TEST(ForecastFidelity, EconomicalFromAFiftyModeTwin) {
  // The example configuration's n = 50: ten of fifty modes.
  auto m = model(50);
  const ForecastOptions ex = exactOptions();
  const Worst w = compare(m, snapshots(m, {2.0, 20.0, 52.5}), ex, economicalForecast(ex, 50));
  EXPECT_LE(w.clearance, 0.02);
  EXPECT_LE(w.lambda0_min, 0.02);
  EXPECT_LE(w.lambda0_max, 0.02);
  std::printf("n = 50: largest differences: min clearance %.3f %% of the gap, lambda_0 min %.3f %%, max %.3f %%\n",
              100 * w.clearance, 100 * w.lambda0_min, 100 * w.lambda0_max);
}

TEST(ForecastFidelity, EconomicalUnderTheStartsOwnLoad) {
  // A start under another eccentric load than the model's (what a forecast
  // from the load estimate gets): both forecasts continue under it, and the
  // economical one projects against equilibria under it too.
  auto m = model(25);
  const ForecastOptions ex = exactOptions();
  const std::vector<FastSolverState> snaps = snapshots(m, {2.0, 20.0, 52.5}, 1.6);
  ASSERT_EQ(snaps[0].Fa, 1.6 * m->params().Fa);
  const Worst w = compare(m, snaps, ex, economicalForecast(ex, 25));
  EXPECT_LE(w.clearance, 0.02);
  EXPECT_LE(w.lambda0_min, 0.02);
  EXPECT_LE(w.lambda0_max, 0.02);
  std::printf("load x 1.6: largest differences: min clearance %.3f %% of the gap, lambda_0 min %.3f %%, max %.3f %%\n",
              100 * w.clearance, 100 * w.lambda0_min, 100 * w.lambda0_max);
}

TEST(ForecastFidelity, TheComparisonSeesACrudeForecast) {
  // The same comparison fails a forecast that is too crude: two modes per
  // rope at 100-ms steps (lambda_0 off by several percent of the static force).
  auto m = model(25);
  const ForecastOptions ex = exactOptions();
  const std::vector<FastSolverState> snaps = snapshots(m, {2.0, 20.0, 52.5});
  ForecastOptions crude = economicalForecast(ex, 25);
  crude.modes = 2;
  crude.dt = 0.1;
  const Worst w = compare(m, snaps, ex, crude);
  std::printf("2 modes, 100-ms steps: %.3f %% %.3f %% %.3f %%\n", 100 * w.clearance, 100 * w.lambda0_min, 100 * w.lambda0_max);
  EXPECT_GT(std::max({w.clearance, w.lambda0_min, w.lambda0_max}), 0.02);
}

TEST(ForecastFidelity, ModesAreCheckedAgainstTheModel) {
  auto m = model(8);
  ForecastOptions o = exactOptions();
  o.modes = 9;
  try {
    ForecastWorkspace ws(m, o);
    FAIL() << "no error for 9 modes of an 8-mode model";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("modes"), std::string::npos) << e.what();
  }
  o.modes = -1;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o.modes = 0;
  o.envelope_tolerance = -1e-3;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  // A state of another n is refused by name.
  o.envelope_tolerance = 0.0;
  o.modes = 4;
  ForecastWorkspace ws(m, o);
  EXPECT_EQ(ws.forecastModes(), 4);
  EXPECT_EQ(ws.startModes(), 8);
  FastSolverState other(5);
  other.valid = true;
  ForecastSummary out;
  EXPECT_THROW(forecast(ws, other, estopProfile(0.0, Kinematics{100.0, 0.0, 0.0}, 3.0, 10.0), out),
               std::invalid_argument);
}

TEST(ForecastFidelity, StoppedForecastsOnTheReducedModel) {
  // The reduced model stops where the exact one does: a scenario that runs
  // out of the shaft (left_shaft at the same instant), a non-finite start
  // (non_finite, nothing integrated).
  auto m = model(12);
  ForecastOptions ex = exactOptions();
  ex.horizon = 60.0;
  const ForecastOptions ec = economicalForecast(ex, 12, 6);
  ForecastWorkspace wx(m, ex), wc(m, ec);
  ASSERT_EQ(wc.forecastModes(), 6);
  const std::vector<FastSolverState> snaps = snapshots(m, {20.0});
  const FastSolverState& st = snaps[0];
  // Cruising on at 5 m/s past the bottom (137.5 m at t0 = 20 s: the end
  // L - 2h is reached about 49 s later).
  ForecastSummary a, b;
  MotionProfile out;
  out.reset(st.t, st.kin);
  out.appendAccel(100.0, 0.0);
  forecast(wx, st, out, a);
  forecast(wc, st, out, b);
  EXPECT_EQ(a.status, ForecastStatus::LeftShaft);
  EXPECT_EQ(b.status, ForecastStatus::LeftShaft);
  EXPECT_NEAR(b.t_reached, a.t_reached, 1e-9);
  EXPECT_LT(a.t_reached, 55.0);
  FastSolverState bad = st;
  bad.x(0) = NAN;
  forecast(wc, bad, out, b);
  EXPECT_EQ(b.status, ForecastStatus::NonFinite);
  EXPECT_EQ(b.steps, 0);
  bad = st;
  bad.kin.l = m->params().maxRopeLength() + 1.0;
  forecast(wc, bad, out, b);
  EXPECT_EQ(b.status, ForecastStatus::LeftShaft);
  EXPECT_EQ(b.steps, 0);
}
