// Clearance alarm logic: thresholds, deadband, on/off delays, latching,
// acknowledgement, shelving, re-announcement (service/alarms.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "hoist/service/core/alarms.hpp"

using namespace hoist::service;

namespace {

AlarmSettings settings(double thr, double db = 0.0, double on = 0.0, double off = 0.0,
                       bool latch = false, double re = 0.0) {
  AlarmSettings s;
  s.threshold = thr;
  s.deadband = db;
  s.on_delay = on;
  s.off_delay = off;
  s.latch = latch;
  s.reannounce = re;
  return s;
}

int count(const AlarmEvents& ev, AlarmEventType type) {
  int n = 0;
  for (const auto& e : ev) n += e.type == type;
  return n;
}

}  // namespace

TEST(BinaryAlarm, RaisesAtThresholdAndClearsBelow) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Warning, settings(1.0));
  AlarmEvents ev;
  a.update(0.0, 0.99, ev);
  EXPECT_TRUE(ev.empty());
  a.update(0.1, 1.0, ev);  // at the threshold: raise
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].type, AlarmEventType::Raise);
  EXPECT_TRUE(ev[0].active);
  EXPECT_FALSE(ev[0].acked);
  EXPECT_DOUBLE_EQ(ev[0].value, 1.0);
  EXPECT_DOUBLE_EQ(ev[0].threshold, 1.0);
  EXPECT_DOUBLE_EQ(ev[0].t, 0.1);
  ev.clear();
  a.update(0.2, 1.5, ev);  // still active: nothing new
  EXPECT_TRUE(ev.empty());
  a.update(0.3, 0.5, ev);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].type, AlarmEventType::Clear);
  EXPECT_FALSE(a.active());
}

TEST(BinaryAlarm, DeadbandStopsChatterAtTheThreshold) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Warning, settings(1.0, 0.1));
  AlarmEvents ev;
  // Noise of +-0.05 around the threshold: one raise, never a clear.
  for (int i = 0; i < 200; ++i) a.update(i * 0.01, 1.0 + ((i % 2) ? 0.05 : -0.05), ev);
  EXPECT_EQ(count(ev, AlarmEventType::Raise), 1);
  EXPECT_EQ(count(ev, AlarmEventType::Clear), 0);
  ev.clear();
  a.update(3.0, 0.91, ev);  // inside the deadband: still active
  EXPECT_TRUE(a.active());
  a.update(3.1, 0.899, ev);  // below threshold - deadband: clear
  EXPECT_FALSE(a.active());
  EXPECT_EQ(count(ev, AlarmEventType::Clear), 1);
}

TEST(BinaryAlarm, WithoutDeadbandTheSameNoiseChatters) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Warning, settings(1.0));
  AlarmEvents ev;
  for (int i = 0; i < 20; ++i) a.update(i * 0.01, 1.0 + ((i % 2) ? 0.05 : -0.05), ev);
  EXPECT_EQ(count(ev, AlarmEventType::Raise), 10);  // what the deadband prevents
}

TEST(BinaryAlarm, OnDelayRequiresAPersistentExcursion) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Warning, settings(1.0, 0.0, 0.5));
  AlarmEvents ev;
  a.update(0.0, 2.0, ev);
  a.update(0.4, 2.0, ev);
  EXPECT_FALSE(a.active());
  a.update(0.45, 0.5, ev);  // dips: the on-delay restarts
  a.update(0.5, 2.0, ev);
  a.update(0.9, 2.0, ev);
  EXPECT_FALSE(a.active());
  a.update(1.0, 2.0, ev);  // 0.5 s continuously over
  EXPECT_TRUE(a.active());
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_DOUBLE_EQ(ev[0].t, 1.0);
}

TEST(BinaryAlarm, OffDelayHoldsTheAlarm) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Warning, settings(1.0, 0.0, 0.0, 1.0));
  AlarmEvents ev;
  a.update(0.0, 2.0, ev);
  ASSERT_TRUE(a.active());
  a.update(0.1, 0.0, ev);
  a.update(0.6, 0.0, ev);
  a.update(0.7, 1.5, ev);  // back over: the off-delay restarts
  a.update(0.8, 0.0, ev);
  a.update(1.7, 0.0, ev);
  EXPECT_TRUE(a.active());
  a.update(1.8, 0.0, ev);  // 1.0 s continuously under
  EXPECT_FALSE(a.active());
  EXPECT_EQ(count(ev, AlarmEventType::Raise), 1);
  EXPECT_EQ(count(ev, AlarmEventType::Clear), 1);
}

