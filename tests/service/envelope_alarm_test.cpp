// The deflection alarm with the bounded envelope (cost per twin:
// [service] envelope_tolerance, GuideRopeEnvelope::evaluateBounded) against
// the exact envelope every step (envelope_tolerance = 0), over the paper's
// whole trip with the demo shaft's tight gaps (scripts/demo.sh), where
// clearance alarms fire:
//   * the published guide deflection lies in [exact, exact + 1 % of the gap],
//     so min_clearance is conservative and within 1 % of the gap;
//   * every clearance alarm is sandwiched: active with the exact envelope =>
//     active with the bounded one => active with the exact envelope and
//     thresholds 1 % of the gap lower; so raise times can only be earlier, by
//     no more than the exact envelope needs to climb 1 % of the gap;
//   * the cage alarms (no envelope) are identical;
// and with a per-tick budget of exact evaluations (the envelope_budget of TwinCore::onInput)
// the deferred bounds change no alarm and lockstep twins share the budget.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "hoist/service/twin/twin_core.hpp"

using namespace hoist;
using namespace hoist::service;

namespace {

constexpr std::int64_t kT0 = 1'700'000'000'000'000;

WinderSample sampleAt(const HoistProfile& p, long k, double dt) {
  const double t = p.startTime() + static_cast<double>(k) * dt;
  const Kinematics kin = p.at(t);
  WinderSample s;
  s.utime = kT0 + std::llround((t - p.startTime()) * 1e6);
  s.seq = k;
  s.v = kin.v;
  s.a = kin.a;
  s.has_length = true;
  s.length = kin.l;
  return s;
}

/// service/config/demo.toml's alarms.
TwinConfig demoConfig(int n, bool corr, double guide_gap) {
  TwinConfig c;
  c.shaft.n = n;
  c.shaft.static_correction = corr;
  c.service.max_step = 0.01;
  c.alarms.gap_pos_y = 0.016;
  c.alarms.gap_neg_y = 0.016;
  c.alarms.guide_rope_gap = guide_gap;
  c.alarms.warning_fraction = 0.6;
  c.alarms.critical_fraction = 0.9;
  c.alarms.deadband = 0.02;
  c.alarms.on_delay = 0.1;
  c.alarms.off_delay = 1.0;
  c.alarms.reannounce = 30.0;
  return c;
}

/// The alarm sandwich of a bounded envelope against the exact one: the cage
/// alarms (no envelope) identical; GUIDE_ROPE active with the exact envelope
/// => active with the bounded one => active with the exact envelope and
/// thresholds 1 % of the gap lower (`lowered`).
::testing::AssertionResult alarmsSandwiched(const TwinCore& exact, const TwinCore& bounded, const TwinCore& lowered,
                                            long k) {
  for (AlarmKind kind : {AlarmKind::CagePosY, AlarmKind::CageNegY, AlarmKind::GuideRope})
    for (AlarmLevel level : {AlarmLevel::Warning, AlarmLevel::Critical}) {
      const bool ae = exact.alarms().find(kind, level)->active();
      const bool ab = bounded.alarms().find(kind, level)->active();
      const bool al = lowered.alarms().find(kind, level)->active();
      if (kind != AlarmKind::GuideRope && ae != ab)
        return ::testing::AssertionFailure() << toString(kind) << " " << toString(level) << " differs at step " << k;
      if (kind != AlarmKind::GuideRope) continue;
      if (ae && !ab) return ::testing::AssertionFailure() << "GUIDE_ROPE " << toString(level) << " missed at step " << k;
      if (ab && !al)
        return ::testing::AssertionFailure() << "GUIDE_ROPE " << toString(level) << " more than 1 % early at step " << k;
    }
  return ::testing::AssertionSuccess();
}

}  // namespace

