// hoist-mqtt's pure parts: configuration, broker URL, shaft names, the bounded
// outgoing buffer and the command parser (no sockets).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "hoist/io/error.hpp"
#include "hoist/mqtt/command.hpp"
#include "hoist/mqtt/config.hpp"
#include "hoist/mqtt/outbox.hpp"
#include "hoist/contract/alarm_command.hpp"

using namespace hoist::mqtt;

namespace {

/// The ConfigError message of applying `toml`, or "" if accepted.
std::string configError(const std::string& toml) {
  BridgeConfig c;
  try {
    applyBridgeToml(toml, "bridge.toml", c);
  } catch (const hoist::io::ConfigError& e) {
    return e.what();
  }
  return "";
}

CommandResult parse(const std::string& s, std::size_t max = 1024) {
  return parseAckCommand(s.data(), s.size(), max, 1234567);
}

}  // namespace

TEST(MqttConfig, BrokerUrls) {
  auto u = parseBrokerUrl("mqtt://127.0.0.1:1884");
  EXPECT_FALSE(u.tls);
  EXPECT_EQ(u.host, "127.0.0.1");
  EXPECT_EQ(u.port, 1884);
  u = parseBrokerUrl("mqtts://broker.example.com");
  EXPECT_TRUE(u.tls);
  EXPECT_EQ(u.port, 8883);
  EXPECT_EQ(parseBrokerUrl("mqtt://localhost").port, 1883);
  u = parseBrokerUrl("mqtt://[::1]:1900");
  EXPECT_EQ(u.host, "::1");
  EXPECT_EQ(u.port, 1900);
  for (const char* bad : {"tcp://x:1", "mqtt://", "mqtt://:1883", "mqtt://h:0", "mqtt://h:65536", "mqtt://h:12a",
                          "mqtt://user@h:1", "mqtt://h:1/path", "mqtt://[::1", "mqtt://h:"})
    EXPECT_THROW(parseBrokerUrl(bad), std::invalid_argument) << bad;
}

TEST(MqttConfig, ShaftNames) {
  EXPECT_EQ(shaftName(""), "default");
  EXPECT_EQ(shaftName("north/"), "north");
  EXPECT_EQ(shaftName("N1_"), "N1");
  EXPECT_EQ(shaftName("site.a-"), "site.a");
  EXPECT_EQ(shaftName("mine/shaft2/"), "mine/shaft2");
  EXPECT_EQ(shaftName("x"), "x");
  EXPECT_TRUE(validChannelPrefix(""));
  EXPECT_TRUE(validChannelPrefix("north/"));
  EXPECT_FALSE(validChannelPrefix("a+b/"));    // MQTT wildcard
  EXPECT_FALSE(validChannelPrefix("a#/"));
  EXPECT_FALSE(validChannelPrefix("//"));      // empty topic level
  EXPECT_FALSE(validChannelPrefix("_bridge/"));  // reserved for the bridge's own topics
  EXPECT_FALSE(validChannelPrefix(std::string(65, 'a')));
}

TEST(MqttConfig, AcceptsAFullFile) {
  const std::string key = std::filesystem::temp_directory_path() / "hoist_mqtt_unit_pw";
  std::ofstream(key) << "s3cret\n";
  BridgeConfig c;
  applyBridgeToml(R"(
[broker]
url = "mqtt://10.0.0.5:1884"
client_id = "bridge-1"
keepalive = 20
username = "twin"
password_file = ")" + key + R"("
reconnect_min = 0.2
reconnect_max = 5
[bridge]
channel_prefixes = ["north/", "south/"]
commands = false
cage_rate = 2.5
health_period = 1
[buffer]
max_messages = 50
max_alarm_events = 500
)",
                  "bridge.toml", c);
  EXPECT_EQ(c.url, "mqtt://10.0.0.5:1884");
  EXPECT_EQ(c.client_id, "bridge-1");
  EXPECT_EQ(c.keepalive, 20);
  EXPECT_EQ(c.channel_prefixes.size(), 2u);
  EXPECT_FALSE(c.commands);
  EXPECT_DOUBLE_EQ(c.cage_rate, 2.5);
  EXPECT_EQ(c.max_messages, 50);
  EXPECT_EQ(resolvePassword(c, "bridge.toml"), "s3cret");
  std::filesystem::remove(key);
}

TEST(MqttConfig, PasswordFromEnvironment) {
  BridgeConfig c;
  c.username = "u";
  c.password_env = "HOIST_MQTT_UNIT_TEST_PW";
  ::setenv("HOIST_MQTT_UNIT_TEST_PW", "from-env", 1);
  EXPECT_EQ(resolvePassword(c, "x"), "from-env");
  ::unsetenv("HOIST_MQTT_UNIT_TEST_PW");
  EXPECT_EQ(resolvePassword(c, "x"), "");
  c.password = "inline";
  EXPECT_EQ(resolvePassword(c, "x"), "inline");
}

