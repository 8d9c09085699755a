// The pure parts of hoist-twind's LCM shell (hoist/service/lcm/messages.hpp):
// output -> cage_state_t mapping, alarm text, operator-command validation,
// literal channel names for LCM's regex subscribe.
#include <gtest/gtest.h>

#include <tuple>

#include <cmath>
#include <cstring>
#include <regex>

#include "hoist/service/lcm/messages.hpp"

using namespace hoist;
using namespace hoist::service;

TEST(Messages, CageMappingCopiesEveryField) {
  CageOutput o;
  o.t = 1.5;
  o.kin = {120.0, 2.0, 0.5};
  o.x_c = 1e-3;
  o.y_c = 2e-3;
  o.theta = 3e-4;
  o.lambda = {8848.0, -31.0, 31.0, -30.0, 30.0};
  o.clearance = computeClearance(o.y_c, o.theta, 8.0, 0.004, AlarmConfig{});
  o.alarm_level = AlarmLevel::Warning;
  o.degraded = true;
  o.input_seq = 42;
  o.rope_slack_threshold = 4424.0;
  o.rope_overload_threshold = 13272.0;
  hoist::cage_state_t m{};
  toCageMessage(o, m);
  EXPECT_EQ(m.input_seq, 42);
  EXPECT_EQ(m.t, 1.5);
  EXPECT_EQ(m.l, 120.0);
  EXPECT_EQ(m.v, 2.0);
  EXPECT_EQ(m.a, 0.5);
  EXPECT_EQ(m.x_c, 1e-3);
  EXPECT_EQ(m.y_c, 2e-3);
  EXPECT_EQ(m.theta, 3e-4);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(m.lambdas[i], o.lambda[static_cast<std::size_t>(i)]);
  EXPECT_EQ(m.y_top, o.clearance.y_top);
  EXPECT_EQ(m.y_bottom, o.clearance.y_bottom);
  EXPECT_EQ(m.guide_deflection, 0.004);
  EXPECT_EQ(m.clearance_pos_y, o.clearance.clearance_pos);
  EXPECT_EQ(m.clearance_neg_y, o.clearance.clearance_neg);
  EXPECT_EQ(m.clearance_guide, o.clearance.clearance_guide);
  EXPECT_EQ(m.min_clearance, o.clearance.min_clearance);
  EXPECT_EQ(m.alarm_level, 1);
  EXPECT_TRUE(m.degraded);
  EXPECT_EQ(m.rope_slack_threshold, 4424.0);  // appended for the rope-force alarms
  EXPECT_EQ(m.rope_overload_threshold, 13272.0);
}

TEST(Messages, AnUnobservedLoadIsPublishedWithANegativeSigma) {
  // estimate_t.lcm: "A sigma < 0 means not observed".  Without a rope load
  // cell the filter still carries Fa's prior sigma (5000 N): not published.
  LoadEstimate e;
  e.Fa = 1000.0;
  e.sigma_Fa = 5000.0;
  e.moment = 150.0;
  e.sigma_moment = 3.0;
  e.b = 0.15;
  e.sigma_b = 0.01;
  e.fa_observed = false;
  e.moment_observed = true;
  hoist::estimate_t m{};
  const EstimateGate gate(AlarmConfig{}, 2.0);
  toEstimateMessage(e, EstimatorCounters{}, 1.0, 0.0, -1.0, gate, 0.0, false, m);
  EXPECT_EQ(m.Fa, 1000.0);
  EXPECT_LT(m.sigma_Fa, 0.0);
  EXPECT_FALSE(m.fa_observed);
  EXPECT_EQ(m.sigma_moment, 3.0);
  EXPECT_LT(m.sigma_b, 0.0) << "b needs both sensors";
  // Observed: the filter's sigma as it is; and M unobserved likewise.
  e.fa_observed = true;
  e.moment_observed = false;
  toEstimateMessage(e, EstimatorCounters{}, 1.0, 0.0, 0.0, gate, 0.0, false, m);
  EXPECT_EQ(m.sigma_Fa, 5000.0);
  EXPECT_LT(m.sigma_moment, 0.0);
  EXPECT_LT(m.sigma_b, 0.0);
  e.moment_observed = true;
  toEstimateMessage(e, EstimatorCounters{}, 1.0, 0.0, 0.0, gate, 0.0, false, m);
  EXPECT_EQ(m.sigma_b, 0.01);
}

