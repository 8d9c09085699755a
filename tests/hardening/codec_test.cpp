// hoist_msgs_codec (msgs/codec/lcm_codec_gen.py): the generated checked
// decoders, JSON conversion and schemas, for every type in msgs/ and for the
// exact hostile payloads of issue 12 section 1.
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

template <class T>
T sample() {
  if constexpr (std::is_same_v<T, health_t>) return sampleHealth();
  else if constexpr (std::is_same_v<T, guide_shape_t>) return sampleShape(3);
  else if constexpr (std::is_same_v<T, alarm_t>) return sampleAlarm();
  else if constexpr (std::is_same_v<T, alarm_ack_t>) return sampleAck();
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
  EXPECT_EQ(allTypes().size(), 7u);  // msgs/*.lcm
  for (const auto& t : allTypes()) EXPECT_EQ(findByName(t.name), &t);
  EXPECT_EQ(findByName("nope_t"), nullptr);
  const std::uint8_t junk[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(findByFingerprint(junk, 8), nullptr);
  EXPECT_EQ(findByFingerprint(junk, 7), nullptr);
}

// Issue 12 section 1: the 37-byte alarm_ack_t with a string length of 0 and
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
  b[b.size() - 3] = 0;
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
  EXPECT_EQ(terminalSafe(std::string(300, 'x'), 10), std::string(10, 'x') + "...");
  for (char c : terminalSafe("\x1b\x07\x08\x00\x9b\xff")) EXPECT_GE(static_cast<unsigned char>(c), 0x20);
}

TEST(Codec, FromJsonStrictAlarmAck) {
  const auto ok = nlohmann::json::parse(
      R"({"utime": 1, "kind": "*", "level": 0, "action": 2, "shelve_duration": 60, "user": "op"})");
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
