// The fast path's step() and initialize() allocate nothing after start-up.
#include <gtest/gtest.h>

#include <new>

#include "hoist/fast_solver.hpp"
#include "hoist/guide_rope_envelope.hpp"
#include "hoist/forecast.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/scenario.hpp"
#include "hoist/simulator.hpp"

// malloc and friends are interposed for the whole process (tests/support
// limit_malloc.hpp), so Eigen's aligned allocations and operator new (which
// calls malloc) are both counted, whichever library they come from.  Eigen's
// own guard (EIGEN_RUNTIME_NO_MALLOC) only covers code compiled in this file,
// not the model library.
#include "limit_malloc.hpp"

using hoist::test::allocationCount;

using namespace hoist;

TEST(NoAlloc, FastStepAndEnvelopeAllocateNothing) {
  for (int n : {10, 50, 200}) {
    ShaftParams p;
    p.n = n;
    p.Tb2 = 32000;  // distinct ropes: both modal bases in use
    auto model = std::make_shared<const ShaftModel>(p);
    FastSolver s(model);
    GuideRopeEnvelope env(*model, 401), bounded(*model, 401), deferring(*model, 401);
    const HoistProfile prof = HoistProfile::trapezoid();
    s.initialize(0.0, prof.at(0.0));
    s.step(0.01, prof.at(0.01));  // first step may size nothing new, but allow it
    const long before = allocationCount();
    Eigen::internal::set_is_malloc_allowed(false);
    double acc = 0;
    for (int k = 2; k <= 3000; ++k) {
      const double t = k * 0.01;
      s.step(t, prof.at(t));
      acc += env.evaluate(s);
      acc += bounded.evaluateBounded(s, 3e-4);  // the bounded envelope, exact and bounded calls
      // ... and deferring every other step (the daemon's spent budget)
      acc += deferring.evaluateBounded(s, 3e-4, k % 2 ? 1.0 : -1.0);
    }
    EXPECT_GT(bounded.boundedEvaluations(), 0) << "n = " << n;
    EXPECT_GT(deferring.deferredEvaluations(), 0) << "n = " << n;
    EXPECT_GT(bounded.exactEvaluations(), 0) << "n = " << n;
    Eigen::internal::set_is_malloc_allowed(true);
    EXPECT_EQ(allocationCount() - before, 0) << "n = " << n;
    EXPECT_TRUE(std::isfinite(acc));
  }
}

TEST(NoAlloc, ReinitializeAllocatesNothing) {
  // A new winder stream or a model-fault recovery re-initializes the solver
  // at the current kinematics (static or rest, moving or not): the daemon
  // does that inside its loop, so it must not allocate either.
  for (int n : {10, 50}) {
    ShaftParams p;
    p.n = n;
    p.Tb2 = 32000;
    auto model = std::make_shared<const ShaftModel>(p);
    FastSolver s(model);
    const HoistProfile prof = HoistProfile::trapezoid();
    s.initialize(0.0, prof.at(0.0));
    const long before = allocationCount();
    Eigen::internal::set_is_malloc_allowed(false);
    double acc = 0;
    for (double t : {0.0, 3.0, 10.0, 30.0, 55.0}) {
      s.initialize(t, prof.at(t), InitialState::Static);
      acc += s.response().theta;
      s.initialize(t, prof.at(t), InitialState::Rest);
      s.step(t + 0.01, prof.at(t + 0.01));
      acc += s.response().y_c;
    }
    Eigen::internal::set_is_malloc_allowed(true);
    EXPECT_EQ(allocationCount() - before, 0) << "n = " << n;
    EXPECT_TRUE(std::isfinite(acc));
  }
}

