// hoist-dash's protocol hub, without network or LCM: Foxglove protocol
// messages in and out of a recording client, min/max decimation, command
// validation, the static-file lookup's traversal checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <set>
#include <sstream>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/msg/names.hpp"
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include "attack_bytes.hpp"
#include "hub.hpp"
#include "static_files.hpp"
#include "server.hpp"
#include "credential.hpp"

namespace hoist::dash {
namespace {

struct RecClient : Client {
  std::vector<Json> text;
  std::vector<std::string> data;
  void sendText(std::shared_ptr<const std::string> f) override { text.push_back(Json::parse(*f)); }
  void sendData(std::shared_ptr<const std::string> f) override { data.push_back(*f); }
  const Json* lastStatus() const {
    for (auto it = text.rbegin(); it != text.rend(); ++it)
      if ((*it)["op"] == "status") return &*it;
    return nullptr;
  }
};

template <class T>
std::vector<std::uint8_t> encode(const T& m) {
  std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_GE(m.encode(b.data(), 0, static_cast<int>(b.size())), 0);
  return b;
}

struct Published {
  std::string channel;
  std::vector<std::uint8_t> bytes;
};

class HubTest : public ::testing::Test {
 protected:
  Hub make(bool read_only, std::vector<std::string> prefixes = {""}) {
    Hub::Options o;
    o.read_only = read_only;
    o.prefixes = std::move(prefixes);
    o.discover = o.prefixes.empty();
    return Hub(
        o, [this](const std::string& ch, const std::vector<std::uint8_t>& b) {
          pub.push_back({ch, b});
          return true;
        },
        [] { return std::uint64_t{1'700'000'000'000'000'000ULL}; });
  }
  std::uint32_t channelId(const RecClient& c, const std::string& topic) {
    for (const auto& m : c.text)
      if (m["op"] == "advertise")
        for (const auto& ch : m["channels"])
          if (ch["topic"] == topic) return ch["id"].get<std::uint32_t>();
    ADD_FAILURE() << "no channel " << topic;
    return 0;
  }
  std::vector<Published> pub;
};

TEST_F(HubTest, ServerInfoThenAdvertiseOfEveryHoistChannelWithJsonSchema) {
  Hub hub = make(false, {"north/"});
  RecClient c;
  hub.addClient(c);
  ASSERT_GE(c.text.size(), 2u);
  EXPECT_EQ(c.text[0]["op"], "serverInfo");
  EXPECT_EQ(c.text[0]["capabilities"], Json::array({"clientPublish"}));
  EXPECT_EQ(c.text[1]["op"], "advertise");
  std::vector<std::string> topics;
  for (const auto& ch : c.text[1]["channels"]) {
    topics.push_back(ch["topic"]);
    EXPECT_EQ(ch["encoding"], "json");
    EXPECT_EQ(ch["schemaEncoding"], "jsonschema");
    const Json schema = Json::parse(ch["schema"].get<std::string>());
    EXPECT_EQ(schema["type"], "object") << ch["topic"];
  }
  for (const char* t : {"north/HOIST_WINDER", "north/HOIST_CAGE", "north/HOIST_GUIDE_SHAPE", "north/HOIST_ALARM",
                        "north/HOIST_ALARM_ACK", "north/HOIST_HEALTH", "north/HOIST_CAGE/decimated",
                        "north/HOIST_ESTIMATE", "north/HOIST_ESTIMATE/decimated", "north/HOIST_FORECAST",
                        "north/HOIST_TRIP_PLAN"})
    EXPECT_NE(std::find(topics.begin(), topics.end(), t), topics.end()) << t;
  // The sensors' raw inputs are not relayed (the estimate made from them is).
  for (const char* t : {"north/HOIST_CAGE_IMU", "north/HOIST_ROPE_LOAD"})
    EXPECT_EQ(std::find(topics.begin(), topics.end(), t), topics.end()) << t;
  // The suffixes come from msgs/*.lcm's @channel (hoist/msg/names.hpp).
  EXPECT_EQ(channelSuffixOfType("hoist.trip_plan_t"), "HOIST_TRIP_PLAN");
  EXPECT_EQ(channelSuffixOfType("hoist.cage_imu_t"), "");
  EXPECT_EQ(hoistSuffixOf("north/HOIST_ALARM_ACK"), "HOIST_ALARM_ACK");  // the longest match
  EXPECT_EQ(hoistSuffixOf("north/HOIST_ROPE_LOAD"), "");
}

TEST_F(HubTest, SubscribeDeliversMessageDataWithTheClientsIdAndUnsubscribeStops) {
  Hub hub = make(false);
  RecClient c;
  hub.addClient(c);
  const auto id = channelId(c, "HOIST_CAGE");
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 42}, {"channelId", id}}}}}.dump());
  cage_state_t m{};
  m.utime = 123456789;
  m.l = 123.25;
  m.y_c = -0.0042;
  m.lambdas[0] = 8000.5;
  const auto bytes = encode(m);
  hub.onLcm("HOIST_CAGE", bytes.data(), bytes.size());
  ASSERT_EQ(c.data.size(), 1u);
  const std::string& f = c.data[0];
  ASSERT_GT(f.size(), 13u);
  EXPECT_EQ(static_cast<std::uint8_t>(f[0]), 0x01);
  std::uint32_t sub = 0;
  std::memcpy(&sub, f.data() + 1, 4);  // little-endian host
  EXPECT_EQ(sub, 42u);
  const Json j = Json::parse(f.substr(13));
  EXPECT_EQ(j["utime"], 123456789);
  EXPECT_DOUBLE_EQ(j["l"].get<double>(), 123.25);
  EXPECT_DOUBLE_EQ(j["y_c"].get<double>(), -0.0042);
  EXPECT_DOUBLE_EQ(j["lambdas"][0].get<double>(), 8000.5);

  hub.onClientText(c, Json{{"op", "unsubscribe"}, {"subscriptionIds", {42}}}.dump());
  hub.onLcm("HOIST_CAGE", bytes.data(), bytes.size());
  EXPECT_EQ(c.data.size(), 1u);
}

TEST_F(HubTest, GarbageAndWrongTypesFromLcmAreCountedNotForwarded) {
  Hub hub = make(false);
  RecClient c;
  hub.addClient(c);
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", channelId(c, "HOIST_CAGE")}}}}}.dump());
  const std::vector<std::uint8_t> junk{1, 2, 3};
  hub.onLcm("HOIST_CAGE", junk.data(), junk.size());
  health_t h{};
  const auto hb = encode(h);
  hub.onLcm("HOIST_CAGE", hb.data(), hb.size());  // a health_t on the cage channel
  cage_state_t m{};
  auto cb = encode(m);
  cb.resize(cb.size() - 10);  // truncated
  hub.onLcm("HOIST_CAGE", cb.data(), cb.size());
  EXPECT_TRUE(c.data.empty());
  EXPECT_EQ(hub.counter("lcm_rejected_unknown_type"), 1u);
  EXPECT_EQ(hub.counter("lcm_rejected_wrong_type"), 1u);
  EXPECT_EQ(hub.counter("lcm_decoded"), 0u);
  std::uint64_t decode_fail = 0;
  const Json counters = hub.stats()["counters"];
  for (const auto& [k, v] : counters.items())
    if (k.rfind("lcm_rejected_decode_", 0) == 0) decode_fail += v.get<std::uint64_t>();
  EXPECT_EQ(decode_fail, 1u);
}