TEST(EnvelopeAlarm, BoundedEnvelopeKeepsTheAlarmWithinOnePercentOfTheGap) {
  const HoistProfile prof = HoistProfile::trapezoid();
  const long steps = std::lround((prof.endTime() - prof.startTime()) / 0.01);
  int guide_raises_total = 0;
  // The demo's 30 mm guide-rope gap, and tighter ones so that the
  // GUIDE_ROPE WARNING and CRITICAL fire.
  for (double gap : {0.030, 0.019, 0.016, 0.0125})
    for (auto [n, corr] : {std::pair{20, true}, std::pair{50, false}}) {
      TwinConfig ce = demoConfig(n, corr, gap);
      ce.service.envelope_tolerance = 0.0;
      TwinConfig cf = demoConfig(n, corr, gap);
      ASSERT_EQ(cf.service.envelope_tolerance, 0.01) << "the default";
      TwinConfig cl = ce;  // exact envelope, thresholds 1 % of the gap lower
      cl.alarms.warning_fraction -= 0.01;
      cl.alarms.critical_fraction -= 0.01;
      TwinCore exact(ce, ClockMode::Input), fast(cf, ClockMode::Input), lowered(cl, ClockMode::Input);
      double worst_over = 0.0, worst_under = 0.0, worst_clear = 0.0;
      double first_raise[2][3] = {{-1, -1, -1}, {-1, -1, -1}};  // [level][exact, fast, lowered]
      int raises = 0;
      std::vector<double> changes[2][2];  // [level][exact, fast]: times the GUIDE_ROPE alarm changed state
      bool was[2][2] = {{false, false}, {false, false}};
      for (long k = 0; k <= steps; ++k) {
        const WinderSample s = sampleAt(prof, k, 0.01);
        TwinCore* cores[3] = {&exact, &fast, &lowered};
        for (TwinCore* c : cores) {
          ASSERT_TRUE(c->onInput(s, 0.01 * k).accepted) << k;
          c->clearEvents();
        }
        const Clearance &e = exact.output().clearance, &f = fast.output().clearance;
        worst_over = std::max(worst_over, f.guide_deflection - e.guide_deflection);
        worst_under = std::max(worst_under, e.guide_deflection - f.guide_deflection);
        worst_clear = std::max(worst_clear, e.min_clearance - f.min_clearance);
        ASSERT_LE(f.min_clearance, e.min_clearance + 1e-15) << "not conservative at step " << k;
        ASSERT_EQ(f.excursion_pos, e.excursion_pos);
        ASSERT_EQ(f.excursion_neg, e.excursion_neg);
        ASSERT_TRUE(alarmsSandwiched(exact, fast, lowered, k));
        for (AlarmLevel level : {AlarmLevel::Warning, AlarmLevel::Critical}) {
          const AlarmKind kind = AlarmKind::GuideRope;
          const bool ae = exact.alarms().find(kind, level)->active();
          const bool af = fast.alarms().find(kind, level)->active();
          const bool al = lowered.alarms().find(kind, level)->active();
          const int li = level == AlarmLevel::Critical;
          const bool act[3] = {ae, af, al};
          for (int v = 0; v < 2; ++v)
            if (act[v] != was[li][v]) {
              changes[li][v].push_back(0.01 * k);
              was[li][v] = act[v];
            }
          for (int v = 0; v < 3; ++v)
            if (act[v] && first_raise[li][v] < 0) {
              first_raise[li][v] = 0.01 * k;
              if (v == 0) ++raises;
            }
        }
      }
      std::printf("guide gap %.1f mm, n = %d, correction %s: bounded - exact deflection in [%.4f, %.4f] mm, "
                  "min_clearance at most %.4f mm lower; GUIDE_ROPE WARNING first active at %.2f / %.2f / %.2f s, "
                  "CRITICAL at %.2f / %.2f / %.2f s (exact / bounded / exact with thresholds 1 %% lower; -1 = "
                  "never); exact envelope on %lld of %lld steps\n",
                  gap * 1e3, n, corr ? "on" : "off", -worst_under * 1e3, worst_over * 1e3, worst_clear * 1e3,
                  first_raise[0][0], first_raise[0][1], first_raise[0][2], first_raise[1][0], first_raise[1][1],
                  first_raise[1][2], static_cast<long long>(fast.envelope().exactEvaluations()),
                  static_cast<long long>(fast.envelope().exactEvaluations() + fast.envelope().boundedEvaluations()));
      for (int li = 0; li < 2; ++li) {
        std::printf("  GUIDE_ROPE %s changes state at", li ? "CRITICAL" : "WARNING");
        for (std::size_t i = 0; i < changes[li][0].size(); ++i)
          std::printf(" %.2f%s", changes[li][0][i],
                      i < changes[li][1].size() ? (" (bounded " + std::to_string(changes[li][1][i]).substr(0, 5) + ")").c_str() : "");
        std::printf(" s with the exact envelope; %zu changes with the bounded one\n", changes[li][1].size());
      }
      EXPECT_LE(worst_under, 1e-15) << "the bound fell below the exact envelope";
      EXPECT_LE(worst_over, 0.01 * gap * (1 + 1e-9));
      EXPECT_LE(worst_clear, 0.01 * gap * (1 + 1e-9));
      EXPECT_GT(fast.envelope().boundedEvaluations(), 0);
      guide_raises_total += raises;
    }
  EXPECT_GE(guide_raises_total, 2) << "the test needs GUIDE_ROPE alarms that fire";
}

