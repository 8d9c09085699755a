// The preload advisor: bracketing on a synthetic model with a known answer,
// then on the real model (n = 20, dt = 0.01 s).
#include <gtest/gtest.h>

#include <cmath>

#include "hoist/study/advisor.hpp"

using namespace hoist;
using namespace hoist::study;

TEST(Advisor, SyntheticKnownAnswer) {
  // excursion = C / T * (1 + 4 (s - 0.6)^2): best split 0.6, T* = C / clearance.
  const double C = 400.0;
  PeakEvaluator ev = [&](double Tb1, double Tb2) {
    const double T = Tb1 + Tb2, s = Tb1 / T;
    TripPeaks p;
    p.excursion = C / T * (1.0 + 4.0 * (s - 0.6) * (s - 0.6));
    p.sleeve_force = 30.0 + 1e5 / T;
    return p;
  };
  AdvisorOptions o;
  o.clearance = 0.01;
  const AdvisorResult r = advisePreload(ev, o);
  ASSERT_TRUE(r.feasible) << r.message;
  EXPECT_NEAR(r.split, 0.6, 0.01);
  EXPECT_NEAR(r.total, C / o.clearance, 2e-3 * C / o.clearance);
  EXPECT_LE(r.achieved.excursion, o.clearance);
  EXPECT_TRUE(r.monotone);
  EXPECT_NEAR(r.Tb1 + r.Tb2, r.total, 1e-9 * r.total);
  EXPECT_GT(r.infeasible_below, 0.99 * r.total);

  // A sleeve-force limit that binds: 30 + 1e5/T <= 32 -> T >= 5e4.
  o.max_sleeve_force = 32.0;
  const AdvisorResult f = advisePreload(ev, o);
  ASSERT_TRUE(f.feasible) << f.message;
  EXPECT_NEAR(f.total, 5e4, 2e-3 * 5e4);
  EXPECT_LE(f.achieved.sleeve_force, 32.0);

  // Impossible target.
  o.max_sleeve_force = 29.0;
  const AdvisorResult bad = advisePreload(ev, o);
  EXPECT_FALSE(bad.feasible);
  EXPECT_NE(bad.message.find("INFEASIBLE"), std::string::npos);
  EXPECT_NE(bad.message.find("sleeve force"), std::string::npos);
}

TEST(Advisor, OptionsAreValidated) {
  AdvisorOptions o;
  EXPECT_THROW(o.validate(), std::invalid_argument);  // clearance 0
  o.clearance = 0.01;
  o.split_min = 0.8;
  o.split_max = 0.7;
  EXPECT_THROW(o.validate(), std::invalid_argument);
}

class AdvisorModel : public ::testing::Test {
 protected:
  void SetUp() override {
    base_.n = 20;
    sim_.dt = 0.01;
    sim_.max_step = 0.0;
    sim_.initial = InitialState::Static;
    eval_ = simulationEvaluator(base_, HoistProfile::trapezoid(), sim_);
  }
  ShaftParams base_;
  SimulationOptions sim_;
  PeakEvaluator eval_;
};

TEST_F(AdvisorModel, FindsTheSmallestSufficientPreload) {
  AdvisorOptions o;
  o.clearance = 0.008;  // 8 mm; the paper's 6e4 N gives about 10 mm at n = 20
  o.samples = 8;
  const AdvisorResult r = advisePreload(eval_, o);
  ASSERT_TRUE(r.feasible) << r.message;
  EXPECT_TRUE(r.monotone);
  EXPECT_LE(r.achieved.excursion, o.clearance);
  // Re-evaluate independently: the recommendation meets the target ...
  const TripPeaks at = eval_(r.Tb1, r.Tb2);
  EXPECT_LE(at.excursion, o.clearance);
  EXPECT_NEAR(at.excursion, r.achieved.excursion, 1e-12);
  // ... and 10 % less preload (same split) does not: the bracket is tight.
  const TripPeaks less = eval_(0.9 * r.Tb1, 0.9 * r.Tb2);
  EXPECT_GT(less.excursion, o.clearance);
  EXPECT_GT(r.infeasible_below, 0.99 * r.total);
  EXPECT_GE(r.split, o.split_min);
  EXPECT_LE(r.split, o.split_max);
}

TEST_F(AdvisorModel, ReportsAnImpossibleTarget) {
  AdvisorOptions o;
  o.clearance = 1e-5;  // 0.01 mm: not even 5e5 N achieves it
  o.samples = 4;
  const AdvisorResult r = advisePreload(eval_, o);
  EXPECT_FALSE(r.feasible);
  EXPECT_NE(r.message.find("INFEASIBLE"), std::string::npos) << r.message;
  EXPECT_GT(r.achieved.excursion, o.clearance);
}