// Hostile bytes: the exact attack bytes (string lengths 0 and 0x80000000,
// huge and negative array counts) on the channels hoist-dash decodes are
// counted as decode rejections before anything is allocated from them;
// nothing reaches a client, nothing throws.
TEST_F(HubTest, Issue12AttackBytesAreCountedNotForwarded) {
  namespace atk = hoist::test::attack;
  Hub hub = make(false);
  RecClient c;
  hub.addClient(c);
  int id = 1;
  for (const char* ch : {"HOIST_HEALTH", "HOIST_GUIDE_SHAPE", "HOIST_ALARM"})
    hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", id++}, {"channelId", channelId(c, ch)}}}}}.dump());
  EXPECT_EQ(hub.counter("ws_subscriptions"), 3u);
  c.data.clear();
  int sent = 0;
  for (std::int32_t n : {0x7fffffff, -1, INT32_MIN, 100001}) {
    const auto h = atk::healthCount(n), g = atk::guideShapeCount(n);
    hub.onLcm("HOIST_HEALTH", h.data(), h.size());
    hub.onLcm("HOIST_GUIDE_SHAPE", g.data(), g.size());
    sent += 2;
  }
  for (std::uint32_t len : {0u, 0x80000000u, 0xffffffffu, 0x7fffffffu}) {
    const auto a = atk::alarmStringLen(len);
    hub.onLcm("HOIST_ALARM", a.data(), a.size());
    ++sent;
  }
  EXPECT_TRUE(c.data.empty());
  EXPECT_EQ(hub.counter("lcm_decoded"), 0u);
  EXPECT_EQ(hub.counter("lcm_handler_exceptions"), 0u);
  EXPECT_EQ(hub.counter("lcm_rejected_decode_bad_count"), 8u);
  EXPECT_EQ(hub.counter("lcm_rejected_decode_bad_string"), 4u);
  EXPECT_EQ(hub.counter("lcm_messages"), static_cast<std::uint64_t>(sent));
}

TEST_F(HubTest, PrefixesAreDiscoveredFromHealthAndEarlierAlarmsKept) {
  Hub hub = make(false, {});
  RecClient c;
  hub.addClient(c);
  EXPECT_TRUE(hub.prefixes().empty());
  cage_state_t m{};
  const auto cb = encode(m);
  hub.onLcm("south/HOIST_CAGE", cb.data(), cb.size());
  EXPECT_TRUE(hub.prefixes().empty());  // only HOIST_HEALTH announces a shaft
  health_t h{};
  const auto hb = encode(h);
  hub.onLcm("south/HOIST_HEALTH", hb.data(), hb.size());
  ASSERT_EQ(hub.prefixes().size(), 1u);
  EXPECT_EQ(hub.prefixes()[0], "south/");
  EXPECT_NE(channelId(c, "south/HOIST_CAGE"), 0u);  // advertised to the connected client
}

TEST_F(HubTest, DecimatedChannelKeepsEachIntervalsMinAndMax) {
  Hub hub = make(false);
  RecClient c;
  hub.addClient(c);
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 7}, {"channelId", channelId(c, "HOIST_CAGE/decimated")}}}}}.dump());
  const double ys[] = {0.001, 0.009, -0.004, 0.002};  // a one-sample peak of 9 mm and dip of -4 mm
  for (int i = 0; i < 4; ++i) {
    cage_state_t m{};
    m.utime = 1000 + i;
    m.t = 0.01 * i;
    m.y_c = ys[i];
    m.lambdas[2] = 10.0 * i;
    m.degraded = i == 1;
    const auto b = encode(m);
    hub.onLcm("HOIST_CAGE", b.data(), b.size());
  }
  hub.flushDecimated();
  ASSERT_EQ(c.data.size(), 1u);
  const Json d = Json::parse(c.data[0].substr(13));
  EXPECT_EQ(d["count"], 4);
  EXPECT_DOUBLE_EQ(d["max"]["y_c"].get<double>(), 0.009);
  EXPECT_DOUBLE_EQ(d["min"]["y_c"].get<double>(), -0.004);
  EXPECT_DOUBLE_EQ(d["max"]["lambdas"][2].get<double>(), 30.0);
  EXPECT_DOUBLE_EQ(d["min"]["lambdas"][2].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(d["last"]["y_c"].get<double>(), 0.002);
  EXPECT_EQ(d["first"]["utime"], 1000);
  EXPECT_TRUE(d["max"]["degraded"].get<bool>());
  EXPECT_FALSE(d["min"]["degraded"].get<bool>());
  hub.flushDecimated();  // nothing new: nothing sent
  EXPECT_EQ(c.data.size(), 1u);
}

// HOIST_ESTIMATE: advertised per shaft with its JSON Schema (field names as in
// estimate_t.lcm), delivered whole on its own channel, and decimated like the
// cage on HOIST_ESTIMATE/decimated (the page's load-estimate panel).
TEST_F(HubTest, EstimateIsAdvertisedAndDecimatedLikeTheCage) {
  Hub hub = make(false, {"north/"});
  RecClient c;
  hub.addClient(c);
  const auto raw = channelId(c, "north/HOIST_ESTIMATE");
  const auto dec = channelId(c, "north/HOIST_ESTIMATE/decimated");
  ASSERT_NE(raw, 0u);
  ASSERT_NE(dec, 0u);
  for (const auto& ch : c.text[1]["channels"])
    if (ch["topic"] == "north/HOIST_ESTIMATE") {
      EXPECT_EQ(ch["schemaName"], "hoist.estimate_t");
      const Json schema = Json::parse(ch["schema"].get<std::string>());
      for (const char* f : {"Fa", "sigma_Fa", "b", "sigma_b", "theta_open", "nis_window", "nis_bound", "sigma_lambdas"})
        EXPECT_TRUE(schema["properties"].contains(f)) << f;
    }
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 3}, {"channelId", raw}}, {{"id", 4}, {"channelId", dec}}}}}.dump());
  const double fa[] = {1499.0, 1504.5, 1501.0};  // Fa +- a few N
  for (int i = 0; i < 3; ++i) {
    estimate_t e{};
    e.utime = 2000 + i;
    e.t = 0.01 * i;
    e.Fa = fa[i];
    e.sigma_Fa = 3.0;
    e.b = 0.6;
    e.sigma_b = 0.01;
    e.theta = 6.5e-4 + 1e-5 * i;
    e.sigma_theta = 1e-5;
    e.theta_open = 8.3e-4;
    e.nis_window = 300.0 + 10.0 * i;
    e.nis_bound = 372.0;
    e.mismatch = i == 1;
    const auto b = encode(e);
    hub.onLcm("north/HOIST_ESTIMATE", b.data(), b.size());
  }
  ASSERT_EQ(c.data.size(), 3u);  // each estimate whole on HOIST_ESTIMATE
  const Json first = Json::parse(c.data[0].substr(13));
  EXPECT_DOUBLE_EQ(first["Fa"].get<double>(), 1499.0);
  hub.flushDecimated();
  ASSERT_EQ(c.data.size(), 4u);
  std::uint32_t sub = 0;
  std::memcpy(&sub, c.data[3].data() + 1, 4);
  EXPECT_EQ(sub, 4u);
  const Json d = Json::parse(c.data[3].substr(13));
  EXPECT_EQ(d["count"], 3);
  EXPECT_DOUBLE_EQ(d["max"]["Fa"].get<double>(), 1504.5);
  EXPECT_DOUBLE_EQ(d["min"]["Fa"].get<double>(), 1499.0);
  EXPECT_DOUBLE_EQ(d["max"]["nis_window"].get<double>(), 320.0);
  EXPECT_TRUE(d["max"]["mismatch"].get<bool>());  // a mismatch within the interval is not lost
  EXPECT_DOUBLE_EQ(d["last"]["Fa"].get<double>(), 1501.0);
  hub.flushDecimated();
  EXPECT_EQ(c.data.size(), 4u);
}

std::string clientMessage(std::uint32_t chan, const Json& j) {
  std::string f(5, '\0');
  f[0] = 1;
  for (int i = 0; i < 4; ++i) f[1 + i] = static_cast<char>((chan >> (8 * i)) & 0xff);
  return f + j.dump();
}