TEST(Messages, ModelMismatchTextNamesItsTestAndIsCutAtAWord) {
  AlarmEvent e;
  e.kind = AlarmKind::ModelMismatch;
  e.level = AlarmLevel::Warning;
  e.type = AlarmEventType::Raise;
  e.value = 1464.0;
  e.threshold = 1455.0;
  e.active = true;
  e.from_estimate = true;
  e.latched = true;
  e.shelved = true;
  AlarmTextContext ctx;
  char buf[256];
  ctx.mismatch_test = "nis";
  describeAlarm(e, ctx, buf, sizeof buf);
  std::string t(buf);
  EXPECT_NE(t.find("NIS 1464 exceeds its bound 1455"), std::string::npos) << t;
  EXPECT_EQ(t.find("drift"), std::string::npos) << t;
  ctx.mismatch_test = "drift";
  e.value = 4.2;
  e.threshold = 3.5;
  describeAlarm(e, ctx, buf, sizeof buf);
  t = buf;
  EXPECT_NE(t.find("load drifted 4.2 sigma during the trip (bound 3.5)"), std::string::npos) << t;
  EXPECT_EQ(t.find("NIS"), std::string::npos) << t;
  // The trip-end preload test: its own sentence after the kind (it fits
  // alarm_t.message whole).
  ctx.mismatch_test = "preload";
  ctx.preload_verdict_text =
      "whole-trip fit: preload x0.59 +- 0.03, 14.3 sigma from the twin's x1 (bound 4): shaft softer, moment reads high "
      "(fit: M = 894 +- 34 N m); adopt (hoist-alarm-ack --adopt-preload) or re-tension";
  e.shelved = e.latched = e.from_estimate = false;
  describeAlarm(e, ctx, buf, sizeof buf);
  t = buf;
  EXPECT_EQ(t, std::string("MODEL_MISMATCH WARNING raised: ") + ctx.preload_verdict_text + " [unacknowledged]") << t;
  ctx.mismatch_test = "drift";
  e.shelved = e.latched = e.from_estimate = true;
  // Too long for the buffer: cut at a word, marked "...".
  char small[80];
  describeAlarm(e, ctx, small, sizeof small);
  t = small;
  ASSERT_LE(t.size(), sizeof small - 1);
  ASSERT_GE(t.size(), 3u);
  EXPECT_EQ(t.substr(t.size() - 3), "...") << t;
  const std::string kept = t.substr(0, t.size() - 3);
  EXPECT_NE(kept.back(), ' ') << t;
  std::string whole(1024, '\0');
  describeAlarm(e, ctx, whole.data(), whole.size());
  whole.resize(std::strlen(whole.c_str()));
  ASSERT_GT(whole.size(), kept.size());
  EXPECT_EQ(whole.compare(0, kept.size(), kept), 0) << "a prefix of the whole text";
  EXPECT_EQ(whole[kept.size()], ' ') << "cut between words, not in one: " << t;
}