TEST(MqttConfig, ErrorsNameFileLineAndKey) {
  struct Case {
    const char* toml;
    const char* expect;  // substring of the message
  };
  const Case cases[] = {
      {"[broker]\nurl = \"http://x:1\"\n", "bridge.toml:2: broker.url: must start with mqtt://"},
      {"[broker]\nurl = 5\n", "bridge.toml:2: broker.url: must be a string"},
      {"[broker]\nurll = \"mqtt://x\"\n", "bridge.toml:2: broker.urll: unknown key (did you mean 'url'?)"},
      {"[brokr]\nurl = \"mqtt://x\"\n", "bridge.toml:1: brokr: unknown section (did you mean 'broker'?)"},
      {"url = \"mqtt://x\"\n", "url: key outside a section"},
      {"[broker]\nkeepalive = 1\n", "bridge.toml:2: broker.keepalive: must be in [5, 3600]"},
      {"[broker]\nkeepalive = 30.5\n", "broker.keepalive: must be an integer"},
      {"[broker]\npassword = \"x\"\n", "broker.password: a password needs broker.username"},
      {"[broker]\nusername = \"u\"\npassword_file = \"/nonexistent/pw\"\n",
       "bridge.toml:3: broker.password_file: cannot read '/nonexistent/pw'"},
      {"[broker]\nreconnect_min = 5\nreconnect_max = 1\n", "broker.reconnect_max: must be in [5, 3600]"},
      {"[broker]\nclient_id = \"a b\"\n", "broker.client_id: may contain only"},
      {"[tls]\nca_file = \"/nonexistent/ca.crt\"\n", "bridge.toml:2: tls.ca_file: cannot read"},
      {"[broker]\nurl = \"mqtts://x\"\n", "tls.ca_file: TLS needs the broker's CA"},
      {"[tls]\nversion = \"ssl3\"\n", "tls.version: must be \"tlsv1.2\" or \"tlsv1.3\""},
      {"[bridge]\ncage_rate = 0\n", "bridge.toml:2: bridge.cage_rate: must be in (0, 1000]"},
      {"[bridge]\ncage_rate = nan\n", "bridge.cage_rate: must be finite"},
      {"[bridge]\ncage_rate = \"fast\"\n", "bridge.cage_rate: must be a number"},
      {"[bridge]\nchannel_prefixes = \"north/\"\n", "bridge.channel_prefixes: must be an array of strings"},
      {"[bridge]\nchannel_prefixes = [\"a+/\"]\n", "bridge.channel_prefixes: 'a+/': may contain only"},
      {"[bridge]\nchannel_prefixes = [\"north/\", \"north_\"]\n", "give the same shaft name 'north'"},
      {"[bridge]\ncommands = \"yes\"\n", "bridge.commands: must be true or false"},
      {"[bridge]\nmax_command_bytes = 10\n", "bridge.max_command_bytes: must be in [64, 65536]"},
      {"[buffer]\nmax_messages = 0\n", "bridge.toml:2: buffer.max_messages: must be in [1, 1000000]"},
      {"[buffer]\nmax_alarm_events = -3\n", "buffer.max_alarm_events"},
      {"[broker\n", "bridge.toml:1: TOML syntax error"},
  };
  for (const auto& c : cases) {
    const std::string msg = configError(c.toml);
    EXPECT_NE(msg.find(c.expect), std::string::npos) << "config:\n" << c.toml << "\nmessage: " << msg;
  }
  EXPECT_EQ(configError(""), "");
}

TEST(MqttConfig, ExampleFileIsValid) {
  const BridgeConfig c = loadBridgeConfig(HOIST_MQTT_EXAMPLE_CONFIG);
  EXPECT_EQ(c.url, BridgeConfig{}.url);
  EXPECT_EQ(c.cage_rate, BridgeConfig{}.cage_rate);
  EXPECT_EQ(c.max_messages, BridgeConfig{}.max_messages);
}

TEST(MqttOutbox, DropsOldestCageStatesFirstNeverAlarms) {
  Outbox box(3, 100);
  auto cage = [](int i) { return OutMsg{"c", std::to_string(i), 0, false, MsgClass::Cage}; };
  box.push(cage(1));
  box.push({"a", "A1", 1, true, MsgClass::Alarm});
  box.push({"h", "H1", 0, false, MsgClass::Health});
  box.push(cage(2));
  box.push(cage(3));  // full (3 cage/health): drops cage 1
  box.push(cage(4));  // drops cage 2
  box.push({"a", "A2", 1, true, MsgClass::Alarm});  // alarms have their own bound
  EXPECT_EQ(box.droppedCage(), 2u);
  EXPECT_EQ(box.droppedAlarm(), 0u);
  std::string order;
  while (!box.empty()) {
    order += box.front().payload + " ";
    box.pop();
  }
  EXPECT_EQ(order, "A1 H1 3 4 A2 ");  // order kept, both alarms there
  // With no cage state left, the oldest health message goes.
  Outbox h(2, 100);
  h.push({"h", "H1", 0, false, MsgClass::Health});
  h.push({"h", "H2", 0, false, MsgClass::Health});
  h.push({"h", "H3", 0, false, MsgClass::Health});
  EXPECT_EQ(h.droppedHealth(), 1u);
  EXPECT_EQ(h.front().payload, "H2");
  // A flood of cage states never displaces an alarm transition.
  Outbox f(10, 5);
  f.push({"a", "A", 1, true, MsgClass::Alarm});
  for (int i = 0; i < 1000; ++i) f.push(cage(i));
  EXPECT_EQ(f.size(), 11u);
  EXPECT_EQ(f.queuedAlarms(), 1u);
  EXPECT_EQ(f.front().payload, "A");
  // Past their own (large) bound alarm transitions are dropped oldest first, and counted.
  for (int i = 0; i < 7; ++i) f.push({"a", std::string("B") + std::to_string(i), 1, true, MsgClass::Alarm});
  EXPECT_EQ(f.queuedAlarms(), 5u);
  EXPECT_EQ(f.droppedAlarm(), 3u);
}