/// The client advertises HOIST_ALARM_ACK (json) as channel `id`.
void advertiseAck(Hub& hub, RecClient& c, int id) {
  hub.onClientText(c, Json{{"op", "advertise"},
                           {"channels", {{{"id", id}, {"topic", "HOIST_ALARM_ACK"}, {"encoding", "json"}, {"schemaName", "hoist.alarm_ack_t"}}}}}
                          .dump());
}

TEST_F(HubTest, ClientPublishesAlarmAckAfterValidation) {
  Hub hub = make(false);
  RecClient c;
  hub.addClient(c);
  advertiseAck(hub, c, 5);
  hub.onClientBinary(c, clientMessage(5, {{"utime", 0}, {"kind", "CAGE_POS_Y"}, {"level", 1}, {"action", 2}, {"shelve_duration", 600.0}, {"user", "ann"}}));
  ASSERT_EQ(pub.size(), 1u);
  EXPECT_EQ(pub[0].channel, "HOIST_ALARM_ACK");
  alarm_ack_t a{};
  ASSERT_GE(a.decode(pub[0].bytes.data(), 0, static_cast<int>(pub[0].bytes.size())), 0);
  EXPECT_EQ(a.kind, "CAGE_POS_Y");
  EXPECT_EQ(a.action, 2);  // ACTION_SHELVE
  EXPECT_EQ(a.user, "ann");
  EXPECT_DOUBLE_EQ(a.shelve_duration, 600.0);
  EXPECT_EQ(a.utime, 1'700'000'000'000'000LL);  // the server's clock, in us

  // Invalid: no user, bad kind, bad action; unadvertised channel; other topics.
  hub.onClientBinary(c, clientMessage(5, {{"utime", 0}, {"kind", "CAGE_POS_Y"}, {"level", 1}, {"action", 1}, {"shelve_duration", 0.0}, {"user", ""}}));
  hub.onClientBinary(c, clientMessage(5, {{"utime", 0}, {"kind", "../x"}, {"level", 1}, {"action", 1}, {"shelve_duration", 0.0}, {"user", "a"}}));
  hub.onClientBinary(c, clientMessage(5, {{"utime", 0}, {"kind", "X"}, {"level", 1}, {"action", 9}, {"shelve_duration", 0.0}, {"user", "a"}}));
  hub.onClientBinary(c, clientMessage(6, {{"utime", 0}, {"kind", "X"}, {"level", 1}, {"action", 1}, {"shelve_duration", 0.0}, {"user", "a"}}));
  hub.onClientText(c, Json{{"op", "advertise"}, {"channels", {{{"id", 8}, {"topic", "HOIST_WINDER"}, {"encoding", "json"}}}}}.dump());
  EXPECT_EQ(pub.size(), 1u);
  EXPECT_EQ(hub.counter("commands_rejected_invalid"), 3u);
  EXPECT_EQ(hub.counter("commands_rejected_unadvertised"), 1u);
  EXPECT_EQ(hub.counter("commands_rejected_topic"), 1u);
  ASSERT_NE(c.lastStatus(), nullptr);
  EXPECT_EQ((*c.lastStatus())["level"], 2);
}

// The load estimator's live calibration through the dashboard's protocol (a
// Foxglove Publish panel, issue 30): the daemon's rule (hoist::contract),
// published with the server's time; invalid ones refused and counted.
TEST_F(HubTest, ClientPublishesACalibrationAfterTheDaemonsValidation) {
  Hub hub = make(false);
  RecClient c;
  hub.addClient(c);
  advertiseAck(hub, c, 5);
  hub.onClientBinary(c, clientMessage(5, {{"kind", ""}, {"level", 0}, {"action", 5}, {"known_fa", 0.0}, {"known_b", 0.0},
                                          {"calibrate_duration", 60.0}, {"user", "eng"}}));
  ASSERT_EQ(pub.size(), 1u);
  alarm_ack_t a{};
  ASSERT_GE(a.decode(pub[0].bytes.data(), 0, static_cast<int>(pub[0].bytes.size())), 0);
  EXPECT_EQ(a.action, +alarm_ack_t::ACTION_CALIBRATE);
  EXPECT_EQ(a.known_fa, 0.0);
  EXPECT_EQ(a.calibrate_duration, 60.0);
  EXPECT_EQ(a.user, "eng");
  EXPECT_EQ(a.utime, 1'700'000'000'000'000LL);
  ASSERT_NE(c.lastStatus(), nullptr);
  EXPECT_EQ((*c.lastStatus())["level"], 0);
  EXPECT_NE((*c.lastStatus())["message"].get<std::string>().find("sent calibrate"), std::string::npos);
  // No duration, too long, a negative load, no user, an alarm named: refused.
  hub.onClientBinary(c, clientMessage(5, {{"kind", ""}, {"level", 0}, {"action", 5}, {"user", "eng"}}));
  hub.onClientBinary(c, clientMessage(5, {{"kind", ""}, {"level", 0}, {"action", 5}, {"known_fa", 0.0}, {"known_b", 0.0},
                                          {"calibrate_duration", 601.0}, {"user", "eng"}}));
  hub.onClientBinary(c, clientMessage(5, {{"kind", ""}, {"level", 0}, {"action", 5}, {"known_fa", -1.0}, {"known_b", 0.0},
                                          {"calibrate_duration", 60.0}, {"user", "eng"}}));
  hub.onClientBinary(c, clientMessage(5, {{"kind", ""}, {"level", 0}, {"action", 5}, {"known_fa", 0.0}, {"known_b", 0.0},
                                          {"calibrate_duration", 60.0}, {"user", ""}}));
  hub.onClientBinary(c, clientMessage(5, {{"kind", ""}, {"level", 0}, {"action", 5}, {"known_fa", 0.0}, {"known_b", 0.0},
                                          {"calibrate_duration", 60.0}, {"user", "eng"}, {"activation_utime", 5}}));
  EXPECT_EQ(pub.size(), 1u);
  EXPECT_EQ(hub.counter("commands_rejected_invalid"), 5u);
  EXPECT_EQ((*c.lastStatus())["level"], 2);
}

TEST_F(HubTest, ReadOnlyRefusesEveryCommand) {
  Hub hub = make(true);
  RecClient c;
  hub.addClient(c);
  EXPECT_TRUE(c.text[0]["capabilities"].empty());
  EXPECT_FALSE(c.text[0].contains("supportedEncodings"));
  hub.onClientText(c, Json{{"op", "advertise"}, {"channels", {{{"id", 5}, {"topic", "HOIST_ALARM_ACK"}, {"encoding", "json"}}}}}.dump());
  hub.onClientBinary(c, clientMessage(5, {{"utime", 0}, {"kind", "CAGE_POS_Y"}, {"level", 1}, {"action", 1}, {"shelve_duration", 0.0}, {"user", "x"}}));
  EXPECT_TRUE(pub.empty());
  EXPECT_EQ(hub.counter("commands_rejected_read_only"), 2u);
}

TEST_F(HubTest, BadClientMessagesGetAnErrorStatusAndAreCounted) {
  Hub hub = make(false);
  RecClient c;
  hub.addClient(c);
  const auto cage = channelId(c, "HOIST_CAGE");
  for (const char* s : {"{", "[]", "{\"op\":3}", "{\"op\":\"nope\"}", "{\"op\":\"fetchAsset\"}",
                        "{\"op\":\"subscribe\"}", "{\"op\":\"subscribe\",\"subscriptions\":[{\"id\":-1,\"channelId\":1}]}",
                        "{\"op\":\"unsubscribe\",\"subscriptionIds\":[99]}"}) {
    const std::size_t n = c.text.size();
    hub.onClientText(c, s);
    ASSERT_EQ(c.text.size(), n + 1) << s;
    EXPECT_EQ(c.text.back()["op"], "status") << s;
  }
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", cage}}}}}.dump());
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", cage}}}}}.dump());  // id reused
  hub.onClientBinary(c, std::string("\x05", 1));
  hub.onClientBinary(c, std::string("\x01\x00", 2));
  EXPECT_EQ(hub.counter("ws_rejected_bad_json"), 3u);
  EXPECT_EQ(hub.counter("ws_rejected_unknown_op"), 1u);
  EXPECT_EQ(hub.counter("ws_rejected_unsupported_op"), 1u);
  EXPECT_EQ(hub.counter("ws_rejected_bad_request"), 5u);
  EXPECT_EQ(hub.counter("ws_rejected_unknown_binary_op"), 1u);
}

// ---- discovery aging, alarm identity, history, optional command fields ----

class HubClockTest : public HubTest {
 protected:
  Hub makeTimed(std::vector<std::string> prefixes = {}) {
    Hub::Options o;
    o.prefixes = std::move(prefixes);
    o.discover = o.prefixes.empty();
    o.max_prefixes = 4;
    return Hub(
        o, [this](const std::string& ch, const std::vector<std::uint8_t>& b) {
          pub.push_back({ch, b});
          return true;
        },
        [this] { return now_ns; });
  }
  void health(Hub& hub, const std::string& prefix, std::int64_t instance) {
    health_t h{};
    h.instance_id = instance;
    const auto b = encode(h);
    hub.onLcm(prefix + "HOIST_HEALTH", b.data(), b.size());
  }
  void alarm(Hub& hub, const std::string& kind, int event, std::int64_t utime, bool active = true, bool acked = false,
             std::int64_t instance = 7) {
    alarm_t a{};
    a.instance_id = instance;  // the daemon whose health the hub follows (issue 33)
    a.id = ++alarm_seq;        // its event number (+1 per event)
    a.utime = utime;
    a.kind = kind;
    a.level = 1;
    a.event_type = static_cast<std::int8_t>(event);
    a.active = active;
    a.acked = acked;
    const auto b = encode(a);
    hub.onLcm("HOIST_ALARM", b.data(), b.size());
  }
  void advance(double s) { now_ns += static_cast<std::uint64_t>(s * 1e9); }
  std::uint64_t now_ns = 1'700'000'000'000'000'000ULL;
  std::int64_t alarm_seq = 0;
};

TEST_F(HubClockTest, OneShotPrefixesAgeOutAndARealDaemonTakesTheirSlot) {
  Hub hub = makeTimed();
  RecClient c;
  hub.addClient(c);
  for (int i = 0; i < 300; ++i) health(hub, "forged" + std::to_string(i) + "/", 42);  // one datagram each
  EXPECT_EQ(hub.prefixes().size(), 4u);
  EXPECT_EQ(hub.counter("prefix_refused_table_full"), 296u);
  EXPECT_TRUE(hub.stats()["discovery"]["table_full"].get<bool>());
  int statuses = 0;
  for (const auto& m : c.text) statuses += m["op"] == "status" && m.value("id", "") == "discovery-full";
  EXPECT_EQ(statuses, 1) << "a full table is a status the clients see, at most once a second (not one per refusal)";
  // The real daemon keeps sending at the health rate: with its second message
  // it has more evidence than a one-shot candidate and takes its slot.
  health(hub, "north/", 7);
  EXPECT_EQ(std::count(hub.prefixes().begin(), hub.prefixes().end(), "north/"), 0);
  advance(1.0);
  health(hub, "north/", 7);
  EXPECT_EQ(std::count(hub.prefixes().begin(), hub.prefixes().end(), "north/"), 1);
  EXPECT_EQ(hub.counter("prefix_replaced"), 1u);
  std::string latest;
  for (const auto& m : c.text)
    if (m["op"] == "status" && m.value("id", "") == "discovery-full") latest = m["message"];
  EXPECT_NE(latest.find("(297 refused so far)"), std::string::npos) << "the throttled text, updated a second later: " << latest;
  advance(1.0);
  health(hub, "north/", 7);  // third message of one instance at the health rate: confirmed
  EXPECT_EQ(hub.stats()["discovery"]["confirmed"], Json::array({"north/"}));
  // The forged candidates fall silent and age out; the confirmed one stays.
  advance(3.5);
  hub.maintainDiscovery();
  EXPECT_EQ(hub.prefixes(), std::vector<std::string>{"north/"});
  EXPECT_EQ(hub.counter("prefix_aged_out"), 3u);
  bool unadvertised = false;
  for (const auto& m : c.text) unadvertised |= m["op"] == "unadvertise";
  EXPECT_TRUE(unadvertised);
  advance(11.0);
  hub.maintainDiscovery();
  bool removed = false;
  for (const auto& m : c.text) removed |= m["op"] == "removeStatus";
  EXPECT_TRUE(removed) << "the table-full status ends once refusals stop";
}

TEST_F(HubClockTest, NoInstanceIdNeverConfirmsAndTwoPrefixesOfOneShaftNameAreReported) {
  Hub hub = makeTimed();
  for (int k = 0; k < 5; ++k) {
    health(hub, "a/", 0);  // no daemon instance id
    advance(1.0);
  }
  EXPECT_TRUE(hub.stats()["discovery"]["confirmed"].empty());
  health(hub, "north/", 5);
  health(hub, "north_", 6);
  EXPECT_EQ(std::count(hub.prefixes().begin(), hub.prefixes().end(), "north/"), 1);
  EXPECT_EQ(std::count(hub.prefixes().begin(), hub.prefixes().end(), "north_"), 1);
  EXPECT_EQ(hub.counter("prefix_name_clash"), 1u);
  bool clash = false;
  const Json stats = hub.stats();
  for (const auto& st : stats["discovery"]["status"]) clash |= st["id"] == "discovery-clash:north";
  EXPECT_TRUE(clash);
  EXPECT_EQ(Hub::shaftName(""), "default");
  EXPECT_EQ(Hub::shaftName("north/"), "north");
}

TEST_F(HubClockTest, AlarmsOfPrefixesThatNeverSendHealthAreForgotten) {
  Hub hub = makeTimed();
  auto alarmOn = [&](const std::string& prefix) {
    alarm_t a{};
    a.utime = 1;
    a.kind = "INPUT_STALE";
    a.level = 1;
    a.event_type = 1;
    a.active = true;
    a.instance_id = 9;
    const auto b = encode(a);
    hub.onLcm(prefix + "HOIST_ALARM", b.data(), b.size());
  };
  for (int i = 0; i < 10; ++i) alarmOn("forged" + std::to_string(i) + "/");  // never followed by health
  advance(31.0);
  hub.maintainDiscovery();
  alarmOn("north/");  // a real daemon's first alarm, its health a moment later
  advance(0.5);
  health(hub, "north/", 9);
  RecClient c;
  hub.addClient(c);
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", channelId(c, "north/HOIST_ALARM")}}}}}.dump());
  ASSERT_EQ(c.data.size(), 1u) << "the early alarm of the real shaft was kept";
  EXPECT_EQ(Json::parse(c.data[0].substr(13))["kind"], "INPUT_STALE");
}

TEST_F(HubClockTest, ActivationKeptAcrossReannouncesAndStaleCommandsRefused) {
  Hub hub = makeTimed({""});
  RecClient c;
  hub.addClient(c);
  health(hub, "", 7);
  alarm(hub, "CAGE_POS_Y", 1, 1000);   // RAISE
  alarm(hub, "CAGE_POS_Y", 6, 31000);  // REANNOUNCE
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 3}, {"channelId", channelId(c, "HOIST_ALARM")}}}}}.dump());
  ASSERT_EQ(c.data.size(), 1u);
  const Json a = Json::parse(c.data[0].substr(13));
  EXPECT_EQ(a["utime"], 31000);
  EXPECT_EQ(a["dash_activation_utime"], 1000);
  EXPECT_EQ(a["dash_reannounce_utime"], 31000);
  EXPECT_TRUE(a["dash_activation_known"].get<bool>());

  hub.onClientText(c, Json{{"op", "advertise"},
                           {"channels", {{{"id", 5}, {"topic", "HOIST_ALARM_ACK"}, {"encoding", "json"}}}}}.dump());
  // Drawn at activation 1000: sent.  Then cleared and raised again: refused.
  hub.onClientBinary(c, clientMessage(5, {{"kind", "CAGE_POS_Y"}, {"level", 1}, {"action", 1}, {"user", "ann"},
                                          {"activation_utime", 1000}}));
  ASSERT_EQ(pub.size(), 1u) << "no utime, no shelve_duration: accepted (Foxglove clients)";
  alarm(hub, "CAGE_POS_Y", 2, 40000, false, true);  // cleared, acknowledged: normal
  alarm(hub, "CAGE_POS_Y", 1, 50000);               // raised again
  hub.onClientBinary(c, clientMessage(5, {{"kind", "CAGE_POS_Y"}, {"level", 1}, {"action", 1}, {"user", "ann"},
                                          {"activation_utime", 1000}}));
  EXPECT_EQ(pub.size(), 1u);
  EXPECT_EQ(hub.counter("commands_refused_stale"), 1u);
  ASSERT_NE(c.lastStatus(), nullptr);
  EXPECT_NE((*c.lastStatus())["message"].get<std::string>().find("CAGE_POS_Y WARNING changed since your page drew it"),
            std::string::npos);
  // A shelve still needs its duration.
  hub.onClientBinary(c, clientMessage(5, {{"kind", "CAGE_POS_Y"}, {"level", 1}, {"action", 2}, {"user", "ann"}}));
  EXPECT_EQ(pub.size(), 1u);
}

