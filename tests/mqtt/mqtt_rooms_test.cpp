// hoist-mqtt's rooms without a broker (tools/mqtt/src, through
// hoist_mqtt_bridge_private): the shaft directory's discovery rules, the
// journal's replay check, and the one token bucket (hoist/rt/token_bucket.hpp).
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "hoist/mqtt/config.hpp"
#include "hoist/mqtt/sparkplug_metrics.hpp"
#include "hoist/rt/token_bucket.hpp"
#include "replay_check.hpp"
#include "shaft_directory.hpp"

using namespace hoist::mqtt;
using namespace std::chrono_literals;

namespace {

struct Recorder : ShaftDirectory::Events {
  std::vector<std::string> bound_names, forgotten;
  void bound(const Shaft& s) override { bound_names.push_back(s.name); }
  void forgetting(const Shaft& s) override { forgotten.push_back(s.prefix); }
};

/// Feeds `prefix` a daemon's health (instance `id`) until discovery would
/// confirm it: 4 messages over a little more than a second.
void healthStream(ShaftDirectory& dir, const std::string& prefix, std::int64_t id) {
  for (int i = 0; i < 4; ++i) {
    if (const Shaft* s = dir.resolve(prefix)) dir.onHealth(*s, id);
    std::this_thread::sleep_for(350ms);
  }
}

OutMsg out(const std::string& topic, bool retain, bool sparkplug = false) {
  OutMsg m;
  m.topic = topic;
  m.payload = "{}";
  m.qos = 1;
  m.retain = retain;
  m.sparkplug = sparkplug;
  return m;
}

}  // namespace

TEST(MqttTokenBucket, AdmitsTheBurstThenTheRateAndNeverMore) {
  hoist::rt::TokenBucket b(2.0, 10.0);
  EXPECT_TRUE(b.full(0.0));
  int admitted = 0;
  for (int i = 0; i < 100; ++i) admitted += b.take(0.0) ? 1 : 0;
  EXPECT_EQ(admitted, 10);  // the burst
  EXPECT_FALSE(b.take(0.4));  // 0.8 tokens
  EXPECT_TRUE(b.take(0.5));   // 1.0 token at t = 0.5 s (rate 2/s)
  EXPECT_FALSE(b.take(0.5));
  EXPECT_FALSE(b.take(0.2));  // time going backwards adds nothing
  EXPECT_NEAR(b.level(3.0), 5.0, 1e-9);
  EXPECT_FALSE(b.full(3.0));
  EXPECT_TRUE(b.full(5.5));    // refilled to the burst, never above it
  EXPECT_NEAR(b.level(100.0), 10.0, 1e-9);
  // Over 60.25 s of constant demand: burst + floor(rate * 60.25) admitted.
  hoist::rt::TokenBucket c(2.0, 10.0);
  int n = 0;
  for (int ms = 0; ms <= 60250; ms += 10) n += c.take(ms / 1000.0) ? 1 : 0;
  EXPECT_EQ(n, 10 + 120);
}

TEST(MqttShaftNames, ClashesAreRefusedAtStartUp) {
  // The same name, a tree inside another's (N20), and, with Sparkplug, the same device id.
  EXPECT_NE(shaftNameClash("north", "north", false), "");
  EXPECT_NE(shaftNameClash("default", "default/alarm", false).find("inside"), std::string::npos);
  EXPECT_NE(shaftNameClash("a/1/x", "a/1", false).find("inside"), std::string::npos);
  EXPECT_EQ(shaftNameClash("a", "ab", false), "");  // hoist/ab/ is not inside hoist/a/
  EXPECT_EQ(shaftNameClash("a/1", "a_1", false), "");  // distinct JSON topics
  EXPECT_NE(shaftNameClash("a/1", "a_1", true).find("device id 'a_1'"), std::string::npos);
  BridgeConfig cfg;
  cfg.channel_prefixes = {"a/1/", "a_1/"};
  EXPECT_NO_THROW(cfg.validate());
  cfg.sparkplug = true;
  cfg.sp_group_id = "g";
  cfg.sp_edge_node_id = "e";
  try {
    cfg.validate();
    ADD_FAILURE() << "a/1/ and a_1/ accepted in Sparkplug mode";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("bridge.channel_prefixes"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("a_1"), std::string::npos) << e.what();
  }
  cfg.sparkplug = false;
  cfg.channel_prefixes = {"", "default/alarm/"};
  EXPECT_THROW(cfg.validate(), std::exception);
}

