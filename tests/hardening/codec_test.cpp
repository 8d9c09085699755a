// hoist_msgs_codec (msgs/codec/lcm_codec_gen.py): the generated checked
// decoders, JSON conversion and schemas, for every type in msgs/ and for the
// exact hostile payloads that once crashed the programs.
#include <gtest/gtest.h>

#include <set>

#include "attack_bytes.hpp"
#include "hoist/msg/codec.hpp"

using namespace hoist;
using namespace hoist::msg;
namespace atk = hoist::test::attack;
using Bytes = std::vector<std::uint8_t>;

namespace {

template <class M>
Bytes encode(const M& m) {
  Bytes b(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  return b;
}

health_t sampleHealth() {
  health_t h{};
  h.utime = 1700000000000001;
  h.instance_id = -42;
  h.clock = "wall";
  h.rate = 1000;
  h.n_reasons = 2;
  h.reject_reason = {"decode", "v_limit"};
  h.rejected = {7, 9};
  h.degraded = 1;
  return h;
}

guide_shape_t sampleShape(int n) {
  guide_shape_t g{};
  g.utime = 5;
  g.n = n;
  for (int i = 0; i < n; ++i) {
    g.x.push_back(i * 0.5);
    g.y1.push_back(-i * 1e-3);
    g.y2.push_back(i * 2e-3);
  }
  return g;
}

alarm_t sampleAlarm() {
  alarm_t a{};
  a.kind = "CAGE_POS_Y";
  a.level = alarm_t::LEVEL_CRITICAL;
  a.event_type = alarm_t::EVENT_RAISE;
  a.active = 1;
  a.message = "cage +y excursion";
  a.user = "";
  return a;
}

alarm_ack_t sampleAck() {
  alarm_ack_t k{};
  k.utime = 123;
  k.kind = "*";
  k.level = 0;
  k.action = alarm_ack_t::ACTION_SHELVE;
  k.shelve_duration = 60;
  k.user = "operator";
  return k;
}

forecast_scenario_t sampleScenario(const char* name, int points) {
  forecast_scenario_t s{};
  s.name = name;
  s.status = forecast_scenario_t::STATUS_OK;
  s.horizon = 20.0;
  s.t_reached = 20.0;
  s.min_clearance = 0.031;
  s.t_min_clearance = 4.25;
  s.t_warning = 3.5;
  s.t_critical = -1.0;
  s.peak_y_c = 0.012;
  s.peak_theta = 1.5e-3;
  for (int k = 0; k < 4; ++k) s.peak_lambdas[k] = 100.0 * (k + 1);
  s.lambda0_min = 2.5e3;
  s.lambda0_max = 1.9e4;
  s.num_points = static_cast<std::int16_t>(points);
  for (int i = 0; i < points; ++i) {
    s.series_t.push_back(20.0 * (i + 1) / points);
    s.series_min_clearance.push_back(0.05 - 1e-3 * i);
    s.series_lambda0_min.push_back(8e3 - i);
    s.series_lambda0_max.push_back(9e3 + i);
  }
  return s;
}

forecast_t sampleForecast() {
  forecast_t f{};
  f.utime = 1700000000000002;
  f.seq = 17;
  f.instance_id = 99;
  f.t_start = 20.0;
  f.l = 150.0;
  f.v = 10.0;
  f.a = 0.0;
  f.plan_seq = -1;
  f.compute_time = 0.004;
  f.num_scenarios = 2;
  f.scenarios = {sampleScenario("estop", 3), sampleScenario("continue", 50)};
  return f;
}

template <class T>
T sample() {
  if constexpr (std::is_same_v<T, health_t>) return sampleHealth();
  else if constexpr (std::is_same_v<T, guide_shape_t>) return sampleShape(3);
  else if constexpr (std::is_same_v<T, alarm_t>) return sampleAlarm();
  else if constexpr (std::is_same_v<T, alarm_ack_t>) return sampleAck();
  else if constexpr (std::is_same_v<T, forecast_scenario_t>) return sampleScenario("estop", 2);
  else if constexpr (std::is_same_v<T, forecast_t>) return sampleForecast();
  else {
    T m{};
    return m;
  }
}

// Every type: fingerprint as lcm-gen's, round trip bytes -> JSON -> bytes,
// every truncation and every trailing byte rejected, schema consistent.
template <class T>
void checkType(const char* short_name) {
  SCOPED_TRACE(short_name);
  const TypeInfo* info = findByName(short_name);
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(info->fingerprint, T::getHash()) << "generator's fingerprint differs from lcm-gen's getHash()";
  const T m = sample<T>();
  const Bytes b = encode(m);
  EXPECT_EQ(findByFingerprint(b.data(), b.size()), info);
  EXPECT_LE(b.size(), info->max_size);
  T d;
  ASSERT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::ok);
  EXPECT_EQ(encode(d), b);
  nlohmann::json j;
  DecodeStatus st{};
  ASSERT_TRUE(info->bytesToJson(b.data(), b.size(), j, st));
  EXPECT_EQ(st, DecodeStatus::ok);
  EXPECT_EQ(j, toJson(m));
  T back;
  std::string err;
  ASSERT_TRUE(fromJson(j, back, err)) << err;
  EXPECT_EQ(encode(back), b);
  // JSON text round trip too (what a dashboard/bridge sends back).
  T back2;
  ASSERT_TRUE(fromJson(nlohmann::json::parse(j.dump()), back2, err)) << err;
  EXPECT_EQ(encode(back2), b);

  for (std::size_t n = 0; n < b.size(); ++n) {
    T t;
    EXPECT_NE(checkedDecode(b.data(), n, t), DecodeStatus::ok) << "prefix of " << n << " bytes";
  }
  Bytes longer = b;
  longer.push_back(0);
  EXPECT_EQ(checkedDecode(longer.data(), longer.size(), d), DecodeStatus::too_large);
  Bytes wrongfp = b;
  wrongfp[3] ^= 0x10;
  EXPECT_EQ(checkedDecode(wrongfp.data(), wrongfp.size(), d), DecodeStatus::bad_fingerprint);

  // Schema: valid JSON, same name, every toJson key required, nothing else.
  const nlohmann::json s = nlohmann::json::parse(jsonSchema<T>());
  EXPECT_EQ(s.at("title"), info->name);
  EXPECT_STREQ(info->schema, jsonSchema<T>());
  std::set<std::string> keys, req, props;
  for (auto it = j.begin(); it != j.end(); ++it) keys.insert(it.key());
  for (const auto& r : s.at("required")) req.insert(r.get<std::string>());
  for (auto it = s.at("properties").begin(); it != s.at("properties").end(); ++it) props.insert(it.key());
  EXPECT_EQ(keys, req);
  EXPECT_EQ(keys, props);
  EXPECT_EQ(s.at("additionalProperties"), false);

  // Strict fromJson: unknown, missing and wrong-typed keys, naming the key.
  auto extra = j;
  extra["bogus_key"] = 1;
  EXPECT_FALSE(fromJson(extra, back, err));
  EXPECT_NE(err.find("bogus_key"), std::string::npos) << err;
  const std::string first = *keys.begin();
  auto missing = j;
  missing.erase(first);
  EXPECT_FALSE(fromJson(missing, back, err));
  EXPECT_NE(err.find(first), std::string::npos) << err;
  auto wrong = j;
  wrong[first] = nlohmann::json::object();
  EXPECT_FALSE(fromJson(wrong, back, err));
  EXPECT_NE(err.find(first), std::string::npos) << err;
  EXPECT_FALSE(fromJson(nlohmann::json::array(), back, err));
}

}  // namespace