TEST(MqttCommand, ValidCommands) {
  auto r = parse(R"({"kind":"CAGE_POS_Y","level":1,"action":1,"user":"scada-1"})");
  ASSERT_EQ(r.reject, CommandReject::None) << r.detail;
  EXPECT_EQ(r.ack.kind, "CAGE_POS_Y");
  EXPECT_EQ(r.ack.level, 1);
  EXPECT_EQ(r.ack.action, +hoist::alarm_ack_t::ACTION_ACK);
  EXPECT_EQ(r.ack.user, "scada-1");
  EXPECT_EQ(r.ack.utime, 1234567);  // the bridge's clock when absent
  r = parse(R"({"kind":"*","level":0,"action":2,"shelve_duration":600})");
  ASSERT_EQ(r.reject, CommandReject::None) << r.detail;
  EXPECT_EQ(r.ack.shelve_duration, 600.0);
  EXPECT_EQ(r.ack.user, "mqtt");
  r = parse(R"({"utime":42,"kind":"","level":2,"action":3,"shelve_duration":0,"user":"x"})");
  ASSERT_EQ(r.reject, CommandReject::None) << r.detail;
  EXPECT_EQ(r.ack.utime, 42);
}

TEST(MqttCommand, RejectsBadPayloadsByReason) {
  EXPECT_EQ(parse(std::string(2000, ' ')).reject, CommandReject::Oversized);
  EXPECT_EQ(parse("ack CAGE_POS_Y").reject, CommandReject::NotJson);
  EXPECT_EQ(parse("").reject, CommandReject::NotJson);
  EXPECT_EQ(parse("{\"kind\":\"\xff\xfe\",\"level\":0,\"action\":1}").reject, CommandReject::NotJson);  // not UTF-8
  EXPECT_EQ(parse(std::string("{\"kind\0", 7)).reject, CommandReject::NotJson);
  EXPECT_EQ(parse("[1,2]").reject, CommandReject::NotObject);
  EXPECT_EQ(parse("\"ack\"").reject, CommandReject::NotObject);
  EXPECT_EQ(parse(R"({"kind":"CAGE_POS_Y","level":0})").reject, CommandReject::BadFields);  // no action
  EXPECT_EQ(parse(R"({"kind":"CAGE_POS_Y","level":0,"action":1,"extra":1})").reject, CommandReject::BadFields);
  EXPECT_EQ(parse(R"({"kind":7,"level":0,"action":1})").reject, CommandReject::BadFields);
  EXPECT_EQ(parse(R"({"kind":"CAGE_POS_Y","level":0,"action":1000})").reject, CommandReject::BadFields);  // not int8
  EXPECT_EQ(parse(R"({"kind":"CAGE_POS_Y","level":0,"action":"ack"})").reject, CommandReject::BadFields);
  EXPECT_EQ(parse(R"({"kind":"NOPE","level":0,"action":1})").reject, CommandReject::UnknownKind);
  EXPECT_EQ(parse(R"({"kind":"cage_pos_y","level":0,"action":1})").reject, CommandReject::UnknownKind);
  EXPECT_EQ(parse(R"({"kind":"CAGE_POS_Y","level":3,"action":1})").reject, CommandReject::BadLevel);
  EXPECT_EQ(parse(R"({"kind":"CAGE_POS_Y","level":0,"action":9})").reject, CommandReject::BadAction);
  EXPECT_EQ(parse(R"({"kind":"CAGE_POS_Y","level":0,"action":2})").reject, CommandReject::BadShelveDuration);
  EXPECT_EQ(parse(R"({"kind":"CAGE_POS_Y","level":0,"action":2,"shelve_duration":-5})").reject,
            CommandReject::BadShelveDuration);
  // The log detail never carries the raw payload.
  const auto r = parse("{\"kind\":\"EVIL\x1b[31m\",\"level\":0,\"action\":1}");
  EXPECT_EQ(r.detail.find('\x1b'), std::string::npos);
}