TEST(BinaryAlarm, LatchedCriticalNeedsAcknowledgement) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Critical, settings(1.0, 0.0, 0.0, 0.0, true));
  AlarmEvents ev;
  a.update(0.0, 2.0, ev);
  a.update(0.1, 0.0, ev);  // condition gone, alarm stays
  EXPECT_TRUE(a.active());
  EXPECT_TRUE(a.latched());
  EXPECT_EQ(count(ev, AlarmEventType::Clear), 0);
  ev.clear();
  EXPECT_TRUE(a.acknowledge(0.2, ev));
  EXPECT_FALSE(a.active());
  ASSERT_EQ(ev.size(), 2u);  // ACK, then CLEAR
  EXPECT_EQ(ev[0].type, AlarmEventType::Ack);
  EXPECT_EQ(ev[1].type, AlarmEventType::Clear);
  EXPECT_FALSE(a.acknowledge(0.3, ev));  // nothing left to acknowledge
}

TEST(BinaryAlarm, AcknowledgedWhileActiveClearsWhenTheConditionGoes) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Critical, settings(1.0, 0.0, 0.0, 0.0, true));
  AlarmEvents ev;
  a.update(0.0, 2.0, ev);
  ev.clear();
  EXPECT_TRUE(a.acknowledge(0.1, ev));
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_TRUE(ev[0].active);
  EXPECT_TRUE(ev[0].acked);
  ev.clear();
  a.update(0.2, 0.0, ev);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].type, AlarmEventType::Clear);
  // A new excursion needs a new acknowledgement.
  ev.clear();
  a.update(0.3, 2.0, ev);
  EXPECT_TRUE(a.active());
  EXPECT_FALSE(a.acked());
}

TEST(BinaryAlarm, ReturnedToNormalUnacknowledgedCanBeAcknowledged) {
  // ISA-18.2 RTN UNACK: an unlatched alarm whose condition went away before
  // anyone acknowledged it stays listed until it is acknowledged.
  BinaryAlarm a(AlarmKind::InputStale, AlarmLevel::Warning, settings(0.5));
  AlarmEvents ev;
  EXPECT_FALSE(a.acknowledge(0.0, ev));  // never raised: nothing to acknowledge
  EXPECT_FALSE(a.rtnUnacked());
  a.update(0.1, 1.0, ev);
  a.update(0.2, 0.0, ev);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[1].type, AlarmEventType::Clear);
  EXPECT_FALSE(ev[1].acked);
  EXPECT_TRUE(a.rtnUnacked());
  ev.clear();
  EXPECT_TRUE(a.acknowledge(0.3, ev));
  ASSERT_EQ(ev.size(), 1u);  // the ACK alone: the alarm was already announced clear
  EXPECT_EQ(ev[0].type, AlarmEventType::Ack);
  EXPECT_FALSE(ev[0].active);
  EXPECT_TRUE(ev[0].acked);
  EXPECT_FALSE(a.rtnUnacked());
  EXPECT_FALSE(a.acknowledge(0.4, ev));  // once only
  // The next excursion needs its own acknowledgement.
  ev.clear();
  a.update(0.5, 1.0, ev);
  EXPECT_FALSE(a.acked());
  a.update(0.6, 0.0, ev);
  EXPECT_TRUE(a.rtnUnacked());
}

TEST(AlarmEngine, AcknowledgeAllReachesReturnedToNormalAlarms) {
  // hoist-alarm-ack --kind '*' (kind empty, level None).
  AlarmEngine eng;
  AlarmEvents ev;
  eng.setInputStale(1.0, true, ev);
  eng.setInputStale(1.1, false, ev);
  ev.clear();
  EXPECT_EQ(eng.acknowledge(1.2, std::nullopt, AlarmLevel::None, ev), 1);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, AlarmKind::InputStale);
  EXPECT_EQ(ev[0].type, AlarmEventType::Ack);
  EXPECT_EQ(eng.acknowledge(1.3, std::nullopt, AlarmLevel::None, ev), 0);
}