TEST(Codec, EveryTypeFingerprintRoundTripTruncationSchema) {
#define HOIST_CHECK_TYPE(T) checkType<T>(#T);
  HOIST_MSG_FOR_EACH_TYPE(HOIST_CHECK_TYPE)
#undef HOIST_CHECK_TYPE
  EXPECT_EQ(allTypes().size(), 12u);  // msgs/*.lcm
  for (const auto& t : allTypes()) EXPECT_EQ(findByName(t.name), &t);
  EXPECT_EQ(findByName("nope_t"), nullptr);
  const std::uint8_t junk[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(findByFingerprint(junk, 8), nullptr);
  EXPECT_EQ(findByFingerprint(junk, 7), nullptr);
}

// The 37-byte alarm_ack_t with a string length of 0 and
// of 0x80000000 (and other impossible lengths) are rejected, not decoded.
TEST(Codec, AlarmAckStringLengthAttacks) {
  for (std::uint32_t len : {0u, 0x80000000u, 0xFFFFFFFFu, 0x7FFFFFFFu, 4097u, 1000u}) {
    const Bytes b = atk::alarmAckStringLen(len);
    ASSERT_EQ(b.size(), 37u);
    alarm_ack_t m;
    const auto st = checkedDecode(b.data(), b.size(), m);
    EXPECT_TRUE(st == DecodeStatus::bad_string || st == DecodeStatus::truncated)
        << "len " << len << ": " << toString(st);
  }
  alarm_ack_t m;
  const Bytes zero = atk::alarmAckStringLen(0);
  EXPECT_EQ(checkedDecode(zero.data(), zero.size(), m), DecodeStatus::bad_string);
  const Bytes neg = atk::alarmAckStringLen(0x80000000u);
  EXPECT_EQ(checkedDecode(neg.data(), neg.size(), m), DecodeStatus::bad_string);
  // Missing NUL, NUL inside, longer than the cap.
  alarm_ack_t k = sampleAck();
  Bytes b = encode(k);
  const std::size_t kind_at = 8 + 8 + 4;  // "*\0"
  b[kind_at + 1] = 'x';
  EXPECT_EQ(checkedDecode(b.data(), b.size(), m), DecodeStatus::bad_string);
  k.user = "abc";
  b = encode(k);
  b[b.size() - 4 * 8 - 3] = 0;  // the user's "b" (known_fa, known_b, calibrate_duration, preload_scale follow it)
  EXPECT_EQ(checkedDecode(b.data(), b.size(), m), DecodeStatus::bad_string);
  k.user = std::string(4097, 'u');
  b = encode(k);
  EXPECT_EQ(checkedDecode(b.data(), b.size(), m), DecodeStatus::bad_string);
  k.user = std::string(4096, 'u');
  b = encode(k);
  EXPECT_EQ(checkedDecode(b.data(), b.size(), m), DecodeStatus::ok);
}

// health_t / guide_shape_t with huge or negative counts: bad_count before any
// allocation; a plausible count without the bytes: truncated.
TEST(Codec, ArrayCountAttacks) {
  health_t h;
  {
    const Bytes ok = atk::healthCount(1);
    ASSERT_EQ(checkedDecode(ok.data(), ok.size(), h), DecodeStatus::ok);
    EXPECT_EQ(h.n_reasons, 1);
  }
  for (std::int32_t n : {-1, INT32_MIN, 65, 1000000, INT32_MAX}) {
    const Bytes b = atk::healthCount(n);
    EXPECT_EQ(checkedDecode(b.data(), b.size(), h), DecodeStatus::bad_count) << n;
  }
  for (std::int32_t n : {2, 64}) {  // the next bytes are not strings, or too few
    const Bytes b = atk::healthCount(n);
    const auto st = checkedDecode(b.data(), b.size(), h);
    EXPECT_TRUE(st == DecodeStatus::truncated || st == DecodeStatus::bad_string) << n << toString(st);
  }
  guide_shape_t g;
  for (std::int32_t n : {-1, INT32_MIN, 100001, 0x10000000, INT32_MAX}) {
    const Bytes b = atk::guideShapeCount(n);
    EXPECT_EQ(checkedDecode(b.data(), b.size(), g), DecodeStatus::bad_count) << n;
  }
  for (std::int32_t n : {1, 2001, 100000}) {
    const Bytes b = atk::guideShapeCount(n);
    EXPECT_EQ(checkedDecode(b.data(), b.size(), g), DecodeStatus::truncated) << n;
  }
  const Bytes zero = atk::guideShapeCount(0);
  EXPECT_EQ(checkedDecode(zero.data(), zero.size(), g), DecodeStatus::ok);
  // The largest shape we accept: 100000 samples (the daemon publishes <= 2001).
  const Bytes big = encode(sampleShape(100000));
  EXPECT_EQ(checkedDecode(big.data(), big.size(), g), DecodeStatus::ok);
  EXPECT_EQ(g.x.size(), 100000u);
  const Bytes too_big = encode(sampleShape(100001));
  EXPECT_EQ(checkedDecode(too_big.data(), too_big.size(), g), DecodeStatus::too_large);
  // A wrong-type payload is a fingerprint mismatch, not decoded as another type.
  EXPECT_EQ(checkedDecode(zero.data(), zero.size(), h), DecodeStatus::bad_fingerprint);
  EXPECT_EQ(checkedDecode(nullptr, 0, h), DecodeStatus::truncated);
}

TEST(Codec, JsonStringsAreValidUtf8) {
  alarm_t a = sampleAlarm();
  a.message = "bad \xff\xfe utf8 \xc3\xa9 \xed\xa0\x80 \x1b[2J";
  const auto j = toJson(a);
  std::string text;
  ASSERT_NO_THROW(text = j.dump());
  EXPECT_NE(text.find("\\u001b[2J"), std::string::npos) << text;
  EXPECT_NE(j.at("message").get<std::string>().find("\xc3\xa9"), std::string::npos);
  EXPECT_EQ(utf8Safe("ok \xc3\xa9"), "ok \xc3\xa9");
  EXPECT_EQ(utf8Safe("\xff"), "\xEF\xBF\xBD");
}

TEST(Codec, TerminalSafeEscapesControlSequences) {
  EXPECT_EQ(terminalSafe("plain text"), "plain text");
  EXPECT_EQ(terminalSafe("\x1b[2J\x1b[H"), "\\x1b[2J\\x1b[H");
  EXPECT_EQ(terminalSafe("a\nb\rc\td\x7f"), "a\\x0ab\\x0dc\\x09d\\x7f");
  EXPECT_EQ(terminalSafe("\xc2\x9b" "31m"), "\\u009b31m");  // C1 CSI
  EXPECT_EQ(terminalSafe("caf\xc3\xa9"), "caf\xc3\xa9");
  // Bidi controls and line separators (issue 33): escaped, other 3-byte
  // characters kept.
  EXPECT_EQ(terminalSafe("a\xe2\x80\xae" "b"), "a\\u202eb");  // RIGHT-TO-LEFT OVERRIDE
  EXPECT_EQ(terminalSafe("\xe2\x81\xa6x\xe2\x81\xa9"), "\\u2066x\\u2069");  // isolates
  EXPECT_EQ(terminalSafe("\xe2\x80\x8f\xe2\x80\xa8"), "\\u200f\\u2028");
  EXPECT_EQ(terminalSafe("\xe2\x82\xac 5"), "\xe2\x82\xac 5");  // the euro sign stays
  EXPECT_EQ(terminalSafe(std::string(300, 'x'), 10), std::string(10, 'x') + "...");
  for (char c : terminalSafe("\x1b\x07\x08\x00\x9b\xff")) EXPECT_GE(static_cast<unsigned char>(c), 0x20);
}

TEST(Codec, FromJsonStrictAlarmAck) {
  const auto ok = nlohmann::json::parse(
      R"({"utime": 1, "kind": "*", "level": 0, "action": 2, "shelve_duration": 60, "user": "op",
          "known_fa": 0, "known_b": 0, "calibrate_duration": 0, "preload_scale": 0})");
  alarm_ack_t k;
  std::string err;
  ASSERT_TRUE(fromJson(ok, k, err)) << err;
  EXPECT_EQ(k.kind, "*");
  EXPECT_EQ(k.action, 2);
  EXPECT_EQ(k.shelve_duration, 60.0);
  auto bad = ok;
  bad["level"] = 300;
  EXPECT_FALSE(fromJson(bad, k, err));
  EXPECT_NE(err.find("'level'"), std::string::npos) << err;
  bad = ok;
  bad["level"] = 1.5;
  EXPECT_FALSE(fromJson(bad, k, err));
  EXPECT_NE(err.find("'level'"), std::string::npos) << err;
  bad = ok;
  bad["action"] = "2";
  EXPECT_FALSE(fromJson(bad, k, err));
  EXPECT_NE(err.find("'action'"), std::string::npos) << err;
  bad = ok;
  bad["user"] = std::string("a\0b", 3);
  EXPECT_FALSE(fromJson(bad, k, err));
  EXPECT_NE(err.find("'user'"), std::string::npos) << err;
  bad = ok;
  bad["user"] = std::string(5000, 'u');
  EXPECT_FALSE(fromJson(bad, k, err));
  bad = ok;
  bad.erase("shelve_duration");
  EXPECT_FALSE(fromJson(bad, k, err));
  EXPECT_NE(err.find("'shelve_duration'"), std::string::npos) << err;
  bad = ok;
  bad["utime"] = 18446744073709551615ull;
  EXPECT_FALSE(fromJson(bad, k, err));
  EXPECT_NE(err.find("'utime'"), std::string::npos) << err;
}

