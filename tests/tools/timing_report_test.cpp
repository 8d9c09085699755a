// hoist-replay --timing-test: the verdict rules and the report (evaluate(),
// formatReport(); pure, no LCM).
#include <gtest/gtest.h>

#include "timing_test.hpp"

namespace {

hoist::replay::TimingResult healthyRun(int shafts) {
  hoist::replay::TimingResult r;
  r.host = "test";
  r.date = "2026-01-01T00:00:00Z";
  r.elapsed = 10.0;
  for (int i = 0; i < 100; ++i) r.feeder_late.add(50.0);
  for (int s = 0; s < shafts; ++s) {
    hoist::replay::ShaftResult x;
    x.prefix = "shaft" + std::to_string(s + 1) + "/";
    x.heard = x.final_report = true;
    x.windows = 10;
    x.clock = "wall";
    x.daemon_rate = 100.0;
    x.sent = x.accepted = 1000;
    x.late_p99_worst = 100.0 + s;
    x.late_max = 500.0;
    x.step_p99_worst = 20.0;
    x.step_max = 40.0;
    for (int k = 0; k < 1000; ++k) x.e2e.add(1000.0 + k);
    r.shafts.push_back(x);
  }
  return r;
}

}  // namespace

TEST(TimingVerdict, BudgetsAggregateOverShafts) {
  using namespace hoist::replay;
  TimingTestOptions o;
  o.prefixes = {"shaft1/", "shaft2/", "shaft3/"};
  o.budgets.late_p99_us = 101.5;
  o.budgets.max_misses = 2;
  TimingResult r = healthyRun(3);
  Evaluation e = evaluate(r, o);
  EXPECT_EQ(e.verdict, Verdict::Fail);  // shaft3's 102 us is the worst window
  ASSERT_EQ(e.violations.size(), 1u);
  EXPECT_NE(e.violations[0].find("--max-late-p99-us"), std::string::npos);
  EXPECT_DOUBLE_EQ(e.late_p99, 102.0);

  o.budgets.late_p99_us = 200.0;
  r.shafts[0].misses = 1;
  r.shafts[2].misses = 1;
  e = evaluate(r, o);
  EXPECT_EQ(e.verdict, Verdict::Pass);  // 2 misses summed: within 2
  EXPECT_EQ(e.misses, 2);
  r.shafts[1].misses = 1;
  e = evaluate(r, o);
  EXPECT_EQ(e.verdict, Verdict::Fail);
  EXPECT_NE(e.violations.at(0).find("measured 3 > allowed 2"), std::string::npos) << e.violations[0];

  const std::string text = formatReport(r, o, e);
  EXPECT_EQ(text.rfind("VERDICT: FAIL\n", 0), 0u);
  EXPECT_NE(text.find("## Per shaft"), std::string::npos);
}

TEST(TimingVerdict, LateFeederIsInconclusiveAndRejectionsFail) {
  using namespace hoist::replay;
  TimingTestOptions o;
  o.rate = 1000.0;
  o.prefixes = {""};
  TimingResult r = healthyRun(1);
  r.shafts[0].rejected = 1;
  r.shafts[0].accepted = 999;
  r.shafts[0].rejected_by_reason["length_range"] = 1;
  Evaluation e = evaluate(r, o);
  EXPECT_EQ(e.verdict, Verdict::Fail);
  EXPECT_NE(e.violations.at(0).find("--max-rejected"), std::string::npos);
  bool hint = false;
  for (const auto& n : e.notes) hint = hint || n.find("--config") != std::string::npos;
  EXPECT_TRUE(hint) << "a length_range rejection suggests --config";
  // A feeder late by more than one period (1 ms) at p99: INCONCLUSIVE.
  for (int i = 0; i < 100; ++i) r.feeder_late.add(5000.0);
  e = evaluate(r, o);
  EXPECT_EQ(e.verdict, Verdict::Inconclusive);
  EXPECT_EQ(formatReport(r, o, e).rfind("VERDICT: INCONCLUSIVE", 0), 0u);
}

TEST(TimingVerdict, ALateFeederDoesNotExcuseTheDaemonsOwnStepTime) {
  // Issue 33: --max-step-p99-us 0.001 cannot pass on any machine; a feeder
  // late on a busy machine made the verdict INCONCLUSIVE.  The step time is
  // the daemon's own: FAIL.  A lateness budget stays INCONCLUSIVE.
  using namespace hoist::replay;
  TimingTestOptions o;
  o.rate = 1000.0;
  o.prefixes = {""};
  TimingResult r = healthyRun(1);
  for (int i = 0; i < 100; ++i) r.feeder_late.add(5000.0);  // p99 over one period (1 ms)
  o.budgets.step_p99_us = 0.001;
  Evaluation e = evaluate(r, o);
  EXPECT_EQ(e.verdict, Verdict::Fail);
  ASSERT_EQ(e.violations.size(), 1u);
  EXPECT_NE(e.violations[0].find("--max-step-p99-us"), std::string::npos);
  bool said = false;
  for (const auto& n : e.notes) said = said || n.find("the verdict is FAIL") != std::string::npos;
  EXPECT_TRUE(said) << "the report says why the late feeder does not matter";
  o.budgets.step_p99_us.reset();
  o.budgets.late_p99_us = 1.0;  // the daemon's lateness: a late feeder may explain it
  e = evaluate(r, o);
  EXPECT_EQ(e.verdict, Verdict::Inconclusive);
  r.shafts[0].restarted = true;  // a restart is the daemon's own
  e = evaluate(r, o);
  EXPECT_EQ(e.verdict, Verdict::Fail);
}

TEST(TimingVerdict, ManyShaftsListOnlyTheWorst) {
  using namespace hoist::replay;
  TimingTestOptions o;
  TimingResult r = healthyRun(30);
  o.prefixes.clear();
  for (const auto& s : r.shafts) o.prefixes.push_back(s.prefix);
  r.shafts[17].misses = 5;
  o.budgets.max_misses = 10;
  const Evaluation e = evaluate(r, o);
  EXPECT_EQ(e.verdict, Verdict::Pass);
  const std::string text = formatReport(r, o, e);
  EXPECT_NE(text.find("## The 10 worst of 30 shafts"), std::string::npos) << text;
  // shaft18 (5 misses) first, then by lateness: shaft30, shaft29, ...
  const auto first = text.find("| \"shaft18/\" |");
  ASSERT_NE(first, std::string::npos) << text;
  EXPECT_LT(first, text.find("| \"shaft30/\" |"));
  EXPECT_EQ(text.find("| \"shaft1/\" |"), std::string::npos) << "only the 10 worst";
}