TEST(Messages, RopeForceAlarmTextStatesForceThresholdAndStaticForce) {
  AlarmConfig cfg;
  AlarmTextContext ctx;
  ctx.alarms = &cfg;
  AlarmEvent e;
  e.kind = AlarmKind::RopeSlack;
  e.level = AlarmLevel::Critical;
  e.type = AlarmEventType::Raise;
  e.active = true;
  e.value = 2400.0;
  e.threshold = 4424.0;  // 0.5 x 8848 N
  char buf[512];
  describeAlarm(e, ctx, buf, sizeof buf);
  std::string s(buf);
  EXPECT_NE(s.find("ROPE_SLACK CRITICAL raised"), std::string::npos) << s;
  EXPECT_NE(s.find("lambda_0 2400 N at or below threshold 4424 N (0.5 x the static rope force 8848 N)"),
            std::string::npos) << s;
  e.kind = AlarmKind::RopeOverload;
  e.value = 15000.0;
  e.threshold = 13272.0;
  describeAlarm(e, ctx, buf, sizeof buf);
  s = buf;
  EXPECT_NE(s.find("ROPE_OVERLOAD CRITICAL raised"), std::string::npos) << s;
  EXPECT_NE(s.find("15000 N at or above threshold 13272 N (1.5 x the static rope force 8848 N)"), std::string::npos)
      << s;
}

TEST(Messages, AlarmTextNamesWhatTheOperatorNeeds) {
  AlarmConfig cfg;
  AlarmTextContext ctx;
  ctx.alarms = &cfg;
  ctx.range = {0.05, 383.95};
  char buf[256];
  AlarmEvent e;
  e.kind = AlarmKind::ModelDomain;
  e.level = AlarmLevel::Critical;
  e.type = AlarmEventType::Raise;
  e.value = 384.2;
  e.threshold = 383.95;
  e.active = true;
  describeAlarm(e, ctx, buf, sizeof buf);
  EXPECT_NE(std::string(buf).find("MODEL_DOMAIN CRITICAL raised: rope length 384.200 m outside the model's valid "
                                  "range [0.050, 383.950] m (limit 383.950 m)"),
            std::string::npos)
      << buf;
  // A shelve clamped to max_shelve says so.
  e = AlarmEvent{};
  e.kind = AlarmKind::GuideRope;
  e.type = AlarmEventType::Shelve;
  e.shelved = true;
  e.shelved_for = 3600.0;
  ctx.requested_shelve = 99999.0;
  describeAlarm(e, ctx, buf, sizeof buf);
  EXPECT_NE(std::string(buf).find("shelved for 3600 s (requested 99999 s, clamped to max_shelve = 3600 s)"),
            std::string::npos)
      << buf;
  ctx.requested_shelve = 600.0;
  e.shelved_for = 600.0;
  describeAlarm(e, ctx, buf, sizeof buf);
  EXPECT_EQ(std::string(buf).find("clamped"), std::string::npos) << buf;
  // An implausible state names the quantity and the bound.
  e = AlarmEvent{};
  e.kind = AlarmKind::ModelFault;
  e.level = AlarmLevel::Critical;
  e.value = -1e159;
  e.threshold = 3.0;
  ctx.fault_what = "y_c";
  describeAlarm(e, ctx, buf, sizeof buf);
  EXPECT_NE(std::string(buf).find("y_c = -1e+159 beyond the plausibility bound 3"), std::string::npos) << buf;
  // Truncation keeps the terminator, and cuts at a word ("...").
  char small[16];
  describeAlarm(e, ctx, small, sizeof small);
  EXPECT_LE(std::strlen(small), 15u);
  EXPECT_EQ(std::string(small).substr(std::strlen(small) - 3), "...") << small;
}

