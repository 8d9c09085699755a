// Superposition of the eccentric load (hoist::addLoadResponse and
// FastSolver::setLoad): the twin's state under its configured load, plus the
// load change times the unit load's response, is the state under the other
// load; restored and stepped on, it follows the run under that load, and a
// forecast from it equals the forecast from that run.  This is how the
// daemon's forecasts start from the load estimator's state.  Checked against
// a second, independent full run under the true load (another ShaftModel).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "hoist/fast_solver.hpp"
#include "hoist/forecast.hpp"
#include "hoist/scenario.hpp"

using namespace hoist;

namespace {

ShaftParams params(double Fa, double b, int n) {
  ShaftParams p;
  p.n = n;
  p.Fa = Fa;
  p.b = b;
  return p;
}

double rel(double a, double b, double scale) { return std::abs(a - b) / scale; }

/// Steps `s` along the paper trip from 0 to t_end at dt with 4 substeps of
/// linearly interpolated kinematics (as the daemon does).
void run(FastSolver& s, const HoistProfile& prof, double t0, double t_end, double dt) {
  const int steps = static_cast<int>(std::lround((t_end - t0) / dt));
  for (int k = 1; k <= steps; ++k) s.step(t0 + k * dt, prof.at(t0 + k * dt));
}

void expectResponsesClose(const CageResponse& a, const CageResponse& b, double tol) {
  EXPECT_LE(rel(a.x_c, b.x_c, std::abs(b.x_c) + 1e-6), tol);
  EXPECT_LE(rel(a.y_c, b.y_c, std::abs(b.y_c) + 1e-7), tol);
  EXPECT_LE(rel(a.theta, b.theta, std::abs(b.theta) + 1e-8), tol);
  EXPECT_LE(rel(a.lambda[0], b.lambda[0], std::abs(b.lambda[0])), tol);
  for (int i = 1; i < 5; ++i) EXPECT_LE(rel(a.lambda[i], b.lambda[i], std::abs(b.lambda[i]) + 1.0), tol) << i;
  EXPECT_LE(rel(a.theta_dot, b.theta_dot, std::abs(b.theta_dot) + 1e-7), tol);
}

}  // namespace

TEST(LoadSuperposition, TwinPlusLoadChangeTimesUnitResponseIsTheRunUnderTheOtherLoad) {
  const int n = 16;
  const HoistProfile prof = HoistProfile::trapezoid();
  // The config the twin runs, the shaft's true load, and the unit load (as
  // hoist::LoadEstimator builds its sensitivity solver).
  auto cfg = std::make_shared<const ShaftModel>(params(1000.0, 0.3, n));
  auto truth = std::make_shared<const ShaftModel>(params(1800.0, -0.5, n));
  auto unit = std::make_shared<const ShaftModel>(params(1.0, 1.0, n));
  FastSolver twin(cfg), real(truth), sens(unit, Forcing::LoadOnly);
  const double dt = 0.01;
  for (FastSolver* s : {&twin, &real, &sens}) s->initialize(0.0, prof.at(0.0));
  for (double t_snap : {3.0, 25.0}) {  // accelerating (start transient), cruising
    const double t_prev = twin.response().t;
    for (FastSolver* s : {&twin, &real, &sens}) run(*s, prof, t_prev, t_snap, dt);
    SCOPED_TRACE("t = " + std::to_string(t_snap));
    FastSolverState st(n), us(n), rs(n);
    twin.saveState(st);
    sens.saveState(us);
    real.saveState(rs);
    EXPECT_EQ(st.Fa, 1000.0);
    EXPECT_DOUBLE_EQ(st.moment, 300.0);
    EXPECT_EQ(us.Fa, 1.0);
    EXPECT_EQ(us.moment, 1.0);
    // The configured and the true response differ visibly (else the test says nothing).
    EXPECT_GT(std::abs(rs.response.theta - st.response.theta), 0.5 * std::abs(rs.response.theta));
    ASSERT_TRUE(addLoadResponse(st, us, 1800.0 - st.Fa, 1800.0 * -0.5 - st.moment));
    EXPECT_DOUBLE_EQ(st.Fa, 1800.0);
    EXPECT_DOUBLE_EQ(st.moment, -900.0);
    expectResponsesClose(st.response, rs.response, 1e-8);
    EXPECT_LE((st.x - rs.x).norm(), 1e-8 * rs.x.norm());
    EXPECT_LE((st.y - rs.y).norm(), 1e-8 * rs.y.norm());

    // Restored into a solver on the configured model, it continues under the
    // true load (setLoad through restoreState), as the true run does.
    FastSolver cont(cfg), cont_real(truth);
    cont.restoreState(st);
    cont_real.restoreState(rs);
    EXPECT_DOUBLE_EQ(cont.loadForce(), 1800.0);
    EXPECT_DOUBLE_EQ(cont.loadMoment(), -900.0);
    run(cont, prof, t_snap, t_snap + 5.0, dt);
    run(cont_real, prof, t_snap, t_snap + 5.0, dt);
    expectResponsesClose(cont.response(), cont_real.response(), 1e-7);
  }
}