TEST(NoAlloc, SnapshotAndForecastAllocateNothing) {
  // Look-ahead: the loop saves a snapshot (into a preallocated state), the
  // worker builds the scenarios and runs the forecasts: none of it allocates
  // once the workspace is set up.  Both the exact forecast and the
  // economical one (at n = 50 a reduced model and the projected start).
  for (int n : {10, 50})
  for (bool economical : {false, true}) {
    ShaftParams p;
    p.n = n;
    p.Tb2 = 32000;
    auto model = std::make_shared<const ShaftModel>(p);
    FastSolver s(model);
    ForecastOptions o;
    o.horizon = 3.0;
    ForecastWorkspace ws(model, economical ? economicalForecast(o, n) : o);
    FastSolverState snap(n), copy(n);
    ForecastSummary out;
    MotionProfile plan;
    const HoistProfile prof = HoistProfile::trapezoid();
    s.initialize(0.0, prof.at(0.0));
    const long before = allocationCount();
    Eigen::internal::set_is_malloc_allowed(false);
    double acc = 0;
    for (int k = 1; k <= 2500; ++k) {
      const double t = k * 0.01;
      s.step(t, prof.at(t));
      if (k % 500 != 0) continue;
      s.saveState(snap);  // loop thread
      copy = snap;        // mailbox hand-over (same size: no allocation)
      forecast(ws, copy, estopProfile(copy.t, copy.kin, 3.0, 10.0), out);
      acc += out.min_clearance + out.lambda0_min;
      forecast(ws, copy, continueProfile(copy.t, copy.kin, 5.0, 1.0, p.maxRopeLength()), out);
      acc += out.peak_lambda[0];
      const PlanCheck c = planProfile(copy.t, copy.kin, TripPlan{300.0, 5.0, 1.0, 1.0}, p.maxRopeLength(), plan);
      if (c.ok()) forecast(ws, copy, plan, out);
      acc += out.peak_y_c + static_cast<double>(c.error);
      s.restoreState(snap);
    }
    Eigen::internal::set_is_malloc_allowed(true);
    EXPECT_EQ(allocationCount() - before, 0) << "n = " << n << (economical ? " (economical)" : "");
    EXPECT_TRUE(std::isfinite(acc));
  }
}

TEST(NoAlloc, CounterSeesAllocations) {
  // The guard itself works (a test that cannot fail is a defect): operator
  // new, and an Eigen allocation made inside the model library.
  const long before = allocationCount();
  auto* v = new std::vector<double>(100);
  delete v;
  EXPECT_GE(allocationCount() - before, 1);
  ShaftParams p;
  p.n = 10;
  auto model = std::make_shared<const ShaftModel>(p);
  const long mid = allocationCount();
  FastSolver s(model);  // sizes its workspace in the library
  EXPECT_GT(allocationCount() - mid, 10);
}

TEST(NoAlloc, LoadEstimatorTickAllocatesNothing) {
  // The estimator's per-tick path (the daemon calls it in its loop): the
  // sensitivity step, prediction, updates and the NIS window.
  ShaftParams p;
  p.n = 25;
  auto model = std::make_shared<const ShaftModel>(p);
  FastSolver twin(model);
  LoadEstimator est(p, EstimatorSettings{});
  const HoistProfile prof = HoistProfile::trapezoid();
  twin.initialize(0.0, prof.at(0.0));
  est.initialize(0.0, prof.at(0.0));
  const long before = allocationCount();
  Eigen::internal::set_is_malloc_allowed(false);
  double acc = 0.0;
  for (int k = 1; k <= 3000; ++k) {
    const double t = k * 0.01;
    twin.step(t, prof.at(t));
    est.advance(t, prof.at(t), 1);
    est.predict(twin.response());
    est.updateImu(0.007, 1e-5);
    if (k % 2) est.updateImuAccel(0.007);
    est.updateRopeLoad(8800.0 + (k % 7));
    acc += est.finish().nis_window;
    if (k == 1500) est.initialize(t, prof.at(t));  // a new stream
  }
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(allocationCount() - before, 0);
  EXPECT_TRUE(std::isfinite(acc));
}

TEST(NoAlloc, LoadEstimatorLoadChangeAllocatesNothing) {
  // A load change at rest (the rope load steps by 1500 N): the gate, the
  // step solver's start and catch-up, the band blocks, the CUSUM and the
  // sensor monitors run in the tick, allocation-free.
  ShaftParams p;
  p.n = 25;
  auto model = std::make_shared<const ShaftModel>(p);
  FastSolver twin(model);
  LoadEstimator est(p, EstimatorSettings{});
  const Kinematics rest{150.0, 0.0, 0.0};
  twin.initialize(0.0, rest);
  est.initialize(0.0, rest);
  const long before = allocationCount();
  Eigen::internal::set_is_malloc_allowed(false);
  std::int64_t changes = 0;
  for (int k = 1; k <= 1500; ++k) {
    const double t = k * 0.01;
    twin.step(t, rest);
    est.advance(t, rest, 4);
    est.predict(twin.response());
    const double f = twin.response().lambda[0] + (k > 500 ? 1500.0 : 0.0) + 20.0 * ((k * 7919) % 13 - 6) / 6.0;
    est.updateImu(0.007 + 0.002 * ((k * 31) % 7 - 3) / 3.0, 1e-4 * ((k * 17) % 5 - 2) / 2.0);
    est.updateRopeLoad(f);
    est.finish();
    changes = est.counters().load_changes;
  }
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(allocationCount() - before, 0);
  EXPECT_GE(changes, 1) << "the test must reach the load-change path";
  EXPECT_TRUE(est.followingLoadChange());
}