// N20: a forged stream under default/alarm/ never makes the bridge publish
// inside hoist/default/ (the shaft bound first keeps its tree).
TEST(MqttShaftDirectory, DiscoveryNeverBindsInsideAnotherShaftsTree) {
  BridgeConfig cfg;  // discovery: no channel_prefixes
  LogBudget log;
  Recorder rec;
  ShaftDirectory dir(cfg, log, rec);
  dir.addConfigured();
  healthStream(dir, "", 11);
  ASSERT_EQ(rec.bound_names, (std::vector<std::string>{"default"}));
  healthStream(dir, "default/alarm/", 66);
  healthStream(dir, "default/", 67);  // "default" again, another prefix: a rival, not bound
  EXPECT_EQ(rec.bound_names, (std::vector<std::string>{"default"}));
  const Shaft* forged = dir.resolve("default/alarm/");
  ASSERT_NE(forged, nullptr);
  EXPECT_TRUE(forged->refused);
  EXPECT_FALSE(forged->bound);
}

TEST(MqttShaftDirectory, SparkplugDeviceIdCollisionIsNotDiscovered) {
  BridgeConfig cfg;
  cfg.sparkplug = true;
  LogBudget log;
  Recorder rec;
  ShaftDirectory dir(cfg, log, rec);
  healthStream(dir, "a/1/", 5);
  healthStream(dir, "a_1/", 6);
  EXPECT_EQ(rec.bound_names, (std::vector<std::string>{"a/1"}));
}

// Issue 33: a journal record is replayed only if the bridge would publish it now.
TEST(MqttReplayCheck, OnlyTheBridgesOwnDataTopicsWithTheirRetainFlag) {
  BridgeConfig cfg;
  cfg.channel_prefixes = {"north/"};
  LogBudget log;
  Recorder rec;
  ShaftDirectory dir(cfg, log, rec);
  dir.addConfigured();
  const std::string health = "hoist/_bridge/me/health";
  auto ok = [&](const OutMsg& m) { return replayRefusal(m, cfg, dir, health); };
  for (const char* t : {"hoist/north/cage", "hoist/north/health", "hoist/north/forecast", "hoist/north/estimate",
                        "hoist/north/cmd/result"})
    EXPECT_EQ(ok(out(t, false)), "") << t;
  EXPECT_EQ(ok(out("hoist/north/alarm/CAGE_POS_Y", true)), "");
  EXPECT_EQ(ok(out(health, false)), "");
  // Refused: a command topic, STATE, $SYS, another tree, wrong retain flags, bad kinds, Sparkplug in JSON mode.
  for (const auto& m : {out("hoist/north/cmd/ack", false), out("spBv1.0/STATE/scada", true),
                        out("$SYS/broker/x", false), out("hoist/south/cage", false), out("hoist/north/cage", true),
                        out("hoist/north/alarm/CAGE_POS_Y", false), out("hoist/north/alarm/x+y", true),
                        out("hoist/north/alarm/", true), out(health, true), out("hoist/_bridge/me/status", true),
                        out("hoist/north/cage", false, true)})
    EXPECT_NE(ok(m), "") << m.topic << " retain " << m.retain;
  OutMsg qos2 = out("hoist/north/cage", false);
  qos2.qos = 2;
  EXPECT_NE(ok(qos2), "");
  // Sparkplug: DDATA of the shafts and NDATA, unretained, Sparkplug payloads.
  cfg.sparkplug = true;
  cfg.sp_group_id = "g";
  cfg.sp_edge_node_id = "e";
  EXPECT_EQ(ok(out("spBv1.0/g/DDATA/e/north", false, true)), "");
  EXPECT_EQ(ok(out("spBv1.0/g/NDATA/e", false, true)), "");
  EXPECT_NE(ok(out("spBv1.0/g/DDATA/e/south", false, true)), "");
  EXPECT_NE(ok(out("spBv1.0/g/DCMD/e/north", false, true)), "");
  EXPECT_NE(ok(out("spBv1.0/STATE/scada", false, true)), "");
  EXPECT_NE(ok(out("spBv1.0/g/DDATA/e/north", true, true)), "");
  EXPECT_NE(ok(out("hoist/north/cage", false)), "");
}
