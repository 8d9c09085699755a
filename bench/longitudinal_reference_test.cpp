// The longitudinal step matrix in its two forms (bench/longitudinal_reference.hpp):
// FastSolver's fused form against the previous one, over the paper's trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hoist/fast_solver.hpp"
#include "longitudinal_reference.hpp"

using namespace hoist;
using hoist::bench::LongitudinalStep;
using hoist::bench::StepMatrix;

namespace {

TEST(FastLongitudinal, FusedStepMatrixMatchesThePreviousForm) {
  // The cost lever: E built in one pass from the constant matrices, Ek never
  // formed.  Same equations, different rounding: x_c and lambda_0 agree to
  // round-off over the paper's trip (the hoisting rope's kHz modes included).
  for (int n : {10, 50}) {
    ShaftParams p;
    p.n = n;
    auto model = std::make_shared<const ShaftModel>(p);
    FastSolver a(model);
    LongitudinalStep b(model, StepMatrix::Previous);
    const HoistProfile prof = HoistProfile::trapezoid();
    a.initialize(0.0, prof.at(0.0));
    FastSolverState s0;
    a.saveState(s0);
    b.start(s0);
    double worst = 0, scale = 0;
    for (int k = 1; k <= 6000; ++k) {
      const double t = 0.01 * k;
      a.step(t, prof.at(t));
      b.step(t, prof.at(t));
      worst = std::max({worst, std::abs(a.response().x_c - b.x_c()) / 1e-3,
                        std::abs(a.response().lambda[0] - b.lambda0()) / 1e4});
      scale = std::max(scale, std::abs(b.x_c()));
    }
    EXPECT_LT(worst, 1e-9) << "n = " << n;
    EXPECT_GT(scale, 1e-4);
  }
}

TEST(FastLongitudinal, BenchmarkFusedFormIsTheSolversStep) {
  // The benchmark times LongitudinalStep's fused form in place of the
  // solver's: it must compute what FastSolver::step computes.
  ShaftParams p;
  p.n = 20;
  auto model = std::make_shared<const ShaftModel>(p);
  FastSolver a(model);
  LongitudinalStep b(model, StepMatrix::Fused);
  const HoistProfile prof = HoistProfile::trapezoid();
  a.initialize(0.0, prof.at(0.0));
  FastSolverState s0;
  a.saveState(s0);
  b.start(s0);
  double worst = 0;
  for (int k = 1; k <= 3000; ++k) {
    const double t = 0.01 * k;
    a.step(t, prof.at(t));
    b.step(t, prof.at(t));
    worst = std::max({worst, std::abs(a.response().x_c - b.x_c()) / 1e-3,
                      std::abs(a.response().lambda[0] - b.lambda0()) / 1e4});
  }
  EXPECT_LT(worst, 1e-12);
}

}  // namespace