TEST(LoadSuperposition, ForecastFromTheShiftedStateEqualsTheForecastUnderTheTrueLoad) {
  const int n = 12;
  const HoistProfile prof = HoistProfile::trapezoid();
  auto cfg = std::make_shared<const ShaftModel>(params(500.0, 0.2, n));
  auto truth = std::make_shared<const ShaftModel>(params(2500.0, 0.8, n));
  auto unit = std::make_shared<const ShaftModel>(params(1.0, 1.0, n));
  FastSolver twin(cfg), real(truth), sens(unit, Forcing::LoadOnly);
  for (FastSolver* s : {&twin, &real, &sens}) {
    s->initialize(0.0, prof.at(0.0));
    run(*s, prof, 0.0, 20.0, 0.01);
  }
  FastSolverState st(n), us(n), rs(n);
  twin.saveState(st);
  sens.saveState(us);
  real.saveState(rs);
  ASSERT_TRUE(addLoadResponse(st, us, 2500.0 - st.Fa, 2500.0 * 0.8 - st.moment));
  ForecastOptions o;
  o.horizon = 8.0;
  o.limits = ClearanceLimits{0.016, 0.016, 0.030, 0.6, 0.9};
  ForecastWorkspace ws_cfg(cfg, o), ws_true(truth, o);
  const MotionProfile sc = estopProfile(st.t, st.kin, 3.0, 10.0);
  ForecastSummary f_shifted, f_true, f_open;
  forecast(ws_cfg, st, sc, f_shifted);
  forecast(ws_true, rs, sc, f_true);
  FastSolverState open(n);
  twin.saveState(open);
  forecast(ws_cfg, open, sc, f_open);
  ASSERT_EQ(f_shifted.status, ForecastStatus::Ok);
  const double gap = 0.016;
  EXPECT_NEAR(f_shifted.min_clearance, f_true.min_clearance, 1e-9 * gap);
  EXPECT_NEAR(f_shifted.peak_theta, f_true.peak_theta, 1e-8 * f_true.peak_theta);
  EXPECT_NEAR(f_shifted.lambda0_min, f_true.lambda0_min, 1e-9 * f_true.lambda0_max);
  EXPECT_NEAR(f_shifted.lambda0_max, f_true.lambda0_max, 1e-9 * f_true.lambda0_max);
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(f_shifted.peak_lambda[i], f_true.peak_lambda[i], 1e-8 * f_true.peak_lambda[i] + 1e-6) << i;
  // The open-loop forecast (configured load) is a different forecast.
  EXPECT_GT(std::abs(f_open.peak_theta - f_true.peak_theta), 0.3 * f_true.peak_theta);
  EXPECT_GT(std::abs(f_open.lambda0_max - f_true.lambda0_max), 1000.0);
}

TEST(LoadSuperposition, RefusesStatesThatDoNotBelongTogether) {
  auto m = std::make_shared<const ShaftModel>(params(1000.0, 0.3, 8));
  auto m6 = std::make_shared<const ShaftModel>(params(1000.0, 0.3, 6));
  auto u = std::make_shared<const ShaftModel>(params(1.0, 1.0, 8));
  FastSolver twin(m), sens(u, Forcing::LoadOnly), other(m6);
  twin.initialize(0.0, Kinematics{100.0, 0.0, 0.0});
  sens.initialize(0.0, Kinematics{100.0, 0.0, 0.0});
  other.initialize(0.0, Kinematics{100.0, 0.0, 0.0});
  FastSolverState st(8), us(8), never(8), s6(6);
  twin.saveState(st);
  const FastSolverState before = st;
  EXPECT_FALSE(addLoadResponse(st, never, 10.0, 10.0));  // unit never saved
  other.saveState(s6);
  EXPECT_FALSE(addLoadResponse(st, s6, 10.0, 10.0));     // another n
  sens.step(0.01, Kinematics{100.0, 0.0, 0.0});
  sens.saveState(us);
  EXPECT_FALSE(addLoadResponse(st, us, 10.0, 10.0));     // another instant
  twin.step(0.01, Kinematics{100.0, 0.0, 0.0});
  twin.saveState(st);
  EXPECT_FALSE(addLoadResponse(st, us, NAN, 10.0));      // not finite
  EXPECT_TRUE(addLoadResponse(st, us, 10.0, 10.0));
  EXPECT_DOUBLE_EQ(st.Fa, 1010.0);
  EXPECT_EQ(before.Fa, 1000.0);
}
