// The daemon's look-ahead rules, pure parts: the single-slot
// mailbox (newest wins, drops counted, safe across two threads -- this test
// also runs under ThreadSanitizer), trip-plan checks with their reasons, the
// verdict behind PREDICTED_CLEARANCE / PREDICTED_SLACK, the alarms and their
// text.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "hoist/service/core/forecast_rules.hpp"
#include "hoist/rt/latest_mailbox.hpp"
#include "hoist/service/lcm/messages.hpp"
#include "hoist/service/core/plan_senders.hpp"

using namespace hoist;
using namespace hoist::service;
using hoist::rt::LatestMailbox;

TEST(LatestMailbox, NewestWinsAndReplacedItemsAreCounted) {
  LatestMailbox<int> box(0);
  EXPECT_EQ(box.take(), nullptr);
  box.writeSlot() = 1;
  EXPECT_FALSE(box.publish());
  const int* got = box.take();
  ASSERT_NE(got, nullptr);
  EXPECT_EQ(*got, 1);
  EXPECT_EQ(box.take(), nullptr);  // nothing new
  box.writeSlot() = 2;
  EXPECT_FALSE(box.publish());
  box.writeSlot() = 3;
  EXPECT_TRUE(box.publish());  // 2 was never read: dropped
  box.writeSlot() = 4;
  EXPECT_TRUE(box.publish());
  got = box.take();
  ASSERT_NE(got, nullptr);
  EXPECT_EQ(*got, 4);  // only the newest, no backlog
  EXPECT_EQ(box.take(), nullptr);
}

TEST(LatestMailbox, TwoThreadsSeeWholeItemsInOrder) {
  // Each item is 64 copies of one number: a torn item (a slot written while
  // read) would show two numbers.  Items arrive in increasing order.
  struct Item {
    std::array<long, 64> v{};
  };
  LatestMailbox<Item> box(Item{});
  constexpr long kItems = 200000;
  std::atomic<bool> done{false};
  long dropped = 0;
  std::thread writer([&] {
    for (long i = 1; i <= kItems; ++i) {
      Item& it = box.writeSlot();
      it.v.fill(i);
      if (box.publish()) ++dropped;
    }
    done = true;
  });
  long last = 0, taken = 0, torn = 0, backwards = 0;
  while (true) {
    const bool finished = done.load();
    if (const Item* it = box.take()) {
      ++taken;
      for (long x : it->v) torn += x != it->v[0];
      backwards += it->v[0] <= last;
      last = it->v[0];
    } else if (finished) {
      break;
    }
  }
  writer.join();
  EXPECT_EQ(torn, 0);
  EXPECT_EQ(backwards, 0);
  EXPECT_EQ(last, kItems);             // the newest always arrives
  EXPECT_EQ(taken + dropped, kItems);  // every item is either taken or counted as dropped
}

namespace {
const ShaftParams kShaft{};  // paper shaft: L - 2h = 384 m
const Kinematics kCruiseDown{137.5, 5.0, 0.0};
}  // namespace