// Issue 35 item 3: a new daemon instance on the same prefix (the daemon was
// killed and restarted) voids the alarm states of the instance that has gone:
// hoist-dash drops them from its table (a page opened later never sees them)
// and sends each subscriber a CLEAR that takes the row off its list; alarms
// of the new instance (utime from its start on) are kept, and the new
// instance is asked to re-announce its own.  Same instance again: nothing.
TEST_F(HubClockTest, ANewDaemonInstanceClearsTheAlarmsOfTheOneThatHasGone) {
  Hub hub = makeTimed({""});
  hub.requestAlarmStates();
  RecClient c;
  hub.addClient(c);
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 3}, {"channelId", channelId(c, "HOIST_ALARM")}}}}}.dump());
  auto healthAt = [&](std::int64_t instance, std::int64_t utime, double uptime) {
    health_t h{};
    h.instance_id = instance;
    h.utime = utime;
    h.uptime = uptime;
    const auto b = encode(h);
    hub.onLcm("HOIST_HEALTH", b.data(), b.size());
  };
  healthAt(7, 100'000'000, 100.0);  // instance 7, up since utime 0
  alarm(hub, "CAGE_NEG_Y", 1, 50'000'000);
  alarm(hub, "PREDICTED_CLEARANCE", 1, 60'000'000);
  healthAt(7, 101'000'000, 101.0);
  const auto before = c.data.size();
  ASSERT_EQ(before, 2u);
  // Killed at 102 s; instance 9 starts at 200 s and raises CAGE_POS_Y before
  // its first health: not the instance the hub follows yet, dropped (issue
  // 33); the re-announce the new instance is asked for brings it back.
  advance(100.0);
  alarm(hub, "CAGE_POS_Y", 1, 200'500'000, true, false, 9);
  EXPECT_EQ(hub.counter("HOIST_ALARM_foreign_instance"), 1u);
  const auto requests = pub.size();
  healthAt(9, 201'000'000, 1.0);
  EXPECT_EQ(hub.counter("daemon_restarts"), 1u);
  EXPECT_EQ(hub.counter("alarms_cleared_restart"), 2u);
  alarm(hub, "CAGE_POS_Y", 6, 201'100'000, true, false, 9);  // the re-announce
  ASSERT_EQ(c.data.size(), before + 2 + 1) << "one CLEAR per alarm of the old instance, then CAGE_POS_Y";
  std::set<std::string> cleared;
  for (std::size_t i = before; i < before + 2; ++i) {
    const Json a = Json::parse(c.data[i].substr(13));
    EXPECT_FALSE(a["active"].get<bool>());
    EXPECT_TRUE(a["acked"].get<bool>()) << "acknowledged and inactive: normal, off every list";
    EXPECT_EQ(a["event_type"], 2);
    EXPECT_NE(a["message"].get<std::string>().find("the daemon restarted"), std::string::npos);
    cleared.insert(a["kind"].get<std::string>());
  }
  EXPECT_EQ(cleared, (std::set<std::string>{"CAGE_NEG_Y", "PREDICTED_CLEARANCE"}));
  EXPECT_GT(pub.size(), requests) << "the new instance is asked to re-announce";
  // A page subscribing now gets only the new instance's alarm.
  RecClient late;
  hub.addClient(late);
  hub.onClientText(late, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 4}, {"channelId", channelId(late, "HOIST_ALARM")}}}}}.dump());
  ASSERT_EQ(late.data.size(), 1u);
  EXPECT_EQ(Json::parse(late.data[0].substr(13))["kind"], "CAGE_POS_Y");
  // The same instance again clears nothing.
  advance(1.0);
  healthAt(9, 202'000'000, 2.0);
  EXPECT_EQ(hub.counter("daemon_restarts"), 1u);
  EXPECT_EQ(c.data.size(), before + 3);
}

