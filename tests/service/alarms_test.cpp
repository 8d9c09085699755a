// Clearance alarm logic: thresholds, deadband, on/off delays, latching,
// acknowledgement, shelving, re-announcement (service/alarms.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "hoist/service/alarms.hpp"

using namespace hoist::svc;

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
  // Acknowledge all CAGE_POS_Y alarms.
  EXPECT_EQ(eng.acknowledge(0.4, AlarmKind::CagePosY, AlarmLevel::None, ev), 1);
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

TEST(AlarmNames, RoundTrip) {
  for (int i = 0; i < kAlarmKinds; ++i) {
    const auto k = static_cast<AlarmKind>(i);
    EXPECT_EQ(parseAlarmKind(toString(k)), k);
  }
  EXPECT_FALSE(parseAlarmKind("NOPE"));
}