// The live calibration (alarm_ack_t.ACTION_CALIBRATE, issue 30) through the
// bridge: the daemon's own validation (hoist::contract), answered with its
// reason when refused; kind and level are ignored as the daemon ignores them.
TEST(MqttCommand, CalibrateIsValidatedAsTheDaemonDoes) {
  auto r = parse(R"({"kind":"","level":0,"action":5,"known_fa":1000,"known_b":0.5,"calibrate_duration":30,"user":"eng"})");
  ASSERT_EQ(r.reject, CommandReject::None) << r.detail;
  EXPECT_EQ(r.ack.action, +hoist::alarm_ack_t::ACTION_CALIBRATE);
  EXPECT_EQ(r.ack.known_fa, 1000.0);
  EXPECT_EQ(r.ack.known_b, 0.5);
  EXPECT_EQ(r.ack.calibrate_duration, 30.0);
  EXPECT_EQ(parse(R"({"kind":"","level":0,"action":5,"known_fa":0,"known_b":0,"calibrate_duration":600})").reject,
            CommandReject::None) << "the empty conveyance, the longest duration";
  for (const char* bad : {R"({"kind":"","level":0,"action":5})",  // no load, no duration
                          R"({"kind":"","level":0,"action":5,"known_fa":1000,"known_b":0.5,"calibrate_duration":0})",
                          R"({"kind":"","level":0,"action":5,"known_fa":1000,"known_b":0.5,"calibrate_duration":601})",
                          R"({"kind":"","level":0,"action":5,"known_fa":-1,"known_b":0.5,"calibrate_duration":30})",
                          R"({"kind":"","level":0,"action":5,"known_fa":2e7,"known_b":0.5,"calibrate_duration":30})",
                          R"({"kind":"","level":0,"action":5,"known_fa":1000,"known_b":101,"calibrate_duration":30})"}) {
    const auto b = parse(bad);
    EXPECT_EQ(b.reject, CommandReject::BadCalibration) << bad;
    EXPECT_NE(b.detail.find("calibrate needs"), std::string::npos) << b.detail;
  }
  EXPECT_STREQ(toString(CommandReject::BadCalibration), "bad_calibration");
  // The same verdicts as the daemon's.
  hoist::contract::AlarmCommand c;
  EXPECT_EQ(hoist::contract::validateAlarmCommand("", 0, 5, 0.0, 1000.0, 0.5, 30.0, c),
            hoist::contract::CommandError::None);
  EXPECT_EQ(hoist::contract::validateAlarmCommand("", 0, 5, 0.0, 1000.0, 0.5, 0.0, c),
            hoist::contract::CommandError::BadCalibration);
  // Adopting a guide-rope preload is a control-room command (hoist-alarm-ack),
  // refused over MQTT with or without its field.
  for (const char* adopt : {R"({"kind":"","level":0,"action":6,"preload_scale":0.8,"user":"eng"})",
                            R"({"kind":"","level":0,"action":6,"user":"eng"})"}) {
    const auto a = parse(adopt);
    EXPECT_EQ(a.reject, CommandReject::BadAction) << adopt;
    EXPECT_NE(a.detail.find("hoist-alarm-ack --adopt-preload"), std::string::npos) << a.detail;
  }
}

TEST(MqttCommand, SameValidationAsTheDaemon) {
  // The bridge and hoist-twind share hoist::contract::validateAlarmCommand.
  hoist::contract::AlarmCommand c;
  EXPECT_EQ(hoist::contract::validateAlarmCommand("GUIDE_ROPE", 2, 2, 30.0, c), hoist::contract::CommandError::None);
  EXPECT_EQ(c.action, hoist::contract::AlarmAction::Shelve);
  ASSERT_TRUE(c.kind.has_value());
  EXPECT_EQ(*c.kind, hoist::contract::AlarmKind::GuideRope);
  EXPECT_EQ(c.level, hoist::contract::AlarmLevel::Critical);
  EXPECT_EQ(hoist::contract::validateAlarmCommand("*", 0, 1, 0.0, c), hoist::contract::CommandError::None);
  EXPECT_FALSE(c.kind.has_value());
  EXPECT_EQ(hoist::contract::validateAlarmCommand("X", 0, 1, 0.0, c), hoist::contract::CommandError::UnknownKind);
  EXPECT_EQ(hoist::contract::validateAlarmCommand("", -1, 1, 0.0, c), hoist::contract::CommandError::BadLevel);
  EXPECT_EQ(hoist::contract::validateAlarmCommand("", 0, 0, 0.0, c), hoist::contract::CommandError::BadAction);
  EXPECT_EQ(hoist::contract::validateAlarmCommand("", 0, 2, std::nan(""), c),
            hoist::contract::CommandError::BadShelveDuration);
  for (int i = 0; i < hoist::contract::kCommandErrors; ++i)
    EXPECT_STRNE(hoist::contract::toString(static_cast<hoist::contract::CommandError>(i)), "?");
  for (int i = 0; i < kCommandRejects; ++i) EXPECT_STRNE(toString(static_cast<CommandReject>(i)), "?");
}