TEST(TripPlanCheck, EachBadPlanHasItsReason) {
  MotionProfile scratch;
  auto reason = [&](TripPlan p, Kinematics k = kCruiseDown) {
    const PlanCheck c = checkPlan(p, 20.0, k, kShaft, scratch);
    return c.ok() ? std::string("ok") : std::string(toString(planReject(c.error)));
  };
  EXPECT_EQ(reason({300.0, 5.0, 1.0, 1.0}), "ok");
  EXPECT_EQ(reason({390.0, 5.0, 1.0, 1.0}), "plan_target_outside_shaft");  // beyond L - 2h = 384 m
  EXPECT_EQ(reason({-5.0, 5.0, 1.0, 1.0}), "plan_target_outside_shaft");
  EXPECT_EQ(reason({std::nan(""), 5.0, 1.0, 1.0}), "plan_not_finite");
  EXPECT_EQ(reason({300.0, std::numeric_limits<double>::infinity(), 1.0, 1.0}), "plan_not_finite");
  EXPECT_EQ(reason({300.0, 0.0, 1.0, 1.0}), "plan_non_positive_limit");
  EXPECT_EQ(reason({300.0, 5.0, -1.0, 1.0}), "plan_non_positive_limit");
  EXPECT_EQ(reason({300.0, 5.0, 1.0, 0.0}), "plan_non_positive_limit");
  EXPECT_EQ(reason({100.0, 5.0, 1.0, 1.0}), "plan_wrong_direction");  // behind the cage, which descends
  EXPECT_EQ(reason({300.0, 4.0, 1.0, 1.0}), "plan_speed_above_vmax");
  EXPECT_EQ(reason({140.0, 5.0, 1.0, 1.0}), "plan_unreachable");  // 2.5 m ahead at 5 m/s
  EXPECT_EQ(reason({300.0, 5.0, 1.0, 1.0}, {137.5, 4.0, 2.0}), "plan_accel_above_amax");
  // Names are distinct and prefixed (HOIST_HEALTH reasons).
  for (int i = 0; i < kPlanRejectReasons; ++i)
    for (int j = 0; j < i; ++j)
      EXPECT_STRNE(toString(static_cast<PlanReject>(i)), toString(static_cast<PlanReject>(j)));
}

TEST(ForecastVerdict, EarliestCrossingOfAnyFiniteScenario) {
  ForecastSummary a, b;
  a.t_critical = 7.5;
  b.t_critical = 3.0;
  a.series_count = b.series_count = 4;
  for (int i = 0; i < 4; ++i) {
    a.series_t[i] = b.series_t[i] = 5.0 * (i + 1);
    a.series_lambda0_min[i] = b.series_lambda0_min[i] = 8000.0;
  }
  a.lambda0_min = b.lambda0_min = 8000.0;
  a.series_lambda0_min[2] = 3000.0;  // slack in a's 3rd bucket (ends at 15 s)
  a.lambda0_min = 3000.0;
  const ForecastSummary* s[2] = {&a, &b};
  ForecastVerdict v = judgeForecast(s, 2, 4000.0);
  EXPECT_TRUE(v.clearance);
  EXPECT_EQ(v.clearance_scenario, 1);
  EXPECT_EQ(v.clearance_s, 3.0);
  EXPECT_TRUE(v.slack);
  EXPECT_EQ(v.slack_scenario, 0);
  EXPECT_EQ(v.slack_s, 15.0);
  v = judgeForecast(s, 2, 2000.0);  // threshold below every lambda_0
  EXPECT_FALSE(v.slack);
  // A non-finite scenario predicts nothing.
  b.status = ForecastStatus::NonFinite;
  a.t_critical = -1.0;
  v = judgeForecast(s, 2, 2000.0);
  EXPECT_FALSE(v.clearance);
  EXPECT_EQ(v.clearance_s, -1.0);
}

TEST(ForecastVerdict, SlackThresholdIsTheLiveRopeSlackAlarms) {
  TwinConfig c;
  c.shaft.n = 4;
  c.alarms.slack_fraction = 0.4;
  const ShaftModel model(c.shaft);
  // ROPE_SLACK's threshold: slack_fraction x the static rope force m g + Fa.
  EXPECT_NEAR(slackThreshold(c, model, 137.5), 0.4 * (800.0 * 9.81 + 1000.0), 1e-9);
}