TEST(BinaryAlarm, ShelvingSuppressesAndExpires) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Warning, settings(1.0));
  AlarmEvents ev;
  EXPECT_TRUE(a.shelve(0.0, 10.0, ev));
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].type, AlarmEventType::Shelve);
  EXPECT_DOUBLE_EQ(ev[0].shelved_for, 10.0);
  ev.clear();
  for (int i = 0; i < 50; ++i) a.update(0.1 * i, (i % 2) ? 2.0 : 0.0, ev);  // chattering, silent
  EXPECT_TRUE(ev.empty());
  a.update(9.0, 2.0, ev);
  EXPECT_TRUE(ev.empty());
  a.update(10.0, 2.0, ev);  // expiry: UNSHELVE, then the current state
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].type, AlarmEventType::Unshelve);
  EXPECT_EQ(ev[1].type, AlarmEventType::Raise);
  EXPECT_FALSE(ev[1].shelved);
}

TEST(BinaryAlarm, UnshelveEarlyAnnouncesAClearThatHappenedWhileShelved) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Warning, settings(1.0));
  AlarmEvents ev;
  a.update(0.0, 2.0, ev);  // raised and announced
  a.shelve(0.5, 100.0, ev);
  a.update(1.0, 0.0, ev);  // clears silently
  ev.clear();
  EXPECT_TRUE(a.unshelve(2.0, ev));
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].type, AlarmEventType::Unshelve);
  EXPECT_EQ(ev[1].type, AlarmEventType::Clear);
  EXPECT_FALSE(a.unshelve(3.0, ev));
  EXPECT_FALSE(a.shelve(3.0, 0.0, ev));  // a shelve needs a duration
}

TEST(BinaryAlarm, ReannouncesActiveAlarmsPeriodically) {
  BinaryAlarm a(AlarmKind::CagePosY, AlarmLevel::Warning, settings(1.0, 0.0, 0.0, 0.0, false, 5.0));
  AlarmEvents ev;
  for (int i = 0; i <= 120; ++i) a.update(0.1 * i, 2.0, ev);  // 12 s active
  EXPECT_EQ(count(ev, AlarmEventType::Raise), 1);
  EXPECT_EQ(count(ev, AlarmEventType::Reannounce), 2);  // at 5 s and 10 s
}

TEST(BinaryAlarm, NonFiniteValueIsTreatedAsOverThreshold) {
  BinaryAlarm a(AlarmKind::GuideRope, AlarmLevel::Warning, settings(1.0, 0.1));
  AlarmEvents ev;
  a.update(0.0, std::numeric_limits<double>::quiet_NaN(), ev);
  EXPECT_TRUE(a.active());
}

TEST(AlarmConfig, ValidateNamesTheKey) {
  AlarmConfig c;
  c.warning_fraction = 0.9;
  c.critical_fraction = 0.8;
  try {
    c.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("alarms.warning_fraction"), std::string::npos);
  }
  c = AlarmConfig{};
  c.gap_pos_y = std::nan("");
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

TEST(Clearance, TopAndBottomExcursionsFollowModelConventions) {
  AlarmConfig cfg;
  cfg.gap_pos_y = 0.02;
  cfg.gap_neg_y = 0.03;
  cfg.guide_rope_gap = 0.05;
  const double h = 8.0;
  // y_c = 5 mm, theta = 0.75 mrad: top y_c - h theta = -1 mm, bottom +11 mm.
  const Clearance c = computeClearance(0.005, 0.00075, h, 0.012, cfg);
  EXPECT_NEAR(c.y_top, -0.001, 1e-12);
  EXPECT_NEAR(c.y_bottom, 0.011, 1e-12);
  EXPECT_NEAR(c.excursion_pos, 0.011, 1e-12);
  EXPECT_NEAR(c.excursion_neg, 0.001, 1e-12);
  EXPECT_NEAR(c.clearance_pos, 0.009, 1e-12);
  EXPECT_NEAR(c.clearance_neg, 0.029, 1e-12);
  EXPECT_NEAR(c.clearance_guide, 0.038, 1e-12);
  EXPECT_NEAR(c.min_clearance, 0.009, 1e-12);
}