TEST(MqttCommand, RefusesDuplicateKeysBadUsersAndStaleUtimes) {
  // A key given twice (nlohmann would keep the last): refused, wherever it is.
  EXPECT_EQ(parse(R"({"kind":"CAGE_POS_Y","level":0,"action":1,"kind":"*"})").reject, CommandReject::DuplicateKey);
  EXPECT_EQ(parse(R"({"action":3,"kind":"*","level":0,"action":2,"shelve_duration":9})").reject,
            CommandReject::DuplicateKey);
  EXPECT_EQ(parse(R"({"kind":"*","level":0,"action":1,"user":"a","user":"b"})").reject, CommandReject::DuplicateKey);
  // The same key in two objects is not a duplicate (then refused for its shape).
  EXPECT_EQ(parse(R"({"kind":"*","level":0,"action":1,"x":{"kind":1}})").reject, CommandReject::BadFields);
  // hoist-dash's rule for `user`, plus the C1 controls.
  for (const char* u : {R"("")", R"("op\u001b[31m")", R"("op\nAUDIT")", R"("op\t")",
                        R"("op\u007f")", R"("op\u0085")", R"("op\u009b")"}) {
    const auto r = parse(std::string(R"({"kind":"*","level":0,"action":1,"user":)") + u + "}");
    EXPECT_EQ(r.reject, CommandReject::BadUser) << u;
    EXPECT_EQ(r.detail.find('\x1b'), std::string::npos);
  }
  EXPECT_EQ(parse(R"({"kind":"*","level":0,"action":1,"user":")" + std::string(65, 'a') + "\"}").reject,
            CommandReject::BadUser);
  EXPECT_EQ(parse(R"({"kind":"*","level":0,"action":1,"user":")" + std::string(64, 'a') + "\"}").reject,
            CommandReject::None);
  EXPECT_EQ(parse(R"({"kind":"*","level":0,"action":1,"user":"Jürgen Åström"})").reject, CommandReject::None);
  EXPECT_EQ(checkUser("op1"), "");
  EXPECT_NE(checkUser("op\x1b"), "");
  // A client's utime must be near the bridge's clock when max_age is set.
  const std::string cmd = R"({"kind":"*","level":0,"action":1,"utime":)";
  const std::int64_t now = 1'700'000'000'000'000;
  auto at = [&](std::int64_t utime, double max_age) {
    const std::string s = cmd + std::to_string(utime) + "}";
    return parseAckCommand(s.data(), s.size(), 1024, now, max_age).reject;
  };
  EXPECT_EQ(at(now - 5'000'000, 60.0), CommandReject::None);
  EXPECT_EQ(at(now - 61'000'000, 60.0), CommandReject::StaleUtime);
  EXPECT_EQ(at(now + 61'000'000, 60.0), CommandReject::StaleUtime);
  EXPECT_EQ(at(now - 3'600'000'000, 0.0), CommandReject::None);  // 0 = no check
  const std::string no_utime = R"({"kind":"*","level":0,"action":1})";
  EXPECT_EQ(parseAckCommand(no_utime.data(), no_utime.size(), 1024, now, 60.0).reject, CommandReject::None);
}

TEST(MqttConfig, CommandRateKeys) {
  EXPECT_EQ(configError("[bridge]\ncommand_rate = 1.5\ncommand_burst = 3\nmax_command_age = 0\n"), "");
  EXPECT_NE(configError("[bridge]\ncommand_rate = 0\n").find("bridge.command_rate"), std::string::npos);
  EXPECT_NE(configError("[bridge]\ncommand_burst = 0\n").find("bridge.command_burst"), std::string::npos);
  EXPECT_NE(configError("[bridge]\nmax_command_age = -1\n").find("bridge.max_command_age"), std::string::npos);
}

TEST(MqttConfig, SystemdCredentialsReplaceTheFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "hoist_mqtt_creds_unit";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  BridgeConfig c;
  c.password = "inline";
  c.password_file = "/etc/hoist-twin/mqtt/site1.password";
  c.key_file = "/etc/hoist-twin/mqtt/site1.key";
  ::unsetenv("CREDENTIALS_DIRECTORY");
  EXPECT_TRUE(applyCredentials(c).empty());
  EXPECT_EQ(c.password_file, "/etc/hoist-twin/mqtt/site1.password");
  // Empty credentials (the unit's SetCredential= default): nothing changes.
  std::ofstream(dir / "mqtt-password") << "\n";
  std::ofstream(dir / "mqtt-tls-key").close();
  ::setenv("CREDENTIALS_DIRECTORY", dir.c_str(), 1);
  EXPECT_TRUE(applyCredentials(c).empty());
  EXPECT_EQ(c.key_file, "/etc/hoist-twin/mqtt/site1.key");
  std::ofstream(dir / "mqtt-password") << "s3cret\n";
  std::ofstream(dir / "mqtt-tls-key") << "-----BEGIN PRIVATE KEY-----\n";
  EXPECT_EQ(applyCredentials(c), (std::vector<std::string>{"mqtt-password", "mqtt-tls-key"}));
  EXPECT_EQ(c.password_file, (dir / "mqtt-password").string());
  EXPECT_EQ(c.password, "");
  EXPECT_EQ(c.key_file, (dir / "mqtt-tls-key").string());
  c.username = "hoist";
  EXPECT_EQ(resolvePassword(c, "x"), "s3cret");
  ::unsetenv("CREDENTIALS_DIRECTORY");
  std::filesystem::remove_all(dir);
}

// ---- Sparkplug B mode ----------------------------------------------------------

#include "hoist/mqtt/sparkplug.hpp"
#include "hoist/mqtt/sparkplug_node.hpp"

namespace sp = hoist::mqtt::sparkplug;

TEST(MqttConfig, SparkplugKeys) {
  BridgeConfig c;
  applyBridgeToml("[sparkplug]\nenabled = true\ngroup_id = \"Mine A\"\nedge_node_id = \"edge-1\"\n"
                  "primary_host_id = \"scada\"\ndeadband = 0.01\n[sparkplug.deadbands]\n\"Cage/Length\" = 0.5\n",
                  "bridge.toml", c);
  EXPECT_TRUE(c.sparkplug);
  EXPECT_EQ(c.sp_group_id, "Mine A");
  EXPECT_EQ(c.sp_edge_node_id, "edge-1");
  EXPECT_EQ(c.sp_primary_host_id, "scada");
  EXPECT_DOUBLE_EQ(c.sp_deadband, 0.01);
  EXPECT_DOUBLE_EQ(c.sp_deadbands.at("Cage/Length"), 0.5);
  const std::pair<const char*, const char*> cases[] = {
      {"[sparkplug]\nenabled = true\nedge_node_id = \"e\"\n", "bridge.toml: sparkplug.group_id: Sparkplug mode needs a group id"},
      {"[sparkplug]\nenabled = true\ngroup_id = \"g\"\n", "sparkplug.edge_node_id: Sparkplug mode needs an edge node id"},
      {"[sparkplug]\ngroup_id = \"a/b\"\n", "bridge.toml:2: sparkplug.group_id: 'a/b': may contain only"},
      {"[sparkplug]\nprimary_host_id = \"h#\"\n", "sparkplug.primary_host_id"},
      {"[sparkplug]\ndeadband = -1\n", "bridge.toml:2: sparkplug.deadband: must be in [0"},
      {"[sparkplug.deadbands]\n\"Cage/Lenght\" = 1\n", "sparkplug.deadbands: 'Cage/Lenght' is not a device metric (did you mean 'Cage/Length'?)"},
      {"[sparkplug.deadbands]\n\"Cage/Degraded\" = 1\n", "is not numeric"},
      {"[sparkplug.deadbands]\n\"Cage/Length\" = \"x\"\n", "sparkplug.deadbands.Cage/Length: must be a number"},
      {"[sparkplug]\nenable = true\n", "sparkplug.enable: unknown key (did you mean 'enabled'?)"},
      {"[sparkplg]\n", "unknown section (did you mean 'sparkplug'?)"},
  };
  for (const auto& [toml, expect] : cases) {
    const std::string msg = configError(toml);
    EXPECT_NE(msg.find(expect), std::string::npos) << toml << "\nmessage: " << msg;
  }
  BridgeConfig o;
  applySparkplugOption("Mine/Edge1", o);
  EXPECT_TRUE(o.sparkplug);
  EXPECT_EQ(o.sp_group_id, "Mine");
  EXPECT_EQ(o.sp_edge_node_id, "Edge1");
  for (const char* bad : {"Mine", "a/b/c", "/e", "g/", "g+/e"}) EXPECT_THROW(applySparkplugOption(bad, o), std::invalid_argument) << bad;
}

TEST(MqttSparkplugCore, PayloadRoundTripAndStamp) {
  if (!sp::available()) GTEST_SKIP() << "built without nanopb";
  sp::DeviceMetrics d(1000, 0.0, {});
  hoist::cage_state_t c{};
  c.utime = 1'700'000'000'123'000;
  c.seq = 42;
  c.l = 123.25;
  c.alarm_level = -1;  // a negative Int32 survives the uint32 field
  c.degraded = true;
  d.onCage(c);
  const sp::Payload birth = d.birth(5);
  const std::string bytes = sp::encode(birth);
  std::string why;
  auto back = sp::decode(bytes.data(), bytes.size(), 1 << 20, why);
  ASSERT_TRUE(back) << why;
  ASSERT_EQ(back->metrics.size(), sp::deviceMetrics().size());
  std::map<std::string, sp::Metric> by;
  for (const auto& m : back->metrics) by[m.name] = m;
  EXPECT_EQ(by["Cage/Length"].value.d, 123.25);
  EXPECT_EQ(by["Cage/Length"].units, "m");
  EXPECT_EQ(by["Cage/Length"].timestamp_ms, 1'700'000'000'123u);
  EXPECT_EQ(by["Cage/Seq"].value.i, 42);
  EXPECT_EQ(by["Cage/Alarm Level"].value.i, -1);
  EXPECT_TRUE(by["Cage/Degraded"].value.b);
  EXPECT_TRUE(by["Estimate/Load Force"].value.is_null);
  EXPECT_EQ(by["Cage/Length"].alias, d.aliasOf(2));
  EXPECT_FALSE(back->has_seq && back->seq != 0);
  // stamp(): seq and is_historical set, the rest unchanged.
  const std::string st = sp::stamp(bytes, 200, true);
  auto s2 = sp::decode(st.data(), st.size(), 1 << 20, why);
  ASSERT_TRUE(s2);
  EXPECT_TRUE(s2->has_seq);
  EXPECT_EQ(s2->seq, 200u);
  for (const auto& m : s2->metrics) EXPECT_TRUE(m.is_historical) << m.name;
  EXPECT_EQ(s2->metrics.size(), back->metrics.size());
  // Bad bytes: refused with a reason, never thrown.
  const std::string junk = "\xff\xff\xff\xff\xff";
  EXPECT_FALSE(sp::decode(junk.data(), junk.size(), 1024, why));
  EXPECT_NE(why.find("not a Sparkplug B payload"), std::string::npos);
  EXPECT_FALSE(sp::decode(bytes.data(), bytes.size(), 100, why));
  EXPECT_EQ(why.rfind("oversized", 0), 0u);
  EXPECT_EQ(sp::stamp(junk, 1, true), junk);
}

TEST(MqttSparkplugCore, ReportByExceptionWithDeadband) {
  sp::DeviceMetrics d(2000, 0.0, {{"Cage/Length", 0.5}});
  hoist::cage_state_t c{};
  c.l = 100.0;
  c.v = 1.0;
  d.onCage(c);
  d.birth(1);
  EXPECT_TRUE(d.changes(sp::Source::Cage, 2).metrics.empty()) << "nothing changed since the birth";
  c.l = 100.4;  // within the deadband
  c.v = 1.5;    // no deadband: any change
  d.onCage(c);
  auto p = d.changes(sp::Source::Cage, 3);
  ASSERT_EQ(p.metrics.size(), 1u);
  EXPECT_EQ(p.metrics[0].alias, d.aliasOf(3));  // Cage/Velocity, by alias only
  EXPECT_TRUE(p.metrics[0].name.empty());
  c.l = 100.6;  // 0.6 from the last reported 100.0
  d.onCage(c);
  p = d.changes(sp::Source::Cage, 4);
  ASSERT_EQ(p.metrics.size(), 1u);
  EXPECT_EQ(p.metrics[0].value.d, 100.6);
  EXPECT_TRUE(d.changes(sp::Source::Health, 5).metrics.empty());
  EXPECT_TRUE(d.setAlarm("CAGE_POS_Y", 1, true, false, false, 7));
  EXPECT_FALSE(d.setAlarm("NOT_A_KIND", 1, true, false, false, 7));
  EXPECT_EQ(d.changes(sp::Source::Alarm, 6).metrics.size(), 4u);  // null (born before any alarm) -> values
  EXPECT_TRUE(d.setAlarm("CAGE_POS_Y", 1, true, true, false, 8));  // acknowledged
  p = d.changes(sp::Source::Alarm, 7);
  ASSERT_EQ(p.metrics.size(), 1u);
  EXPECT_TRUE(p.metrics[0].value.b);
}

TEST(MqttSparkplugCore, NodeClassifiesCommands) {
  if (!sp::available()) GTEST_SKIP() << "built without nanopb";
  sp::Node n({"G", "E", "", "v", 0.0, {}});
  n.device("north");
  const auto will1 = n.nextWill();
  EXPECT_EQ(will1.topic, "spBv1.0/G/NDEATH/E");
  EXPECT_EQ(n.bdSeq(), 0);
  n.nextWill();
  EXPECT_EQ(n.bdSeq(), 1);
  const auto births = n.births({}, 1);
  ASSERT_EQ(births.size(), 2u);
  EXPECT_EQ(births[0].topic, "spBv1.0/G/NBIRTH/E");
  EXPECT_EQ(births[1].topic, "spBv1.0/G/DBIRTH/E/north");
  auto cmd = [&](const std::string& topic, std::vector<sp::Metric> ms) {
    sp::Payload p;
    p.metrics = std::move(ms);
    const std::string b = sp::encode(p);
    std::vector<sp::Command> out;
    n.onMessage(topic, b.data(), b.size(), 1024, false, out);
    return out;
  };
  auto metric = [](const std::string& name, sp::DataType t, bool b, double d = 0) {
    sp::Metric m;
    m.name = name;
    m.has_type = true;
    m.type = t;
    m.value.is_null = false;
    m.value.b = b;
    m.value.d = d;
    return m;
  };
  auto r = cmd("spBv1.0/G/DCMD/E/north", {metric("Alarms/CAGE_POS_Y/Ack", sp::DataType::Boolean, true)});
  ASSERT_EQ(r.size(), 1u);
  ASSERT_EQ(r[0].what, sp::Command::What::Alarm);
  // The JSON command the checker of hoist/<shaft>/cmd/ack accepts.
  const CommandResult ok = parseAckCommand(r[0].json.data(), r[0].json.size(), 1024, 1234567);
  EXPECT_EQ(ok.reject, CommandReject::None) << ok.detail;
  EXPECT_EQ(ok.ack.kind, "CAGE_POS_Y");
  EXPECT_EQ(ok.ack.action, +hoist::alarm_ack_t::ACTION_ACK);
  r = cmd("spBv1.0/G/DCMD/E/north", {metric("Alarms/CAGE_POS_Y/Shelve", sp::DataType::Double, false, 60.0)});
  ASSERT_EQ(r[0].what, sp::Command::What::Alarm);
  EXPECT_EQ(parseAckCommand(r[0].json.data(), r[0].json.size(), 1024, 1).ack.shelve_duration, 60.0);
  r = cmd("spBv1.0/G/DCMD/E/north", {metric("Cage/Length", sp::DataType::Double, false, 1.0)});
  EXPECT_EQ(r[0].reject, CommandReject::ReadOnly);
  r = cmd("spBv1.0/G/DCMD/E/south", {metric("Alarms/CAGE_POS_Y/Ack", sp::DataType::Boolean, true)});
  EXPECT_EQ(r[0].reject, CommandReject::UnknownMetric);
  r = cmd("spBv1.0/G/DCMD/E/north", {metric("Alarms/CAGE_POS_Y/Ack", sp::DataType::String, true)});
  EXPECT_EQ(r[0].reject, CommandReject::BadValue);
  r = cmd("spBv1.0/G/NCMD/E", {metric("Node Control/Rebirth", sp::DataType::Boolean, true)});
  EXPECT_EQ(r[0].what, sp::Command::What::Rebirth);
  r = cmd("spBv1.0/G/NCMD/E", {metric("Node Control/Rebirth", sp::DataType::Boolean, false)});
  EXPECT_EQ(r[0].reject, CommandReject::BadValue);
  std::vector<sp::Command> out;
  EXPECT_EQ(n.onMessage("spBv1.0/Other/NCMD/E", "x", 1, 1024, false, out), sp::Node::Inbound::NotOurs);
  const std::string junk = "\x0a";
  n.onMessage("spBv1.0/G/NCMD/E", junk.data(), junk.size(), 1024, false, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].reject, CommandReject::BadPayload);
}