// Issue 33: one forged alarm_t CLEAR of the active CAGE_POS_Y, from another
// daemon instance than the one whose health the hub follows, cleared the
// dashboard's row for every client with no trace.  Now it is dropped,
// counted and logged; so is a forged health stream of another instance under
// the same prefix while the real daemon talks (it would have cleared every
// alarm as a "restart"), and its cage states.
TEST_F(HubClockTest, ForgedAlarmClearAndImpostorHealthNeitherClearTheRowNorGoUnlogged) {
  std::ostringstream log_text;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log_text);
  auto old_logger = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("t", sink));
  Hub hub = makeTimed({""});
  RecClient c;
  hub.addClient(c);
  hub.onClientText(c, Json{{"op", "subscribe"},
                           {"subscriptions", {{{"id", 3}, {"channelId", channelId(c, "HOIST_ALARM")}}}}}.dump());
  health(hub, "", 7);
  alarm(hub, "CAGE_POS_Y", alarm_t::EVENT_CLEAR, 500, false, true, 7);  // an earlier CLEAR
  alarm(hub, "CAGE_POS_Y", alarm_t::EVENT_RAISE, 1000, true, false, 7);
  ASSERT_EQ(c.data.size(), 2u);
  alarm(hub, "CAGE_POS_Y", alarm_t::EVENT_CLEAR, 2000, false, true, 8);  // forged: another instance
  alarm(hub, "CAGE_POS_Y", alarm_t::EVENT_CLEAR, 2000, false, true, 0);  // forged: no instance
  EXPECT_EQ(c.data.size(), 2u) << "a forged CLEAR reached the clients";
  EXPECT_EQ(hub.counter("HOIST_ALARM_foreign_instance"), 2u);
  // An impostor's health under the same prefix while instance 7 talks: no
  // restart, no row cleared, its cage states dropped.
  advance(1.0);
  health(hub, "", 8);
  cage_state_t cs{};
  cs.instance_id = 8;
  const auto cb = encode(cs);
  hub.onLcm("HOIST_CAGE", cb.data(), cb.size());
  EXPECT_EQ(hub.counter("health_impostor"), 1u);
  EXPECT_EQ(hub.counter("HOIST_CAGE_foreign_instance"), 1u);
  EXPECT_EQ(hub.counter("daemon_restarts"), 0u);
  EXPECT_EQ(c.data.size(), 2u);
  RecClient late;
  hub.addClient(late);
  hub.onClientText(late, Json{{"op", "subscribe"},
                              {"subscriptions", {{{"id", 4}, {"channelId", channelId(late, "HOIST_ALARM")}}}}}.dump());
  ASSERT_EQ(late.data.size(), 1u);
  EXPECT_TRUE(Json::parse(late.data[0].substr(13))["active"].get<bool>()) << "the row is still active";
  spdlog::set_default_logger(old_logger);
  const std::string text = log_text.str();
  EXPECT_NE(text.find("dropped HOIST_ALARM of daemon instance 8: the dashboard follows instance 7"), std::string::npos)
      << text;
  EXPECT_NE(text.find("health of another daemon instance 8 while instance 7 is alive"), std::string::npos) << text;
}