TEST(AlarmEngine, WarningThenCriticalOnOneSide) {
  AlarmConfig cfg;
  cfg.gap_pos_y = 0.02;
  cfg.warning_fraction = 0.5;   // 10 mm
  cfg.critical_fraction = 0.8;  // 16 mm
  cfg.deadband = 0.05;          // 1 mm
  cfg.on_delay = 0.0;
  cfg.off_delay = 0.0;
  AlarmEngine eng(cfg);
  AlarmEvents ev;
  auto feed = [&](double t, double y_c) { eng.updateClearance(t, computeClearance(y_c, 0.0, 8.0, 0.0, cfg), ev); };
  feed(0.0, 0.005);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::None);
  feed(0.1, 0.012);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::Warning);
  feed(0.2, 0.017);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::Critical);
  EXPECT_EQ(eng.activeCount(), 2);
  feed(0.3, 0.0);  // both conditions gone; CRITICAL latched
  EXPECT_EQ(eng.highestActive(), AlarmLevel::Critical);
  EXPECT_EQ(eng.activeCount(), 1);
  ev.clear();
  // Acknowledge all CAGE_POS_Y alarms: the latched CRITICAL and the WARNING
  // that returned to normal unacknowledged (RTN UNACK).
  EXPECT_EQ(eng.acknowledge(0.4, AlarmKind::CagePosY, AlarmLevel::None, ev), 2);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::None);
  EXPECT_EQ(eng.activeCount(), 0);
  // The other side never alarmed.
  EXPECT_FALSE(eng.find(AlarmKind::CageNegY, AlarmLevel::Warning)->active());
}

TEST(AlarmEngine, ShelveIsBoundedByMaxShelve) {
  AlarmConfig cfg;
  cfg.max_shelve = 60.0;
  AlarmEngine eng(cfg);
  AlarmEvents ev;
  EXPECT_EQ(eng.shelve(0.0, AlarmKind::GuideRope, AlarmLevel::None, 1e9, ev), 2);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_DOUBLE_EQ(ev[0].shelved_for, 60.0);
  EXPECT_EQ(eng.shelvedCount(), 2);
  ev.clear();
  eng.poll(60.0, ev);
  EXPECT_EQ(eng.shelvedCount(), 0);
  EXPECT_EQ(ev.size(), 2u);  // two UNSHELVE events
}

TEST(AlarmEngine, StaleAndFaultFlags) {
  AlarmEngine eng;
  AlarmEvents ev;
  eng.setInputStale(0.0, true, ev);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::Warning);
  eng.setInputStale(1.0, false, ev);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::None);
  eng.setModelFault(2.0, true, ev);
  eng.setModelFault(2.01, false, ev);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::Critical);  // latched
  eng.acknowledge(3.0, std::nullopt, AlarmLevel::None, ev);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::None);
}