TEST(Codec, FromJsonArrays) {
  auto j = toJson(sampleShape(2));
  guide_shape_t g;
  std::string err;
  ASSERT_TRUE(fromJson(j, g, err)) << err;
  j["x"].push_back(1.0);  // 3 elements but n = 2
  EXPECT_FALSE(fromJson(j, g, err));
  EXPECT_NE(err.find("'x'"), std::string::npos) << err;
  j = toJson(sampleShape(2));
  j["y1"][1] = "no";
  EXPECT_FALSE(fromJson(j, g, err));
  EXPECT_NE(err.find("'y1[1]'"), std::string::npos) << err;
  auto c = toJson(cage_state_t{});
  cage_state_t cs;
  ASSERT_TRUE(fromJson(c, cs, err)) << err;
  c["lambdas"].erase(0);
  EXPECT_FALSE(fromJson(c, cs, err));
  EXPECT_NE(err.find("'lambdas'"), std::string::npos) << err;
  auto h = toJson(sampleHealth());
  h["n_reasons"] = -1;
  health_t hh;
  EXPECT_FALSE(fromJson(h, hh, err));
}

// ---- nested types (forecast_t holds forecast_scenario_t[]) ------

namespace {

// Offsets in sampleForecast()'s encoding.  forecast_t: fp 8, utime, seq,
// instance_id, t_start, l, v, a, plan_seq, compute_time (9 x 8), then
// num_scenarios (int8), then the scenarios WITHOUT fingerprints (lcm-gen's
// _encodeNoHash), then from_estimate (1), Fa, moment (2 x 8).  forecast_scenario_t body: name (4 + len + 1), status (1),
// horizon, t_reached, min_clearance, t_min_clearance, t_warning, t_critical,
// peak_y_c, peak_theta (8 x 8), peak_lambdas (4 x 8), lambda0_min/max (16),
// num_points (int16), then 4 x num_points doubles.
constexpr std::size_t kNumScenariosAt = 8 + 9 * 8;
constexpr std::size_t kFirstScenarioAt = kNumScenariosAt + 1;
std::size_t numPointsAt(std::size_t scenario_at, std::size_t name_len) {
  return scenario_at + 4 + name_len + 1 + 1 + 8 * 8 + 4 * 8 + 16;
}
void put16(Bytes& b, std::size_t at, std::int16_t v) {
  b[at] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(v) >> 8);
  b[at + 1] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(v) & 0xff);
}

}  // namespace