TEST(Messages, AckValidation) {
  hoist::alarm_ack_t a{};
  a.kind = "*";
  a.level = 0;
  a.action = hoist::alarm_ack_t::ACTION_SHELVE;
  a.shelve_duration = 600.0;
  const char* why = "";
  auto c = validateAck(a, why);
  ASSERT_TRUE(c);
  EXPECT_FALSE(c->kind);
  EXPECT_EQ(c->action, AlarmAction::Shelve);
  EXPECT_EQ(c->shelve_duration, 600.0);
  a.kind = "MODEL_DOMAIN";
  c = validateAck(a, why);
  ASSERT_TRUE(c);
  EXPECT_EQ(*c->kind, AlarmKind::ModelDomain);
  for (auto bad : {std::string("NOPE"), std::string("cage_pos_y")}) {
    a.kind = bad;
    EXPECT_FALSE(validateAck(a, why));
    EXPECT_STREQ(why, "unknown alarm kind");
  }
  a.kind = "";
  a.level = 3;
  EXPECT_FALSE(validateAck(a, why));
  a.level = 2;
  a.action = 9;
  EXPECT_FALSE(validateAck(a, why));
  a.action = hoist::alarm_ack_t::ACTION_SHELVE;
  for (double d : {0.0, -1.0, std::nan(""), static_cast<double>(INFINITY)}) {
    a.shelve_duration = d;
    EXPECT_FALSE(validateAck(a, why)) << d;
  }
}

TEST(Messages, CalibrationCommandIsValidated) {
  hoist::alarm_ack_t a{};
  a.action = hoist::alarm_ack_t::ACTION_CALIBRATE;
  a.known_fa = 0.0;  // the empty conveyance
  a.known_b = 0.0;
  a.calibrate_duration = 60.0;
  const char* why = "";
  auto c = validateAck(a, why);
  ASSERT_TRUE(c) << why;
  EXPECT_EQ(c->action, AlarmAction::Calibrate);
  EXPECT_EQ(c->calibrate_duration, 60.0);
  a.known_fa = 1500.0;
  a.known_b = -0.7;
  c = validateAck(a, why);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->known_fa, 1500.0);
  EXPECT_EQ(c->known_b, -0.7);
  for (const auto& [fa, b, s] : {std::tuple{-1.0, 0.0, 60.0}, std::tuple{std::nan(""), 0.0, 60.0},
                                 std::tuple{2e7, 0.0, 60.0}, std::tuple{100.0, 1e3, 60.0},
                                 std::tuple{100.0, 0.0, 0.0}, std::tuple{100.0, 0.0, 601.0},
                                 std::tuple{100.0, 0.0, static_cast<double>(INFINITY)}}) {
    a.known_fa = fa;
    a.known_b = b;
    a.calibrate_duration = s;
    EXPECT_FALSE(validateAck(a, why)) << fa << " " << b << " " << s;
    EXPECT_NE(std::string(why).find("calibrate needs"), std::string::npos) << why;
  }
  // A client without the fields (the 5-argument rule) cannot calibrate.
  hoist::contract::AlarmCommand out;
  EXPECT_EQ(hoist::contract::validateAlarmCommand("", 0, 5, 0.0, out), hoist::contract::CommandError::BadCalibration);
}

TEST(Messages, PreloadAdoptionIsValidated) {
  hoist::alarm_ack_t a{};
  a.action = hoist::alarm_ack_t::ACTION_ADOPT_PRELOAD;
  a.kind = "GUIDE_ROPE";  // ignored, as for the calibration
  const char* why = "";
  for (const double s : {0.3, 0.82, 1.0, 1.6}) {
    a.preload_scale = s;
    const auto c = validateAck(a, why);
    ASSERT_TRUE(c) << s << ": " << why;
    EXPECT_EQ(c->action, AlarmAction::AdoptPreload);
    EXPECT_EQ(c->preload_scale, s);
    EXPECT_FALSE(c->kind.has_value());
  }
  for (const double s : {0.0, 0.29, 1.61, -1.0, std::nan(""), static_cast<double>(INFINITY)}) {
    a.preload_scale = s;
    EXPECT_FALSE(validateAck(a, why)) << s;
    EXPECT_NE(std::string(why).find("preload_scale in [0.3, 1.6]"), std::string::npos) << why;
  }
  // A client without the field (the 8- and 5-argument rules) cannot adopt.
  hoist::contract::AlarmCommand out;
  EXPECT_EQ(hoist::contract::validateAlarmCommand("", 0, 6, 0.0, 0.0, 0.0, 0.0, out),
            hoist::contract::CommandError::BadPreload);
  EXPECT_EQ(hoist::contract::validateAlarmCommand("", 0, 6, 0.0, out), hoist::contract::CommandError::BadPreload);
  EXPECT_EQ(hoist::contract::validateAlarmCommand("", 0, 7, 0.0, out), hoist::contract::CommandError::BadAction);
}