// The shaft's memory's verdicts: GUIDE_PRELOAD_LOW's WARNING is active at
// both levels, its CRITICAL latches; the events report the 95 % upper bound
// against each level's limit; SHAFT_FINGERPRINT reports z against its limit.
TEST(AlarmEngine, ConditionAlarmsFollowTheTrendAndTheCriticalLatches) {
  AlarmConfig cfg;
  cfg.reannounce = 0.0;  // only the changes
  AlarmEngine eng(cfg);
  AlarmEvents ev;
  eng.setGuidePreloadLow(0.0, AlarmLevel::Warning, 0.80, 0.85, 0.70, ev);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, AlarmKind::GuidePreloadLow);
  EXPECT_EQ(ev[0].level, AlarmLevel::Warning);
  EXPECT_EQ(ev[0].type, AlarmEventType::Raise);
  EXPECT_DOUBLE_EQ(ev[0].value, 0.80);
  EXPECT_DOUBLE_EQ(ev[0].threshold, 0.85);
  ev.clear();
  eng.setGuidePreloadLow(10.0, AlarmLevel::Critical, 0.64, 0.85, 0.70, ev);
  ASSERT_EQ(ev.size(), 1u);  // the WARNING stays up: only the CRITICAL rises
  EXPECT_EQ(ev[0].level, AlarmLevel::Critical);
  EXPECT_DOUBLE_EQ(ev[0].threshold, 0.70);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::Critical);
  ev.clear();
  eng.setGuidePreloadLow(20.0, AlarmLevel::None, 0.95, 0.85, 0.70, ev);
  ASSERT_EQ(ev.size(), 1u);  // the WARNING clears; the CRITICAL waits for an operator
  EXPECT_EQ(ev[0].level, AlarmLevel::Warning);
  EXPECT_EQ(ev[0].type, AlarmEventType::Clear);
  EXPECT_TRUE(eng.find(AlarmKind::GuidePreloadLow, AlarmLevel::Critical)->active());
  ev.clear();
  eng.acknowledge(21.0, AlarmKind::GuidePreloadLow, AlarmLevel::Critical, ev);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::None);
  ev.clear();
  eng.setShaftFingerprint(30.0, true, 5.6, 4.0, ev);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, AlarmKind::ShaftFingerprint);
  EXPECT_DOUBLE_EQ(ev[0].value, 5.6);
  EXPECT_DOUBLE_EQ(ev[0].threshold, 4.0);
  ev.clear();
  eng.setShaftFingerprint(31.0, true, 5.9, 4.0, ev);  // still active: no new event
  EXPECT_TRUE(ev.empty());
  eng.setShaftFingerprint(40.0, false, 1.0, 4.0, ev);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].type, AlarmEventType::Clear);
}

TEST(AlarmNames, RoundTrip) {
  for (int i = 0; i < kAlarmKinds; ++i) {
    const auto k = static_cast<AlarmKind>(i);
    EXPECT_EQ(parseAlarmKind(toString(k)), k);
  }
  EXPECT_FALSE(parseAlarmKind("NOPE"));
}

// ---- live rope-force alarms ----------------------------------------

TEST(BinaryAlarm, LowAlarmRaisesAtOrBelowAndClearsAboveThresholdPlusDeadband) {
  AlarmSettings s = settings(100.0, 10.0);
  s.low = true;
  BinaryAlarm a(AlarmKind::RopeSlack, AlarmLevel::Critical, s);
  AlarmEvents ev;
  a.update(0.0, 150.0, ev);
  EXPECT_FALSE(a.active());
  a.update(0.1, 100.0, ev);  // at the threshold: on
  EXPECT_TRUE(a.active());
  a.update(0.2, 109.0, ev);  // inside the deadband: stays
  EXPECT_TRUE(a.active());
  a.update(0.3, 110.5, ev);  // above threshold + deadband: off
  EXPECT_FALSE(a.active());
  EXPECT_EQ(count(ev, AlarmEventType::Raise), 1);
  EXPECT_EQ(count(ev, AlarmEventType::Clear), 1);
  a.update(0.4, std::numeric_limits<double>::quiet_NaN(), ev);  // fail safe
  EXPECT_TRUE(a.active());
  // Moving the threshold keeps the state: 105 is above 50 + 10 -> clears.
  a.setThreshold(50.0, 10.0);
  a.update(0.5, 105.0, ev);
  EXPECT_FALSE(a.active());
  EXPECT_EQ(a.settings().threshold, 50.0);
}