TEST(CodecNested, ForecastRoundTripAndLayout) {
  const forecast_t f = sampleForecast();
  const Bytes b = encode(f);
  // The layout assumed by the attack tests below.
  ASSERT_EQ(b[kNumScenariosAt], 2);
  const std::size_t np = numPointsAt(kFirstScenarioAt, 5);  // "estop"
  ASSERT_EQ(b[np], 0);
  ASSERT_EQ(b[np + 1], 3);
  forecast_t d;
  ASSERT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::ok);
  ASSERT_EQ(d.scenarios.size(), 2u);
  EXPECT_EQ(d.scenarios[1].name, "continue");
  EXPECT_EQ(d.scenarios[1].series_lambda0_max.size(), 50u);
  const auto j = toJson(d);
  EXPECT_EQ(j.at("scenarios").size(), 2u);
  EXPECT_EQ(j.at("scenarios")[0].at("name"), "estop");
  EXPECT_EQ(j.at("scenarios")[1].at("series_min_clearance").size(), 50u);
  EXPECT_EQ(j.at("scenarios")[0].at("peak_lambdas")[3], 400.0);
  EXPECT_EQ(j.at("scenarios")[0].at("t_critical"), -1.0);
  // The largest valid forecast (8 scenarios of 64 points, long names) fits.
  forecast_t big = f;
  big.num_scenarios = forecast_t::MAX_SCENARIOS;
  big.scenarios.assign(forecast_t::MAX_SCENARIOS,
                       sampleScenario(std::string(4096, 'n').c_str(), forecast_scenario_t::MAX_POINTS));
  const Bytes bb = encode(big);
  const TypeInfo* info = findByName("forecast_t");
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(bb.size(), info->max_size);
  EXPECT_EQ(checkedDecode(bb.data(), bb.size(), d), DecodeStatus::ok);
  // One more point in one scenario: bad_count (and the size cap holds).
  big.scenarios[7] = sampleScenario("x", forecast_scenario_t::MAX_POINTS + 1);
  const Bytes over = encode(big);
  EXPECT_NE(checkedDecode(over.data(), over.size(), d), DecodeStatus::ok);
}