TEST(Messages, OneOperatorNameRuleForEveryFrontEnd) {
  using hoist::contract::operatorNameProblem;
  EXPECT_EQ(operatorNameProblem("alice"), nullptr);
  EXPECT_EQ(operatorNameProblem(std::string(64, 'a')), nullptr);
  EXPECT_EQ(operatorNameProblem("Zo\xc3\xab"), nullptr) << "UTF-8 letters are names";
  EXPECT_STREQ(operatorNameProblem(""), "user must have 1..64 characters");
  EXPECT_STREQ(operatorNameProblem(std::string(65, 'a')), "user must have 1..64 characters");
  for (const char* bad : {"op\x1b[2J", "op\x7f", "op\xc2\x9b", "a\nb"})
    EXPECT_STREQ(operatorNameProblem(bad), "user may not contain control characters") << bad;
}

TEST(Messages, SensorFaultTextNamesTheSensorAndWhy) {
  AlarmEvent e;
  e.kind = AlarmKind::SensorFault;
  e.level = AlarmLevel::Warning;
  e.type = AlarmEventType::Raise;
  e.value = 2.003;
  e.threshold = 0.5;
  e.active = true;
  AlarmTextContext ctx;
  ctx.sensor = SensorId::CageImu;
  ctx.sensor_reason = SensorFaultReason::ClockOffset;
  char buf[512];
  describeAlarm(e, ctx, buf, sizeof buf);
  EXPECT_NE(std::string(buf).find("SENSOR_FAULT WARNING raised: HOIST_CAGE_IMU: its clock is +2.003 s from the "
                                  "daemon's (sensors.max_clock_offset = 0.5 s)"), std::string::npos) << buf;
  ctx.sensor = SensorId::RopeLoad;
  ctx.sensor_reason = SensorFaultReason::TimeBackwards;
  describeAlarm(e, ctx, buf, sizeof buf);
  EXPECT_NE(std::string(buf).find("HOIST_ROPE_LOAD: a sample's utime went backwards"), std::string::npos) << buf;
  ctx.sensor = SensorId::Estimate;
  ctx.sensor_reason = SensorFaultReason::Implausible;
  e.value = 10.0;
  e.threshold = 1.2;
  describeAlarm(e, ctx, buf, sizeof buf);
  EXPECT_NE(std::string(buf).find("the load estimate is implausible (10 beyond the physical bound 1.2)"),
            std::string::npos) << buf;
  e.type = AlarmEventType::Clear;
  e.active = false;
  describeAlarm(e, ctx, buf, sizeof buf);
  EXPECT_NE(std::string(buf).find("SENSOR_FAULT WARNING cleared"), std::string::npos) << buf;
}

TEST(Messages, PrintableAndRegexEscape) {
  EXPECT_EQ(printable("\x1b[31mevil\x1b[0m"), "?[31mevil?[0m");
  EXPECT_EQ(printable(std::string(100, 'x'), 64), std::string(64, 'x') + "...");
  // LCM subscribes to "^<name>$" as a regular expression (GRegex, PCRE).
  const std::string name = "mine.1/HOIST_WINDER";
  const std::regex re("^" + regexEscape(name) + "$");
  EXPECT_TRUE(std::regex_match(name, re));
  EXPECT_FALSE(std::regex_match(std::string("mineX1/HOIST_WINDER"), re));
  EXPECT_FALSE(std::regex_match(std::string("mine_1/HOIST_WINDER"), re));
  EXPECT_EQ(regexEscape("a-b.c/d_e"), "a\\-b\\.c\\/d_e");
}