TEST(MqttSparkplugCore, PrimaryHostState) {
  sp::Node n({"G", "E", "scada", "v", 0.0, {}});
  std::vector<sp::Command> out;
  auto state = [&](const std::string& j) { return n.onMessage("spBv1.0/STATE/scada", j.data(), j.size(), 1024, true, out); };
  using In = sp::Node::Inbound;
  EXPECT_EQ(state(R"({"online": true, "timestamp": 1000})"), In::HostOnline);
  EXPECT_TRUE(n.hostOnline());
  EXPECT_EQ(state(R"({"online": false, "timestamp": 999})"), In::StateIgnored) << "older than the online STATE";
  EXPECT_TRUE(n.hostOnline());
  EXPECT_EQ(state(R"({"online": false, "timestamp": 1001})"), In::HostOfflineUnverified) << "not the session's death";
  EXPECT_EQ(state("not json"), In::StateIgnored);
  EXPECT_EQ(state(R"({"online": "yes", "timestamp": 1})"), In::StateIgnored);
  EXPECT_EQ(n.subscriptions().back(), "spBv1.0/STATE/scada");
  EXPECT_EQ(n.stateIgnored(), 3);
  // A forged STATE from the far future is ignored (with the wall clock given),
  // so it cannot make the genuine host's next STATE "older".
  auto stateAt = [&](const std::string& j, std::uint64_t now_ms) {
    return n.onMessage("spBv1.0/STATE/scada", j.data(), j.size(), 1024, true, out, now_ms);
  };
  const std::uint64_t now = 1'800'000'000'000;
  EXPECT_EQ(stateAt(R"({"online": false, "timestamp": 4611686018427387904})", now), In::StateIgnored);
  EXPECT_EQ(stateAt(R"({"online": true, "timestamp": )" + std::to_string(now + sp::Node::kStateFutureMs + 1) + "}", now),
            In::StateIgnored);
  EXPECT_EQ(stateAt(R"({"online": true, "timestamp": )" + std::to_string(now) + "}", now), In::HostOnline)
      << "the genuine host is not locked out";
  EXPECT_EQ(n.stateIgnored(), 5);
}