TEST(CodecNested, HugeNegativeAndLyingScenarioCounts) {
  const Bytes good = encode(sampleForecast());
  forecast_t d;
  for (int n : {-1, -128, 9, 127}) {  // outside 0..MAX_SCENARIOS (8)
    Bytes b = good;
    b[kNumScenariosAt] = static_cast<std::uint8_t>(static_cast<std::int8_t>(n));
    EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::bad_count) << n;
  }
  for (int n : {3, 8}) {  // plausible, but the bytes are not there
    Bytes b = good;
    b[kNumScenariosAt] = static_cast<std::uint8_t>(n);
    const auto st = checkedDecode(b.data(), b.size(), d);
    EXPECT_TRUE(st == DecodeStatus::truncated || st == DecodeStatus::bad_string) << n << " " << toString(st);
  }
  {  // count x smallest scenario encoding > bytes left: truncated before walking any
    // (the fields after the scenarios -- from_estimate, Fa, moment: 17 bytes -- kept)
    Bytes b(good.begin(), good.begin() + static_cast<long>(kFirstScenarioAt));
    b.insert(b.end(), good.end() - 17, good.end());
    b[kNumScenariosAt] = 1;
    EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::truncated);
    b[kNumScenariosAt] = 0;
    EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::ok);
    EXPECT_TRUE(d.scenarios.empty());
  }
  {  // fewer scenarios than the bytes hold: trailing bytes
    Bytes b = good;
    b[kNumScenariosAt] = 1;
    EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::too_large);
  }
}