TEST(EnvelopeAlarm, ToleranceIsValidated) {
  TwinConfig c;
  c.service.envelope_tolerance = -0.001;
  EXPECT_THROW(c.service.validate(), std::invalid_argument);
  c.service.envelope_tolerance = 0.06;
  EXPECT_THROW(c.service.validate(), std::invalid_argument);
  c.service.envelope_tolerance = std::nan("");
  EXPECT_THROW(c.service.validate(), std::invalid_argument);
  c.service.envelope_tolerance = 0.0;
  EXPECT_NO_THROW(c.service.validate());
}

// The per-tick budget of exact envelopes ([service] max_exact_envelopes_per_tick,
// the envelope_budget of TwinCore::onInput): a twin whose budget is always spent keeps
// the wider bound wherever it lies below the GUIDE_ROPE WARNING alarm's clear
// level.  Over the same trips and gaps as above, against the exact envelope:
//   * its guide deflection is never below the exact envelope;
//   * every deferred value lies below the clear level, so
//   * the GUIDE_ROPE alarms keep the sandwich of the test above (active with
//     the exact envelope => active with the budget => active with the exact
//     envelope and thresholds 1 % of the gap lower), the cage alarms are
//     identical, and
//   * it evaluates exactly less often than without a budget.
TEST(EnvelopeAlarm, ASpentBudgetDefersOnlyBelowTheAlarmsClearLevel) {
  const HoistProfile prof = HoistProfile::trapezoid();
  const long steps = std::lround((prof.endTime() - prof.startTime()) / 0.01);
  std::int64_t deferred_total = 0;
  for (double gap : {0.030, 0.019, 0.0125})
    for (auto [n, corr] : {std::pair{20, true}, std::pair{50, false}}) {
      TwinConfig ce = demoConfig(n, corr, gap);
      ce.service.envelope_tolerance = 0.0;
      const TwinConfig cf = demoConfig(n, corr, gap);
      TwinConfig cl = ce;
      cl.alarms.warning_fraction -= 0.01;
      cl.alarms.critical_fraction -= 0.01;
      TwinCore exact(ce, ClockMode::Input), free(cf, ClockMode::Input), starved(cf, ClockMode::Input),
          lowered(cl, ClockMode::Input);
      int spent = 0;
      const double clear = (cf.alarms.warning_fraction - cf.alarms.deadband) * gap;
      ASSERT_DOUBLE_EQ(starved.envelopeDeferBelow(), clear);
      double worst_over = 0.0, worst_under = 0.0;
      std::int64_t deferred = 0;
      for (long k = 0; k <= steps; ++k) {
        const WinderSample s = sampleAt(prof, k, 0.01);
        spent = 0;  // every tick's budget is already spent
        for (TwinCore* c : {&exact, &free, &starved, &lowered}) {
          ASSERT_TRUE(c->onInput(s, 0.01 * k, c == &starved ? &spent : nullptr).accepted) << k;
          c->clearEvents();
        }
        const double e = exact.output().clearance.guide_deflection;
        const double b = starved.output().clearance.guide_deflection;
        worst_under = std::max(worst_under, e - b);
        worst_over = std::max(worst_over, b - e);
        if (starved.envelope().lastDeferred()) {
          ++deferred;
          ASSERT_LT(b, clear) << "deferred at or above the clear level, step " << k;
        }
        ASSERT_LE(spent, 0) << "the core spent no budget it was not given";
        ASSERT_TRUE(alarmsSandwiched(exact, starved, lowered, k));
      }
      std::printf("guide gap %.1f mm, n = %d, correction %s: budget always spent: %lld deferred, exact on %lld "
                  "steps (%lld without a budget), longest deferral %d steps, deflection at most %.3f mm "
                  "(%.1f %% of the gap) above the exact one\n",
                  gap * 1e3, n, corr ? "on" : "off", static_cast<long long>(deferred),
                  static_cast<long long>(starved.envelope().exactEvaluations()),
                  static_cast<long long>(free.envelope().exactEvaluations()), starved.envelope().longestDeferral(),
                  worst_over * 1e3, 100.0 * worst_over / gap);
      EXPECT_LE(worst_under, 1e-15) << "the deferred bound fell below the exact envelope";
      EXPECT_EQ(starved.envelope().deferredEvaluations(), deferred);
      EXPECT_LT(starved.envelope().exactEvaluations(), free.envelope().exactEvaluations());
      EXPECT_EQ(free.envelope().deferredEvaluations(), 0) << "no budget, no deferral";
      deferred_total += deferred;
    }
  EXPECT_GT(deferred_total, 100) << "the test needs deferred evaluations";
}