// Sparkplug 3.0 stamps a host's online STATE and its death with one
// timestamp: an offline stamped otherwise is no death of the session
// followed (counted unverified), and it raises no bar -- the same session's
// online (retained, read again; or republished) brings the host back.
TEST(MqttSparkplugCore, AnOfflineNotStampedLikeTheSessionRaisesNoBar) {
  sp::Node n({"G", "E", "scada", "v", 0.0, {}});
  std::vector<sp::Command> out;
  using In = sp::Node::Inbound;
  auto state = [&](bool online, std::uint64_t ts) {
    const std::string j = std::string(R"({"online": )") + (online ? "true" : "false") + R"(, "timestamp": )" +
                          std::to_string(ts) + "}";
    return n.onMessage("spBv1.0/STATE/scada", j.data(), j.size(), 1024, true, out, 2'000'000);
  };
  EXPECT_EQ(state(false, 500), In::HostOffline) << "no session known yet: an offline is just offline";
  EXPECT_EQ(state(true, 400), In::HostOnline) << "an offline raises no bar, even before a session";
  EXPECT_EQ(state(true, 1000), In::HostOnline);
  EXPECT_EQ(state(false, 1'500'000), In::HostOfflineUnverified) << "a forged offline stamped now";
  EXPECT_FALSE(n.hostOnline()) << "stored as for a death: the bridge cannot tell";
  EXPECT_EQ(state(true, 1000), In::HostOnline) << "the session's own online, read again, brings it back";
  EXPECT_TRUE(n.hostOnline());
  EXPECT_EQ(state(false, 1000), In::HostOffline) << "the session's death: its timestamp";
  EXPECT_EQ(state(true, 1000), In::HostOnline) << "the host republishes its online (it read an offline on its topic)";
  EXPECT_EQ(state(true, 999), In::StateIgnored) << "an earlier session's";
  EXPECT_EQ(state(false, 999), In::StateIgnored) << "an earlier session's death";
  EXPECT_EQ(state(true, 3000), In::HostOnline) << "a new session";
  EXPECT_EQ(state(false, 1000), In::StateIgnored) << "the old session's death, late";
  EXPECT_TRUE(n.hostOnline());
  EXPECT_EQ(n.stateUnverified(), 1);
  EXPECT_EQ(n.stateIgnored(), 3);
}