TEST(CodecNested, HugeNegativeAndLyingPointCountsInsideAScenario) {
  const Bytes good = encode(sampleForecast());
  const std::size_t np = numPointsAt(kFirstScenarioAt, 5);
  forecast_t d;
  for (std::int16_t n : {std::int16_t(-1), std::int16_t(INT16_MIN), std::int16_t(65), std::int16_t(INT16_MAX)}) {
    Bytes b = good;
    put16(b, np, n);
    EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::bad_count) << n;
  }
  // 64 points claimed, 3 there: the rest of the message is read as points
  // and the second scenario runs out (or bytes are missing).
  Bytes b = good;
  put16(b, np, 64);
  EXPECT_NE(checkedDecode(b.data(), b.size(), d), DecodeStatus::ok);
  // The second scenario's count, past the first scenario.
  const std::size_t second = np + 2 + 4 * 3 * 8;
  const std::size_t np2 = numPointsAt(second, 8);  // "continue"
  ASSERT_EQ(b.size(), good.size());
  ASSERT_EQ(good[np2 + 1], 50);
  for (std::int16_t n : {std::int16_t(-2), std::int16_t(1000)}) {
    Bytes c = good;
    put16(c, np2, n);
    EXPECT_EQ(checkedDecode(c.data(), c.size(), d), DecodeStatus::bad_count) << n;
  }
  Bytes c = good;
  put16(c, np2, 51);
  EXPECT_EQ(checkedDecode(c.data(), c.size(), d), DecodeStatus::truncated);
  // Every truncation of a message with nested values is rejected.
  for (std::size_t n = 0; n < good.size(); ++n)
    EXPECT_NE(checkedDecode(good.data(), n, d), DecodeStatus::ok) << n;
}