TEST(AlarmEngine, RopeSlackAndOverloadFollowTheStaticForce) {
  AlarmConfig cfg;  // slack 0.5, overload 1.5, force_deadband 0.05, on 0.1 s, off 1 s
  AlarmEngine eng(cfg);
  AlarmEvents ev;
  // No rope force yet: polling raises nothing (the slack alarm's "no value"
  // is not a zero force).
  eng.poll(0.0, ev);
  eng.poll(5.0, ev);
  EXPECT_TRUE(ev.empty());
  EXPECT_EQ(eng.activeCount(), 0);
  const double F = 800.0 * 9.81 + 1000.0;  // m g + Fa of the paper's shaft
  double t = 10.0;
  auto feed = [&](double lambda0, double seconds) {
    for (double end = t + seconds; t < end - 1e-9; t += 0.01) eng.updateRopeForce(t, lambda0, F, ev);
  };
  feed(F, 1.0);
  EXPECT_TRUE(ev.empty());
  EXPECT_DOUBLE_EQ(eng.ropeSlackThreshold(), 0.5 * F);
  EXPECT_DOUBLE_EQ(eng.ropeOverloadThreshold(), 1.5 * F);
  // A dip shorter than on_delay: nothing.
  feed(0.3 * F, 0.05);
  feed(F, 0.5);
  EXPECT_TRUE(ev.empty());
  // A slack rope: CRITICAL after the on-delay, value and threshold in N.
  feed(0.3 * F, 0.3);
  const BinaryAlarm* slack = eng.find(AlarmKind::RopeSlack, AlarmLevel::Critical);
  ASSERT_NE(slack, nullptr);
  EXPECT_TRUE(slack->active());
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, AlarmKind::RopeSlack);
  EXPECT_EQ(ev[0].level, AlarmLevel::Critical);
  EXPECT_EQ(ev[0].type, AlarmEventType::Raise);
  EXPECT_NEAR(ev[0].value, 0.3 * F, 1e-9);
  EXPECT_NEAR(ev[0].threshold, 0.5 * F, 1e-9);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::Critical);
  EXPECT_EQ(eng.find(AlarmKind::RopeSlack, AlarmLevel::Warning), nullptr);
  ev.clear();
  // Back inside the deadband (0.52 F < 0.55 F) for long: the condition holds.
  feed(0.52 * F, 2.0);
  EXPECT_TRUE(slack->condition());
  // Above it for off_delay: condition gone, but latched until acknowledged.
  feed(F, 1.5);
  EXPECT_FALSE(slack->condition());
  EXPECT_TRUE(slack->active());
  EXPECT_TRUE(slack->latched());
  EXPECT_EQ(eng.acknowledge(t, AlarmKind::RopeSlack, AlarmLevel::None, ev), 1);
  EXPECT_FALSE(slack->active());
  ev.clear();
  // Overload.
  feed(1.6 * F, 0.3);
  const BinaryAlarm* over = eng.find(AlarmKind::RopeOverload, AlarmLevel::Critical);
  ASSERT_NE(over, nullptr);
  EXPECT_TRUE(over->active());
  EXPECT_FALSE(slack->active());
  ASSERT_GE(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, AlarmKind::RopeOverload);
  EXPECT_NEAR(ev[0].threshold, 1.5 * F, 1e-9);
  // Shelving works as for every alarm.
  EXPECT_EQ(eng.shelve(t, AlarmKind::RopeOverload, AlarmLevel::Critical, 60.0, ev), 1);
  EXPECT_EQ(eng.highestActive(), AlarmLevel::None);
  // The thresholds follow the static force given (e.g. another length).
  eng.updateRopeForce(t, F, 2.0 * F, ev);
  EXPECT_DOUBLE_EQ(eng.ropeSlackThreshold(), F);
  EXPECT_DOUBLE_EQ(eng.ropeOverloadThreshold(), 3.0 * F);
  // A bad static force leaves them.
  eng.updateRopeForce(t, F, std::numeric_limits<double>::quiet_NaN(), ev);
  eng.updateRopeForce(t, F, -1.0, ev);
  EXPECT_DOUBLE_EQ(eng.ropeSlackThreshold(), F);
}