// A Rebirth request (NCMD) within kRebirthMinMs of the births is held and
// done when the interval has passed; further requests merge into it: a flood
// (one NCMD may carry 150 Rebirth metrics) costs at most two births per
// interval, and a host that missed the births still gets them.
TEST(MqttSparkplugCore, RebirthRequestsAreHeldAndMergedWithinTheInterval) {
  sp::Node n({"G", "E", "", "v", 0.0, {}});
  n.device("north");
  const std::uint64_t t0 = 1'800'000'000'000, gap = sp::Node::kRebirthMinMs;
  EXPECT_TRUE(n.acceptRebirth(t0)) << "before any birth";
  ASSERT_EQ(n.births({}, t0).size(), 2u);
  int at_once = 0;
  for (int i = 0; i < 150; ++i)
    if (n.acceptRebirth(t0 + 10)) ++at_once;  // 150 Rebirth metrics in one NCMD, just after the births
  EXPECT_EQ(at_once, 0);
  EXPECT_EQ(n.rebirthsCoalesced(), 150);
  EXPECT_FALSE(n.rebirthDue(t0 + gap - 1));
  EXPECT_TRUE(n.rebirthDue(t0 + gap)) << "the held request is done once the interval has passed";
  EXPECT_FALSE(n.rebirthDue(t0 + gap + 1)) << "... once";
  n.births({}, t0 + gap);
  EXPECT_FALSE(n.acceptRebirth(t0 + gap + 1)) << "the new births restart the interval";
  n.births({}, t0 + gap + 5);  // births for another reason (a new session) answer the held request
  EXPECT_FALSE(n.rebirthDue(t0 + 3 * gap));
  EXPECT_TRUE(n.acceptRebirth(t0 + 3 * gap));
  EXPECT_EQ(n.rebirthsCoalesced(), 151);
}