TEST(CodecNested, NestedStringAttacks) {
  const Bytes good = encode(sampleForecast());
  forecast_t d;
  for (std::uint32_t len : {0u, 0x80000000u, 0xFFFFFFFFu, 4098u}) {
    Bytes b = good;
    for (int i = 0; i < 4; ++i) b[kFirstScenarioAt + i] = static_cast<std::uint8_t>(len >> (8 * (3 - i)));
    const auto st = checkedDecode(b.data(), b.size(), d);
    EXPECT_TRUE(st == DecodeStatus::bad_string || st == DecodeStatus::truncated) << len << " " << toString(st);
  }
  Bytes b = good;
  b[kFirstScenarioAt + 4 + 5] = 'x';  // "estop" loses its NUL
  EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::bad_string);
  b = good;
  b[kFirstScenarioAt + 4 + 2] = 0;  // NUL inside "estop"
  EXPECT_EQ(checkedDecode(b.data(), b.size(), d), DecodeStatus::bad_string);
}

// Nested values have no fingerprint of their own on the wire: the outer
// fingerprint covers the nested type (lcm-gen adds the nested hash into it).
// A scenario published alone, or a forecast with a stray fingerprint before
// a scenario, is rejected.
TEST(CodecNested, FingerprintsOfNestedTypes) {
  EXPECT_EQ(findByName("forecast_t")->fingerprint, forecast_t::getHash());
  EXPECT_EQ(findByName("forecast_scenario_t")->fingerprint, forecast_scenario_t::getHash());
  const Bytes sc = encode(sampleScenario("estop", 2));
  forecast_t d;
  EXPECT_EQ(checkedDecode(sc.data(), sc.size(), d), DecodeStatus::bad_fingerprint);
  forecast_scenario_t s;
  const Bytes fb = encode(sampleForecast());
  EXPECT_EQ(checkedDecode(fb.data(), fb.size(), s), DecodeStatus::bad_fingerprint);
  // A "nested fingerprint" inserted before the first scenario: the name's
  // length field then reads the fingerprint's first bytes.
  forecast_t one = sampleForecast();
  one.num_scenarios = 1;
  one.scenarios.resize(1);
  Bytes b = encode(one);
  Bytes withfp(b.begin(), b.begin() + static_cast<long>(kFirstScenarioAt));
  withfp.insert(withfp.end(), sc.begin(), sc.begin() + 8);
  withfp.insert(withfp.end(), b.begin() + static_cast<long>(kFirstScenarioAt), b.end());
  EXPECT_NE(checkedDecode(withfp.data(), withfp.size(), d), DecodeStatus::ok);
  // The schema inlines the nested type and gives its fingerprint.
  const auto sch = nlohmann::json::parse(jsonSchema<forecast_t>());
  const auto& item = sch.at("properties").at("scenarios").at("items");
  EXPECT_EQ(item.at("title"), "hoist.forecast_scenario_t");
  EXPECT_EQ(item.at("additionalProperties"), false);
  EXPECT_EQ(item.at("properties").at("num_points").at("maximum"), int(forecast_scenario_t::MAX_POINTS));
  EXPECT_EQ(sch.at("properties").at("scenarios").at("maxItems"), int(forecast_t::MAX_SCENARIOS));
  EXPECT_EQ(sch.at("properties").at("num_scenarios").at("maximum"), int(forecast_t::MAX_SCENARIOS));
  EXPECT_EQ(item.at("x-lcm-constants").at("STATUS_LEFT_SHAFT"), 1);
  std::set<std::string> keys, req;
  const auto sj = toJson(sampleScenario("a", 1));
  for (auto it = sj.begin(); it != sj.end(); ++it) keys.insert(it.key());
  for (const auto& r : item.at("required")) req.insert(r.get<std::string>());
  EXPECT_EQ(keys, req);
}

