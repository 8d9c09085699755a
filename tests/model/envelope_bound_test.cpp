// GuideRopeEnvelope::evaluateBounded (cost per twin): the deflection
// envelope without the samples x n product on most steps.  Along whole trips
// (static start and from rest, with and without the static correction, n =
// 10..50, equal and unequal guide-rope tensions) the bounded value must never
// be below the exact envelope and never more than the tolerance above it, and
// it must actually skip exact evaluations.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

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