TEST(PredictedAlarms, RaiseAtOnceClearAfterOffDelayNameScenarioAndSeconds) {
  AlarmConfig cfg;
  cfg.off_delay = 1.0;
  AlarmEngine eng(cfg);
  AlarmEvents ev;
  eng.setPredictedClearance(10.0, true, 6.25, 20.0, ev);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, AlarmKind::PredictedClearance);
  EXPECT_EQ(ev[0].level, AlarmLevel::Warning);
  EXPECT_EQ(ev[0].type, AlarmEventType::Raise);
  EXPECT_EQ(ev[0].value, 6.25);
  EXPECT_EQ(ev[0].threshold, 20.0);
  EXPECT_FALSE(ev[0].latched);
  AlarmTextContext ctx;
  ctx.alarms = &cfg;
  ctx.predicted_clearance_scenario = "estop";
  char text[256];
  describeAlarm(ev[0], ctx, text, sizeof text);
  EXPECT_NE(std::string(text).find("PREDICTED_CLEARANCE WARNING raised: forecast scenario 'estop' crosses the "
                                   "CRITICAL clearance threshold in 6.2 s"),
            std::string::npos)
      << text;
  ev.clear();
  eng.setPredictedClearance(11.0, false, 0.0, 20.0, ev);
  EXPECT_TRUE(ev.empty());  // off_delay
  eng.poll(12.0, ev);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].type, AlarmEventType::Clear);
  // Slack, operator commands work on it like on every alarm.
  ev.clear();
  eng.setPredictedSlack(20.0, true, 2.0, 20.0, ev);
  ASSERT_EQ(ev.size(), 1u);
  ctx.predicted_slack_scenario = "continue";
  ctx.slack_threshold = 4424.0;
  describeAlarm(ev[0], ctx, text, sizeof text);
  EXPECT_NE(std::string(text).find("PREDICTED_SLACK WARNING raised: forecast scenario 'continue' brings the "
                                   "hoisting-rope force lambda_0 below the slack threshold 4424 N within 2.0 s"),
            std::string::npos)
      << text;
  ev.clear();
  EXPECT_EQ(eng.shelve(20.5, AlarmKind::PredictedSlack, AlarmLevel::None, 60.0, ev), 1);
  EXPECT_EQ(eng.acknowledge(20.5, AlarmKind::PredictedSlack, AlarmLevel::None, ev), 1);
  EXPECT_EQ(parseAlarmKind("PREDICTED_CLEARANCE"), AlarmKind::PredictedClearance);
  EXPECT_EQ(parseAlarmKind("PREDICTED_SLACK"), AlarmKind::PredictedSlack);
}

// The trip-plan sequence rule is per sender (hoist/service/core/plan_senders.hpp):
// a forged INT64_MAX from one sender never makes another's plans old; a
// sender's own old seq is refused until its last plan expired, then a
// sequence reset is accepted; a full table forgets the sender heard longest ago.
TEST(PlanSenders, SequenceIsPerSenderAndResetsAfterExpiry) {
  PlanSenders s;
  const double timeout = 10.0;
  std::int64_t last = 0;
  double last_t = 0.0;
  EXPECT_FALSE(s.isOld(1, 5, 0.0, timeout, last, last_t));
  s.accept(1, 5, 0.0, timeout);
  s.accept(666, std::numeric_limits<std::int64_t>::max(), 0.5, timeout);  // forged sender
  EXPECT_FALSE(s.isOld(1, 6, 1.0, timeout, last, last_t)) << "another sender's seq does not lock sender 1 out";
  EXPECT_TRUE(s.isOld(1, 5, 1.0, timeout, last, last_t));
  EXPECT_EQ(last, 5);
  EXPECT_DOUBLE_EQ(last_t, 0.0);
  EXPECT_TRUE(s.isOld(666, 1, 1.0, timeout, last, last_t));
  s.accept(1, 6, 1.0, timeout);
  EXPECT_TRUE(s.isOld(1, 0, 10.9, timeout, last, last_t)) << "a reset before expiry is old";
  EXPECT_FALSE(s.isOld(1, 0, 11.1, timeout, last, last_t)) << "a reset after expiry is accepted";
  EXPECT_FALSE(s.isOld(1, 0, -9.1, timeout, last, last_t)) << "model time restarted (a new winder stream)";
  // More senders than the table holds: the one accepted longest ago is forgotten.
  for (std::int64_t id = 100; id < 100 + PlanSenders::kSenders; ++id) s.accept(id, 1, 2.0, timeout);
  EXPECT_FALSE(s.isOld(1, 6, 2.0, timeout, last, last_t)) << "sender 1 was forgotten";
  EXPECT_TRUE(s.isOld(100 + PlanSenders::kSenders - 1, 1, 2.0, timeout, last, last_t));
}