TEST(AlarmConfig, RopeForceKeysNameTheKey) {
  auto err = [](auto set) {
    AlarmConfig c;
    set(c);
    try {
      c.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(err([](AlarmConfig& c) { c.slack_fraction = 0.0; }).find("alarms.slack_fraction"), std::string::npos);
  EXPECT_NE(err([](AlarmConfig& c) { c.slack_fraction = 1.0; }).find("alarms.slack_fraction"), std::string::npos);
  EXPECT_NE(err([&](AlarmConfig& c) { c.slack_fraction = nan; }).find("alarms.slack_fraction"), std::string::npos);
  EXPECT_NE(err([](AlarmConfig& c) { c.overload_fraction = 1.0; }).find("alarms.overload_fraction"),
            std::string::npos);
  EXPECT_NE(err([](AlarmConfig& c) { c.overload_fraction = 101.0; }).find("alarms.overload_fraction"),
            std::string::npos);
  EXPECT_NE(err([](AlarmConfig& c) { c.force_deadband = -1e-3; }).find("alarms.force_deadband"), std::string::npos);
  EXPECT_NE(err([](AlarmConfig& c) { c.force_deadband = 0.5; }).find("alarms.force_deadband"), std::string::npos);
  EXPECT_NE(err([](AlarmConfig& c) {
              c.overload_fraction = 1.04;
            }).find("alarms.force_deadband"),
            std::string::npos);  // 0.05 deadband cannot clear 1.04 x static
  EXPECT_EQ(err([](AlarmConfig& c) {
              c.slack_fraction = 0.2;
              c.overload_fraction = 3.0;
              c.force_deadband = 0.0;
            }),
            "(no error)");
}

// The alarm slots come from one table (alarms.cpp, kSlotTable): every
// (kind, level) alarm exists once, carries its own kind and level, and gets
// the settings its rule gives it under the [alarms] section.
TEST(AlarmEngine, SlotTableGivesEachAlarmItsKindLevelAndSettings) {
  AlarmConfig cfg;
  cfg.gap_pos_y = 0.2;
  cfg.gap_neg_y = 0.25;
  cfg.guide_rope_gap = 0.4;
  cfg.latch_critical = false;
  cfg.off_delay = 0.7;
  const AlarmEngine eng(cfg);
  int found = 0;
  for (int k = 0; k < kAlarmKinds; ++k)
    for (const AlarmLevel l : {AlarmLevel::Warning, AlarmLevel::Critical})
      if (const BinaryAlarm* a = eng.find(static_cast<AlarmKind>(k), l)) {
        ++found;
        EXPECT_EQ(a->kind(), static_cast<AlarmKind>(k));
        EXPECT_EQ(a->level(), l);
      }
  EXPECT_EQ(found, AlarmEngine::kSlots);
  // Which alarms exist (the documented layout).
  const std::pair<AlarmKind, AlarmLevel> expected[] = {
      {AlarmKind::CagePosY, AlarmLevel::Warning},        {AlarmKind::CagePosY, AlarmLevel::Critical},
      {AlarmKind::CageNegY, AlarmLevel::Warning},        {AlarmKind::CageNegY, AlarmLevel::Critical},
      {AlarmKind::GuideRope, AlarmLevel::Warning},       {AlarmKind::GuideRope, AlarmLevel::Critical},
      {AlarmKind::InputStale, AlarmLevel::Warning},      {AlarmKind::ModelFault, AlarmLevel::Critical},
      {AlarmKind::ModelDomain, AlarmLevel::Critical},    {AlarmKind::DuplicatePublisher, AlarmLevel::Warning},
      {AlarmKind::RopeSlack, AlarmLevel::Critical},      {AlarmKind::RopeOverload, AlarmLevel::Critical},
      {AlarmKind::PredictedClearance, AlarmLevel::Warning}, {AlarmKind::PredictedSlack, AlarmLevel::Warning},
      {AlarmKind::ModelMismatch, AlarmLevel::Warning},   {AlarmKind::SensorFault, AlarmLevel::Warning},
      {AlarmKind::GuidePreloadLow, AlarmLevel::Warning}, {AlarmKind::GuidePreloadLow, AlarmLevel::Critical},
      {AlarmKind::ShaftFingerprint, AlarmLevel::Warning}};
  for (const auto& [k, l] : expected) EXPECT_NE(eng.find(k, l), nullptr) << toString(k) << "/" << toString(l);
  // Settings by rule.
  const AlarmSettings& neg_c = eng.find(AlarmKind::CageNegY, AlarmLevel::Critical)->settings();
  EXPECT_DOUBLE_EQ(neg_c.threshold, cfg.critical_fraction * cfg.gap_neg_y);
  EXPECT_DOUBLE_EQ(neg_c.deadband, cfg.deadband * cfg.gap_neg_y);
  EXPECT_FALSE(neg_c.latch);  // latch_critical = false
  const AlarmSettings& guide_w = eng.find(AlarmKind::GuideRope, AlarmLevel::Warning)->settings();
  EXPECT_DOUBLE_EQ(guide_w.threshold, cfg.warning_fraction * cfg.guide_rope_gap);
  EXPECT_DOUBLE_EQ(guide_w.off_delay, 0.7);
  EXPECT_TRUE(eng.find(AlarmKind::ModelFault, AlarmLevel::Critical)->settings().latch);  // always latched
  EXPECT_FALSE(eng.find(AlarmKind::ModelDomain, AlarmLevel::Critical)->settings().latch);
  EXPECT_TRUE(eng.find(AlarmKind::RopeSlack, AlarmLevel::Critical)->settings().low);
  EXPECT_FALSE(eng.find(AlarmKind::RopeOverload, AlarmLevel::Critical)->settings().low);
  const AlarmSettings& pred = eng.find(AlarmKind::PredictedSlack, AlarmLevel::Warning)->settings();
  EXPECT_DOUBLE_EQ(pred.off_delay, 0.7);
  EXPECT_DOUBLE_EQ(pred.on_delay, 0.0);
  EXPECT_FALSE(pred.latch);
  EXPECT_DOUBLE_EQ(eng.find(AlarmKind::InputStale, AlarmLevel::Warning)->settings().off_delay, 0.0);
}

// A re-announce request (alarm_ack_t ACTION_REANNOUNCE): one EVENT_REANNOUNCE
// per alarm that has a state to tell -- active, shelved, or raised and
// cleared since the start -- and none for alarms never touched; nothing
// changes (the periodic re-announce keeps its schedule, a later raise is
// still a RAISE).
TEST(AlarmEngine, ReannounceRequestReportsEveryAlarmWithAStateAndChangesNothing) {
  AlarmConfig cfg;
  cfg.reannounce = 100.0;
  AlarmEngine eng(cfg);
  AlarmEvents ev;
  EXPECT_EQ(eng.reannounce(0.0, std::nullopt, AlarmLevel::None, ev), 0) << "nothing has a state yet";
  EXPECT_TRUE(ev.empty());
  eng.setInputStale(1.0, true, ev);                                            // active WARNING
  eng.shelve(1.0, AlarmKind::GuideRope, AlarmLevel::Critical, 600.0, ev);      // shelved, inactive
  eng.setDuplicatePublisher(1.0, true, 7.0, ev);
  eng.setDuplicatePublisher(2.0, false, 0.0, ev);                              // raised and cleared
  ev.clear();
  EXPECT_EQ(eng.reannounce(3.0, std::nullopt, AlarmLevel::None, ev), 3);
  ASSERT_EQ(ev.size(), 3u);
  for (const AlarmEvent& e : ev) {
    EXPECT_EQ(e.type, AlarmEventType::Reannounce);
    EXPECT_DOUBLE_EQ(e.t, 3.0);
    if (e.kind == AlarmKind::InputStale) {
      EXPECT_TRUE(e.active);
      EXPECT_FALSE(e.acked);
    } else if (e.kind == AlarmKind::GuideRope) {
      EXPECT_EQ(e.level, AlarmLevel::Critical);
      EXPECT_TRUE(e.shelved);
      EXPECT_FALSE(e.active);
      EXPECT_NEAR(e.shelved_for, 598.0, 1e-9);
    } else {
      EXPECT_EQ(e.kind, AlarmKind::DuplicatePublisher);
      EXPECT_FALSE(e.active);
    }
  }
  // Filtered by kind; the states did not change.
  ev.clear();
  EXPECT_EQ(eng.reannounce(3.5, AlarmKind::InputStale, AlarmLevel::None, ev), 1);
  EXPECT_EQ(eng.activeCount(), 1);
  EXPECT_EQ(eng.unackedCount(), 1);
  EXPECT_EQ(eng.shelvedCount(), 1);
  // The periodic re-announce still runs from the RAISE at 1 s (not from the requests).
  ev.clear();
  eng.poll(100.5, ev);
  EXPECT_EQ(count(ev, AlarmEventType::Reannounce), 0);
  eng.poll(101.0, ev);
  EXPECT_EQ(count(ev, AlarmEventType::Reannounce), 1);
  // A clear after the request is still announced as a CLEAR.
  ev.clear();
  eng.setInputStale(102.0, false, ev);
  EXPECT_EQ(count(ev, AlarmEventType::Clear), 1);
}