// hoist-dash asks each shaft's daemon for its alarms' current states
// (alarm_ack_t ACTION_REANNOUNCE) once its LCM receive path is open: when a
// daemon's health first arrives (a fixed prefix), when a discovered shaft is
// confirmed, and for a new daemon instance -- never into the void, never for
// an unconfirmed (possibly forged) prefix.  The daemon's answer (a
// REANNOUNCE of an alarm raised before the dashboard started) is in the
// alarm list at once, as its state, its activation marked as from before.
TEST_F(HubClockTest, AlarmStatesAreRequestedAtStartAndForEachDiscoveredShaft) {
  auto requests = [&](const std::string& channel) {
    int n = 0;
    for (const auto& p : pub) {
      if (p.channel != channel) continue;
      alarm_ack_t m{};
      EXPECT_GE(m.decode(p.bytes.data(), 0, static_cast<int>(p.bytes.size())), 0);
      EXPECT_EQ(m.action, +alarm_ack_t::ACTION_REANNOUNCE);
      EXPECT_EQ(m.kind, "*");
      EXPECT_EQ(m.level, 0);
      ++n;
    }
    return n;
  };
  {
    Hub fixed = makeTimed({"a/", "b/"});
    health(fixed, "a/", 7);
    EXPECT_TRUE(pub.empty()) << "not before the receive path is open";
    fixed.requestAlarmStates();
    EXPECT_TRUE(pub.empty()) << "no request before a daemon is heard";
    health(fixed, "a/", 7);
    health(fixed, "a/", 7);
    EXPECT_EQ(requests("a/HOIST_ALARM_ACK"), 1) << "once per daemon instance";
    advance(4.0);            // instance 7 silent for longer than health_gap_s ...
    health(fixed, "a/", 8);  // ... the daemon restarted
    EXPECT_EQ(requests("a/HOIST_ALARM_ACK"), 2);
    EXPECT_EQ(requests("b/HOIST_ALARM_ACK"), 0);
    health(fixed, "b/", 9);
    EXPECT_EQ(requests("b/HOIST_ALARM_ACK"), 1);
    EXPECT_EQ(pub.size(), 3u);
  }
  pub.clear();
  Hub hub = makeTimed();
  hub.requestAlarmStates();
  for (int i = 0; i < 3; ++i) {
    health(hub, "north/", 7);
    health(hub, "forged/", 66);  // one datagram each, at most (never confirmed)
    EXPECT_EQ(requests("north/HOIST_ALARM_ACK"), i == 2 ? 1 : 0) << "asked when confirmed (third health)";
    advance(1.0);
    if (i == 0) health(hub, "forged/", 67);
  }
  EXPECT_EQ(requests("forged/HOIST_ALARM_ACK"), 0);
  // The daemon's answer: CAGE_POS_Y raised before the dashboard started.
  RecClient c;
  hub.addClient(c);
  alarm_t a{};
  a.utime = 5000;
  a.instance_id = 7;
  a.kind = "CAGE_POS_Y";
  a.level = 1;
  a.event_type = alarm_t::EVENT_REANNOUNCE;
  a.active = true;
  const auto b = encode(a);
  hub.onLcm("north/HOIST_ALARM", b.data(), b.size());
  hub.onClientText(c, Json{{"op", "subscribe"},
                           {"subscriptions", {{{"id", 3}, {"channelId", channelId(c, "north/HOIST_ALARM")}}}}}.dump());
  ASSERT_EQ(c.data.size(), 1u);
  const Json got = Json::parse(c.data[0].substr(13));
  EXPECT_TRUE(got["active"].get<bool>());
  EXPECT_EQ(got["event_type"], +alarm_t::EVENT_REANNOUNCE);
  EXPECT_FALSE(got["dash_activation_known"].get<bool>()) << "raised before the dashboard heard it";
  EXPECT_EQ(hub.counter("alarm_state_requests"), 1u);
}

TEST_F(HubClockTest, HistoryIsSentOnSubscribeAndBounded) {
  Hub hub = makeTimed({""});
  for (int i = 0; i < 400 * 25; ++i) {  // 400 s at 25 Hz, one cage state per flush
    cage_state_t m{};
    m.utime = 1'000'000'000 + static_cast<std::int64_t>(i) * 40'000;
    m.y_c = 0.001 * (i % 7);
    m.l = 10.0 + i * 0.001;
    const auto b = encode(m);
    hub.onLcm("HOIST_CAGE", b.data(), b.size());
    hub.flushDecimated();
  }
  RecClient c;
  hub.addClient(c);
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 9}, {"channelId", channelId(c, "HOIST_CAGE/history")}}}}}.dump());
  ASSERT_EQ(c.data.size(), 1u);
  const Json h = Json::parse(c.data[0].substr(13));
  const auto n = h["first_utime"].size();
  EXPECT_GE(n, 1400u);  // 300 s in 0.2 s buckets
  EXPECT_LE(n, 1520u);
  const double span = (h["last_utime"].back().get<double>() - h["first_utime"][0].get<double>()) * 1e-6;
  EXPECT_NEAR(span, 300.0, 1.0);
  const auto yi = static_cast<std::size_t>(std::find(Hub::historyFields().begin(), Hub::historyFields().end(), "y_c") -
                                           Hub::historyFields().begin());
  EXPECT_DOUBLE_EQ(h["min"][10][yi].get<double>(), 0.0);  // min and max of each bucket
  EXPECT_DOUBLE_EQ(h["max"][10][yi].get<double>(), 0.006);
}

// Issue 35 item 4: the display unit of every alarm kind comes from one table
// beside the contract (msgs/contract/alarm_units.json; the page imports it as
// the generated alarm_units.js).  Every KIND_ of alarm_t.lcm has a row, each
// row a known format; PREDICTED_CLEARANCE reads in seconds (to the crossing
// against the horizon), not millimetres; the clearance kinds in mm.
TEST(AlarmUnitsTest, EveryAlarmKindHasAUnitFromTheOneTable) {
  std::ifstream in(HOIST_ALARM_UNITS_JSON);
  ASSERT_TRUE(in) << HOIST_ALARM_UNITS_JSON;
  const Json t = Json::parse(in, nullptr, false);
  ASSERT_TRUE(t.is_object() && t.contains("kinds")) << "not a JSON table with \"kinds\"";
  const Json& kinds = t["kinds"];
  for (const auto name : msg::enums::alarm_t::kKindNames) {
    const std::string k(name);
    ASSERT_TRUE(kinds.contains(k)) << "alarm_units.json has no row for " << k << " (a new KIND_ of alarm_t.lcm?)";
    const std::string f = kinds[k].value("format", "");
    EXPECT_TRUE(f == "fixed" || f == "sig" || f == "flag" || f == "instance") << k << ": format '" << f << "'";
    if (f == "fixed") {
      EXPECT_TRUE(kinds[k].contains("scale") && kinds[k].contains("decimals") && kinds[k].contains("unit")) << k;
    }
  }
  EXPECT_EQ(kinds.size(), msg::enums::alarm_t::kKindNames.size()) << "a row for a kind alarm_t.lcm does not have";
  EXPECT_EQ(kinds["PREDICTED_CLEARANCE"]["unit"], "s");
  EXPECT_EQ(kinds["PREDICTED_CLEARANCE"]["scale"], 1);
  EXPECT_EQ(kinds["CAGE_POS_Y"]["unit"], "mm");
  EXPECT_EQ(kinds["CAGE_POS_Y"]["scale"], 1000);
  EXPECT_EQ(kinds["ROPE_SLACK"]["unit"], "kN");
}