// Many twins in lockstep (the daemon's worst case: all need the exact
// envelope on the same tick) sharing one budget per tick, as a schedule's
// shafts do: at most the budget's exact evaluations per tick (the default
// 0.3 m gap never brings a deflection near the clear level, so none is
// forced), every twin's value at or above the exact envelope, and every
// twin refreshed within a bounded number of ticks.
TEST(EnvelopeAlarm, LockstepTwinsShareTheBudgetAndEachIsRefreshed) {
  const HoistProfile prof = HoistProfile::trapezoid();
  const double dt = 0.01;
  const long steps = std::lround((prof.endTime() - prof.startTime()) / dt);
  constexpr int kTwins = 24, kBudget = 3;
  TwinConfig c;
  c.shaft.n = 12;
  c.shaft.static_correction = true;
  c.service.max_step = dt;
  TwinConfig ce = c;
  ce.service.envelope_tolerance = 0.0;
  TwinCore exact(ce, ClockMode::Input);
  std::vector<std::unique_ptr<TwinCore>> twins;
  for (int i = 0; i < kTwins; ++i) twins.push_back(std::make_unique<TwinCore>(c, ClockMode::Input));
  TwinCore alone(c, ClockMode::Input);  // no budget: how many exact evaluations the trip needs
  int worst_tick = 0, longest = 0;
  std::int64_t deferred = 0;
  for (long k = 0; k <= steps; ++k) {
    const WinderSample s = sampleAt(prof, k, dt);
    ASSERT_TRUE(exact.onInput(s, dt * k).accepted);
    ASSERT_TRUE(alone.onInput(s, dt * k).accepted);
    int left = kBudget;
    int exact_this_tick = 0;
    for (auto& t : twins) {
      const std::int64_t before = t->envelope().exactEvaluations();
      ASSERT_TRUE(t->onInput(s, dt * k, &left).accepted);
      exact_this_tick += static_cast<int>(t->envelope().exactEvaluations() - before);
      ASSERT_GE(t->output().clearance.guide_deflection, exact.output().clearance.guide_deflection - 1e-15)
          << "step " << k;
    }
    // (The first step of every twin has no reference yet: exact regardless.)
    if (k > 0) ASSERT_LE(exact_this_tick, kBudget) << "step " << k;
    worst_tick = std::max(worst_tick, exact_this_tick);
  }
  for (auto& t : twins) {
    longest = std::max(longest, t->envelope().longestDeferral());
    deferred += t->envelope().deferredEvaluations();
  }
  std::printf("%d lockstep twins, budget %d per tick: %lld deferred evaluations, longest deferral %d ticks; one "
              "twin alone evaluates exactly on %lld of %ld steps\n",
              kTwins, kBudget, static_cast<long long>(deferred), longest,
              static_cast<long long>(alone.envelope().exactEvaluations()), steps + 1);
  EXPECT_GT(deferred, 0) << "the lockstep twins needed more than the budget on some tick";
  EXPECT_LE(longest, kTwins / kBudget + 2) << "each twin refreshed within about twins / budget ticks";
}

TEST(EnvelopeAlarm, BudgetIsValidated) {
  TwinConfig c;
  c.service.max_exact_envelopes_per_tick = -1;
  EXPECT_THROW(c.service.validate(), std::invalid_argument);
  c.service.max_exact_envelopes_per_tick = 100001;
  EXPECT_THROW(c.service.validate(), std::invalid_argument);
  c.service.max_exact_envelopes_per_tick = 0;
  EXPECT_NO_THROW(c.service.validate());
  EXPECT_EQ(ServiceConfig{}.max_exact_envelopes_per_tick, 32) << "the default";
}