TEST(CodecNested, FromJsonNestedIsStrictAndNamesThePath) {
  const auto good = toJson(sampleForecast());
  forecast_t f;
  std::string err;
  ASSERT_TRUE(fromJson(good, f, err)) << err;
  EXPECT_EQ(f.scenarios[1].name, "continue");
  auto bad = good;
  bad["scenarios"][1]["name"] = 5;
  EXPECT_FALSE(fromJson(bad, f, err));
  EXPECT_NE(err.find("'scenarios[1]'"), std::string::npos) << err;
  EXPECT_NE(err.find("'name'"), std::string::npos) << err;
  bad = good;
  bad["scenarios"][0].erase("t_critical");
  EXPECT_FALSE(fromJson(bad, f, err));
  EXPECT_NE(err.find("'scenarios[0]'"), std::string::npos) << err;
  EXPECT_NE(err.find("t_critical"), std::string::npos) << err;
  bad = good;
  bad["scenarios"][0]["extra"] = 1;
  EXPECT_FALSE(fromJson(bad, f, err));
  EXPECT_NE(err.find("extra"), std::string::npos) << err;
  bad = good;
  bad["scenarios"][0]["series_t"].push_back(1.0);  // 4 values, num_points 3
  EXPECT_FALSE(fromJson(bad, f, err));
  EXPECT_NE(err.find("series_t"), std::string::npos) << err;
  bad = good;
  bad["scenarios"][0]["num_points"] = 65;  // over MAX_POINTS even with 65 values
  for (int i = 0; i < 62; ++i)
    for (const char* k : {"series_t", "series_min_clearance", "series_lambda0_min", "series_lambda0_max"})
      bad["scenarios"][0][k].push_back(0.0);
  EXPECT_FALSE(fromJson(bad, f, err));
  EXPECT_NE(err.find("at most 64"), std::string::npos) << err;
  bad = good;
  bad["scenarios"].push_back(bad["scenarios"][0]);  // 3 elements, num_scenarios 2
  EXPECT_FALSE(fromJson(bad, f, err));
  EXPECT_NE(err.find("'scenarios'"), std::string::npos) << err;
  bad = good;
  bad["scenarios"][0] = "estop";
  EXPECT_FALSE(fromJson(bad, f, err));
  EXPECT_NE(err.find("'scenarios[0]'"), std::string::npos) << err;
  bad = good;
  bad["scenarios"][0]["peak_lambdas"].erase(0);
  EXPECT_FALSE(fromJson(bad, f, err));
  EXPECT_NE(err.find("peak_lambdas"), std::string::npos) << err;
}