// Issue 33: one local process can bind all of 127.0.0.0/8 (and ::1), one
// remote host a whole IPv6 /64: each is one peer for the per-peer limits.
TEST(PeerTest, LoopbackIsOnePeerAndEachIpv6Slash64IsOne) {
  namespace ip = boost::asio::ip;
  EXPECT_EQ(Server::peerOf(ip::make_address("127.0.0.1")), "loopback");
  EXPECT_EQ(Server::peerOf(ip::make_address("127.0.0.2")), "loopback");
  EXPECT_EQ(Server::peerOf(ip::make_address("127.255.3.9")), "loopback");
  EXPECT_EQ(Server::peerOf(ip::make_address("::1")), "loopback");
  EXPECT_EQ(Server::peerOf(ip::make_address("::ffff:127.0.0.5")), "loopback");
  EXPECT_EQ(Server::peerOf(ip::make_address("10.1.2.3")), "10.1.2.3");
  EXPECT_EQ(Server::peerOf(ip::make_address("::ffff:10.1.2.3")), "10.1.2.3");
  EXPECT_NE(Server::peerOf(ip::make_address("10.1.2.3")), Server::peerOf(ip::make_address("10.1.2.4")));
  EXPECT_EQ(Server::peerOf(ip::make_address("2001:db8:1:2::1")), "2001:db8:1:2::/64");
  EXPECT_EQ(Server::peerOf(ip::make_address("2001:db8:1:2:ffff:ffff:ffff:ffff")), "2001:db8:1:2::/64");
  EXPECT_EQ(Server::peerOf(ip::make_address("2001:db8:1:3::1")), "2001:db8:1:3::/64");
  EXPECT_EQ(Server::peerOf(ip::make_address("fd00::2")), "fd00:0:0:0::/64");
}

// The token of authenticated clients: where a request presents it, and the
// credential it is read from ($CREDENTIALS_DIRECTORY, systemd's LoadCredential=).
TEST(PeerTest, TokenIsPresentedByBearerCookieOrQueryAndReadThroughLoadCredential) {
  EXPECT_EQ(Server::presentedToken("Bearer abc", "", "/"), "abc");
  EXPECT_EQ(Server::presentedToken("", "x=1; hoist_dash_token=tok; y=2", "/"), "tok");
  EXPECT_EQ(Server::presentedToken("", "hoist_dash_tokenX=no", "/?a=1&token=q"), "q");
  EXPECT_EQ(Server::presentedToken("Basic abc", "", "/index.html"), "");
  const std::string dir = ::testing::TempDir() + "hoist-dash-cred";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ::setenv("CREDENTIALS_DIRECTORY", dir.c_str(), 1);
  EXPECT_FALSE(readCredential("hoist-dash-token").found);
  std::ofstream(dir + "/hoist-dash-token") << "0123456789abcdef0123\n";
  Credential c = readCredential("hoist-dash-token");
  EXPECT_TRUE(c.found && c.error.empty());
  EXPECT_EQ(c.value, "0123456789abcdef0123");
  std::ofstream(dir + "/short") << "abc";
  c = readCredential("short");
  EXPECT_TRUE(c.found && c.value.empty());
  EXPECT_NE(c.error.find("16 to 256"), std::string::npos) << c.error;
  EXPECT_NE(readCredential("../etc/passwd").error, "");
  Server::Limits lim;
  lim.token = "0123456789abcdef0123";
  boost::asio::io_context io;
  Hub hub(Hub::Options{}, [](const std::string&, const std::vector<std::uint8_t>&) { return true; },
          [] { return std::uint64_t{1}; });
  StaticFiles files;
  Server srv(io, hub, files, lim);
  EXPECT_TRUE(srv.tokenMatches("0123456789abcdef0123"));
  EXPECT_FALSE(srv.tokenMatches("0123456789abcdef0124"));
  EXPECT_FALSE(srv.tokenMatches(""));
  ::unsetenv("CREDENTIALS_DIRECTORY");
}

TEST(StaticFilesTest, OnlyKnownFilesTraversalRefusedInEveryEncoding) {
  StaticFiles f;
  f.add("/index.html", "<html>", "text/html");
  f.add("/vendor/uPlot.iife.min.js", "x", "text/javascript");
  const StaticFile* p = nullptr;
  EXPECT_EQ(f.lookup("/", &p), StaticFiles::Verdict::Found);
  EXPECT_EQ(p->body, "<html>");
  EXPECT_EQ(f.lookup("/vendor/uPlot.iife.min.js?v=1", &p), StaticFiles::Verdict::Found);
  EXPECT_EQ(f.lookup("/%76endor/uPlot.iife.min.js", &p), StaticFiles::Verdict::Found);
  for (const char* t : {"/../../etc/passwd", "/%2e%2e/etc/passwd", "/%2E%2E%2Fetc%2Fpasswd", "/%252e%252e/etc/passwd",
                        "/vendor/../index.html", "/..", "/a/..", "/..\\x", "/x%5c..%5cy", "/index.html%00"})
    EXPECT_EQ(f.lookup(t, &p), StaticFiles::Verdict::Traversal) << t;
  for (const char* t : {"", "index.html", "/%zz", "/%4"}) EXPECT_EQ(f.lookup(t, &p), StaticFiles::Verdict::BadRequest) << t;
  EXPECT_EQ(f.lookup("/etc/passwd", &p), StaticFiles::Verdict::NotFound);
  EXPECT_EQ(f.lookup("/index.htm", &p), StaticFiles::Verdict::NotFound);
}

TEST(ValidateAckTest, Fields) {
  EXPECT_EQ(validateAckFields("CAGE_POS_Y", 1, 1, 0, "ann"), "");
  EXPECT_EQ(validateAckFields("*", 0, 3, 0, "ann"), "");
  EXPECT_NE(validateAckFields("", 1, 1, 0, "ann"), "");
  EXPECT_NE(validateAckFields(std::string(65, 'A'), 1, 1, 0, "ann"), "");
  EXPECT_NE(validateAckFields("cage", 1, 1, 0, "ann"), "");
  EXPECT_NE(validateAckFields("GUIDE_ROPE", 3, 1, 0, "ann"), "");
  EXPECT_NE(validateAckFields("GUIDE_ROPE", 1, 0, 0, "ann"), "");
  EXPECT_NE(validateAckFields("GUIDE_ROPE", 1, 4, 0, "ann"), "") << "re-announce is not the page's";
  EXPECT_NE(validateAckFields("GUIDE_ROPE", 1, 2, 0, "ann"), "");        // shelve needs a duration
  EXPECT_NE(validateAckFields("GUIDE_ROPE", 1, 2, 1e300 * 1e300, "ann"), "");
  EXPECT_NE(validateAckFields("GUIDE_ROPE", 1, 2, 2e6, "ann"), "");
  EXPECT_EQ(validateAckFields("GUIDE_ROPE", 1, 2, 600, "ann"), "");
  EXPECT_NE(validateAckFields("GUIDE_ROPE", 1, 1, 0, ""), "");
  EXPECT_NE(validateAckFields("GUIDE_ROPE", 1, 1, 0, "a\nb"), "");
  // The daemon's rule under the page's: a kind the daemon does not know is
  // refused here, named (it was forwarded and refused by the daemon).
  const std::string why = validateAckFields("NO_SUCH_KIND", 1, 1, 0, "ann");
  EXPECT_NE(why.find("alarm kind"), std::string::npos) << why;
  EXPECT_NE(why.find("NO_SUCH_KIND"), std::string::npos) << why;
  // Every kind of the contract passes, at both levels.
  for (std::string_view k : hoist::msg::enums::alarm_t::kKindNames)
    for (int level : {0, 1, 2}) EXPECT_EQ(validateAckFields(std::string(k), level, 1, 0, "ann"), "") << k;
}

}  // namespace
}  // namespace hoist::dash

