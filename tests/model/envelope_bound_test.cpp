// GuideRopeEnvelope::evaluateBounded (cost per twin): the deflection
// envelope without the samples x n product on most steps.  Along whole trips
// (static start and from rest, with and without the static correction, n =
// 10..50, equal and unequal guide-rope tensions) the bounded value must never
// be below the exact envelope and never more than the tolerance above it, and
// it must actually skip exact evaluations.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "hoist/fast_solver.hpp"
#include "hoist/guide_rope_envelope.hpp"
#include "hoist/simulator.hpp"

using namespace hoist;

namespace {

struct Outcome {
  double worst_over = 0.0;   // max (bounded - exact) [m]
  double worst_under = 0.0;  // max (exact - bounded) [m], must be 0
  double peak = 0.0;         // largest exact envelope [m]
  std::int64_t exact = 0, bounded = 0;
};

Outcome runTrip(int n, bool corr, InitialState init, double Tb2, double tol) {
  ShaftParams p;
  p.n = n;
  p.static_correction = corr;
  if (Tb2 > 0) p.Tb2 = Tb2;
  auto model = std::make_shared<const ShaftModel>(p);
  FastSolver s(model);
  GuideRopeEnvelope exact(*model, 401), fast(*model, 401);
  Outcome o;
  SimulationOptions opt;
  opt.dt = 0.01;
  opt.max_step = 0.01;  // the daemon's benchmark setting: one step per 100 Hz tick
  opt.initial = init;
  simulate(s, HoistProfile::trapezoid(), opt, [&](const CageResponse&) {
    const double e = exact.evaluate(s);
    const double b = fast.evaluateBounded(s, tol);
    o.worst_over = std::max(o.worst_over, b - e);
    o.worst_under = std::max(o.worst_under, e - b);
    o.peak = std::max(o.peak, e);
  });
  o.exact = fast.exactEvaluations();
  o.bounded = fast.boundedEvaluations();
  return o;
}

}  // namespace

TEST(EnvelopeBound, NeverBelowAndWithinToleranceOfTheExactEnvelope) {
  // Tolerances: 1 % of the demo shaft's 30 mm guide-rope gap, and of the
  // default 0.3 m gap (the daemon's service.envelope_tolerance x gap).
  for (double tol : {3e-4, 3e-3})
    for (int n : {10, 20, 50})
      for (bool corr : {true, false})
        for (InitialState init : {InitialState::Static, InitialState::Rest}) {
          const double Tb2 = n == 20 ? 32000.0 : 0.0;  // unequal ropes once
          const Outcome o = runTrip(n, corr, init, Tb2, tol);
          const double share = static_cast<double>(o.bounded) / static_cast<double>(o.bounded + o.exact);
          std::printf("tol %.0e m, n = %d, correction %s, %s: peak %.2f mm, bounded - exact <= %.3f mm, "
                      "%.1f %% of the steps without the exact product\n",
                      tol, n, corr ? "on" : "off", init == InitialState::Static ? "static start" : "from rest",
                      o.peak * 1e3, o.worst_over * 1e3, 100.0 * share);
          EXPECT_LE(o.worst_under, 1e-12 * o.peak) << "the bound fell below the exact envelope";
          EXPECT_LE(o.worst_over, tol * (1.0 + 1e-9)) << "the bound drifted beyond the tolerance";
          EXPECT_GT(o.peak, 1e-3);
          EXPECT_GT(o.bounded, 0) << "no step saved";
        }
}

TEST(EnvelopeBound, ZeroToleranceIsExactEveryTime) {
  ShaftParams p;
  p.n = 12;
  auto model = std::make_shared<const ShaftModel>(p);
  FastSolver s(model);
  GuideRopeEnvelope exact(*model, 101), fast(*model, 101);
  const HoistProfile prof = HoistProfile::trapezoid();
  s.initialize(0.0, prof.at(0.0));
  for (int k = 1; k <= 200; ++k) {
    s.step(0.01 * k, prof.at(0.01 * k));
    EXPECT_EQ(fast.evaluateBounded(s, 0.0), exact.evaluate(s));
    EXPECT_TRUE(fast.lastExact());
  }
  EXPECT_EQ(fast.boundedEvaluations(), 0);
  // A non-finite tolerance is exact too.
  EXPECT_EQ(fast.evaluateBounded(s, std::nan("")), exact.evaluate(s));
  EXPECT_TRUE(fast.lastExact());
}

// Deferral (evaluateBounded with defer_below: the daemon's per-tick budget of
// exact evaluations): a deferred value is the same rigorous bound, only wider
// than the tolerance, so it is never below the exact envelope; a deferral
// level of -inf is the two-argument form exactly; a value at or above the
// level is never deferred.
TEST(EnvelopeBound, DeferredBoundsStayAboveTheExactEnvelope) {
  for (bool corr : {true, false}) {
    ShaftParams p;
    p.n = 20;
    p.static_correction = corr;
    auto model = std::make_shared<const ShaftModel>(p);
    FastSolver s(model);
    GuideRopeEnvelope exact(*model, 401), plain(*model, 401), never(*model, 401), always(*model, 401),
        capped(*model, 401);
    const double tol = 3e-4;
    double worst_under = 0.0, worst_over = 0.0, cap = 0.0;
    SimulationOptions opt;
    opt.dt = 0.01;
    opt.max_step = 0.01;
    bool first = true;
    simulate(s, HoistProfile::trapezoid(), opt, [&](const CageResponse&) {
      const double e = exact.evaluate(s);
      ASSERT_EQ(never.evaluateBounded(s, tol, -std::numeric_limits<double>::infinity()),
                plain.evaluateBounded(s, tol));
      const double a = always.evaluateBounded(s, tol, std::numeric_limits<double>::infinity());
      worst_under = std::max(worst_under, e - a);
      worst_over = std::max(worst_over, a - e);
      if (first) cap = 2.0 * e + 1e-3;
      first = false;
      const double c = capped.evaluateBounded(s, tol, cap);
      if (capped.lastDeferred()) { ASSERT_LT(c, cap); }
      ASSERT_GE(c, e - 1e-15);
    });
    EXPECT_EQ(never.exactEvaluations(), plain.exactEvaluations());
    EXPECT_EQ(never.deferredEvaluations(), 0);
    EXPECT_LE(worst_under, 1e-15) << "a deferred bound fell below the exact envelope";
    EXPECT_EQ(always.exactEvaluations(), 1) << "always deferring: only the first (no reference yet) is exact";
    EXPECT_GT(always.deferredEvaluations(), 0);
    EXPECT_GT(worst_over, tol) << "the deferred bounds did get wider than the tolerance";
    EXPECT_GT(capped.exactEvaluations(), 1) << "above the level the evaluation is exact";
    EXPECT_GT(capped.deferredEvaluations(), 0);
    std::printf("correction %s: always deferring, the bound is at most %.3f mm above the exact envelope (%lld "
                "deferred); deferring below %.3f mm: %lld exact, %lld deferred\n",
                corr ? "on" : "off", worst_over * 1e3, static_cast<long long>(always.deferredEvaluations()),
                cap * 1e3, static_cast<long long>(capped.exactEvaluations()),
                static_cast<long long>(capped.deferredEvaluations()));
  }
}