// ---- HOIST_FORECAST (forecast_t with nested scenarios) ---------------
namespace hoist::dash {
namespace {

forecast_t sampleForecast() {
  forecast_t f{};
  f.utime = 1700000000000000;
  f.seq = 1;
  f.t_start = 20.0;
  f.l = 150.0;
  f.plan_seq = -1;
  f.num_scenarios = 2;
  f.scenarios.resize(2);
  for (int k = 0; k < 2; ++k) {
    auto& s = f.scenarios[static_cast<std::size_t>(k)];
    s.name = k == 0 ? "estop" : "continue";
    s.horizon = s.t_reached = 20.0;
    s.min_clearance = 0.02 + 0.01 * k;
    s.t_min_clearance = 3.0;
    s.t_warning = k == 0 ? 1.5 : -1.0;
    s.t_critical = k == 0 ? 2.5 : -1.0;
    s.lambda0_min = 3000.0;
    s.lambda0_max = 14000.0;
    s.num_points = 50;
    for (int i = 0; i < 50; ++i) {
      s.series_t.push_back(0.4 * (i + 1));
      s.series_min_clearance.push_back(0.05 - 0.0005 * i);
      s.series_lambda0_min.push_back(8000.0 - 10.0 * i);
      s.series_lambda0_max.push_back(9000.0 + 10.0 * i);
    }
  }
  return f;
}

TEST_F(HubTest, ForecastIsAdvertisedWithItsNestedSchemaAndForwardedAsJson) {
  Hub hub = make(false, {"north/"});
  RecClient c;
  hub.addClient(c);
  // Advertised under its LCM channel name, schema hoist.forecast_t with the
  // scenarios' schema inlined (no $ref for a client to resolve).
  Json adv;
  for (const auto& m : c.text)
    if (m["op"] == "advertise")
      for (const auto& ch : m["channels"])
        if (ch["topic"] == "north/HOIST_FORECAST") adv = ch;
  ASSERT_FALSE(adv.is_null());
  EXPECT_EQ(adv["schemaName"], "hoist.forecast_t");
  const Json schema = Json::parse(adv["schema"].get<std::string>());
  const Json& item = schema["properties"]["scenarios"]["items"];
  EXPECT_EQ(item["title"], "hoist.forecast_scenario_t");
  for (const char* k : {"name", "min_clearance", "t_min_clearance", "t_warning", "t_critical", "series_t",
                        "series_min_clearance", "series_lambda0_min", "series_lambda0_max"})
    EXPECT_TRUE(item["properties"].contains(k)) << k;
  EXPECT_EQ(schema["properties"]["scenarios"]["maxItems"], 8);

  const auto id = channelId(c, "north/HOIST_FORECAST");
  const auto bytes = encode(sampleForecast());
  hub.onLcm("north/HOIST_FORECAST", bytes.data(), bytes.size());  // before any subscriber: kept as latest
  hub.onClientText(c, Json{{"op", "subscribe"}, {"subscriptions", {{{"id", 7}, {"channelId", id}}}}}.dump());
  ASSERT_EQ(c.data.size(), 1u) << "the latest forecast is sent on subscribe";
  Json j = Json::parse(c.data[0].substr(13));
  ASSERT_EQ(j["scenarios"].size(), 2u);
  EXPECT_EQ(j["scenarios"][0]["name"], "estop");
  EXPECT_DOUBLE_EQ(j["scenarios"][0]["t_critical"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(j["scenarios"][1]["t_critical"].get<double>(), -1.0);
  EXPECT_EQ(j["scenarios"][1]["series_lambda0_max"].size(), 50u);
  hub.onLcm("north/HOIST_FORECAST", bytes.data(), bytes.size());
  EXPECT_EQ(c.data.size(), 2u);

  // Hostile forecasts: a lying nested count, a truncation, a forecast on the
  // wrong channel -- counted, never forwarded.
  auto bad = bytes;
  const std::size_t np = 8 + 9 * 8 + 1 + 4 + 6 + 1 + 8 * 8 + 4 * 8 + 16;  // scenarios[0].num_points
  ASSERT_EQ(bad[np + 1], 50);
  bad[np] = 0x7f;
  hub.onLcm("north/HOIST_FORECAST", bad.data(), bad.size());
  auto cut = bytes;
  cut.resize(cut.size() - 3);
  hub.onLcm("north/HOIST_FORECAST", cut.data(), cut.size());
  hub.onLcm("north/HOIST_CAGE", bytes.data(), bytes.size());
  EXPECT_EQ(c.data.size(), 2u);
  EXPECT_EQ(hub.counter("lcm_rejected_decode_bad_count"), 1u);
  EXPECT_EQ(hub.counter("lcm_rejected_decode_truncated"), 1u);
  EXPECT_EQ(hub.counter("lcm_rejected_wrong_type"), 1u);
}

// A client flooding valid commands (issue 33): beyond its burst it is refused
// before anything is parsed, counted, told why; the refill lets it send again
// at the rate; another client's commands are untouched meanwhile.  At the
// defaults (2/s, bursts of 10) 64 clients stay inside a daemon's budget.
TEST_F(HubClockTest, AClientFloodingCommandsIsHeldToItsRateAndOthersAreNot) {
  Hub hub = makeTimed({""});
  RecClient flood, other;
  hub.addClient(flood);
  hub.addClient(other);
  advertiseAck(hub, flood, 5);
  advertiseAck(hub, other, 6);
  const Json ack = {{"kind", "INPUT_STALE"}, {"level", 0}, {"action", 1}, {"user", "op"}};
  for (int k = 0; k < 100; ++k) hub.onClientBinary(flood, clientMessage(5, ack));
  EXPECT_EQ(pub.size(), 10u);  // the burst
  EXPECT_EQ(hub.counter("commands_rejected_rate"), 90u);
  ASSERT_NE(flood.lastStatus(), nullptr);
  EXPECT_EQ((*flood.lastStatus())["level"], 2);
  EXPECT_NE((*flood.lastStatus())["message"].get<std::string>().find("more than 2 commands a second"), std::string::npos);
  // Garbage costs a token too (refused before it is parsed).
  hub.onClientBinary(flood, clientMessage(5, {{"nonsense", 1}}));
  EXPECT_EQ(hub.counter("commands_rejected_rate"), 91u);
  EXPECT_EQ(hub.counter("commands_rejected_invalid"), 0u);
  // The other operator is not held by the flood.
  hub.onClientBinary(other, clientMessage(6, ack));
  EXPECT_EQ(pub.size(), 11u);
  // One second later: two more (the rate), then refused again; a clock
  // stepping back gives nothing.
  advance(1.0);
  for (int k = 0; k < 5; ++k) hub.onClientBinary(flood, clientMessage(5, ack));
  EXPECT_EQ(pub.size(), 13u);
  now_ns -= 10'000'000'000ULL;
  hub.onClientBinary(flood, clientMessage(5, ack));
  EXPECT_EQ(pub.size(), 13u);
  EXPECT_EQ(hub.counter("commands_rejected_rate"), 95u);
}

}  // namespace
}  // namespace hoist::dash
