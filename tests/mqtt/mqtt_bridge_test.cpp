// hoist-mqtt against a real mosquitto broker (started here on a free loopback
// port with a generated configuration), a real hoist-twind (demo.toml's tight
// gaps: the paper's cage at rest at the top raises CAGE_POS_Y WARNING) fed by
// hoist-replay, over LCM on loopback multicast (ttl=0, ports 7931-7934).
// The MQTT side is checked with libmosquitto as a client: payloads, retained
// flags, a late subscriber, commands, broker restarts.
#include <arpa/inet.h>
#include <mosquitto.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <atomic>
#include <mutex>
#include <nlohmann/json.hpp>
#include <regex>

#include "lcm_fixtures.hpp"
#include "tcp.hpp"
#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/health_t.hpp"

using namespace hoist::test;
using json = nlohmann::json;

namespace {

/// A mosquitto broker on 127.0.0.1:port, no persistence (a restart loses the
/// retained messages, as a broker without a persistence file does).
class Broker {
 public:
  Broker(const std::filesystem::path& dir, int port) : dir_(dir), port_(port) {}
  void start() {
    const auto conf = (dir_ / "mosquitto.conf").string();
    std::ofstream(conf) << "listener " << port_ << " 127.0.0.1\nallow_anonymous true\npersistence false\n"
                        << "log_dest stdout\n";
    proc_ = std::make_unique<Process>(std::vector<std::string>{HOIST_MOSQUITTO, "-c", conf},
                                      (dir_ / "mosquitto.log").string());
    const auto end = std::chrono::steady_clock::now() + 10s;
    while (!tcpOpen(port_) && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(20ms);
    ASSERT_TRUE(tcpOpen(port_)) << "mosquitto did not start:\n" << readFile((dir_ / "mosquitto.log").string());
  }
  void stop() {
    if (!proc_) return;
    proc_->signal(SIGTERM);
    proc_->wait(5s);
    proc_.reset();
  }
  std::string url() const { return "mqtt://127.0.0.1:" + std::to_string(port_); }
  int port() const { return port_; }

 private:
  std::filesystem::path dir_;
  int port_;
  std::unique_ptr<Process> proc_;
};

/// An MQTT client (libmosquitto, its own network thread) recording every message.
class Client {
 public:
  struct Msg {
    std::string topic, payload;
    bool retain = false;
  };
  Client(int port, const std::string& id, const std::string& user = "", const std::string& password = "") {
    mosquitto_lib_init();
    m_ = mosquitto_new(id.c_str(), true, this);
    if (!user.empty()) mosquitto_username_pw_set(m_, user.c_str(), password.c_str());
    mosquitto_message_callback_set(m_, [](mosquitto*, void* obj, const mosquitto_message* msg) {
      auto* self = static_cast<Client*>(obj);
      std::lock_guard<std::mutex> lk(self->mu_);
      self->msgs_.push_back({msg->topic, std::string(static_cast<const char*>(msg->payload), msg->payloadlen),
                             msg->retain});
    });
    mosquitto_connect_callback_set(m_, [](mosquitto*, void* obj, int rc) {
      if (rc == 0) static_cast<Client*>(obj)->connected_ = true;
    });
    connect_ok_ = mosquitto_connect(m_, "127.0.0.1", port, 30) == MOSQ_ERR_SUCCESS;
    mosquitto_loop_start(m_);
    const auto end = std::chrono::steady_clock::now() + 5s;
    while (!connected_ && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(10ms);
  }
  ~Client() {
    mosquitto_disconnect(m_);
    mosquitto_loop_stop(m_, true);
    mosquitto_destroy(m_);
  }
  bool connected() const { return connect_ok_ && connected_; }
  void subscribe(const std::string& topic) { mosquitto_subscribe(m_, nullptr, topic.c_str(), 1); }
  void publish(const std::string& topic, const std::string& payload, bool retain = false) {
    mosquitto_publish(m_, nullptr, topic.c_str(), static_cast<int>(payload.size()), payload.data(), 1, retain);
  }
  std::vector<Msg> messages() {
    std::lock_guard<std::mutex> lk(mu_);
    return msgs_;
  }
  std::vector<Msg> on(const std::string& topic) {
    std::vector<Msg> out;
    for (auto& m : messages())
      if (m.topic == topic) out.push_back(m);
    return out;
  }
  /// Waits until pred(messages) holds.
  bool waitFor(const std::function<bool(const std::vector<Msg>&)>& pred, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      if (pred(messages())) return true;
      std::this_thread::sleep_for(20ms);
    }
    return pred(messages());
  }
  /// The latest message on `topic` whose JSON satisfies pred.
  std::optional<json> waitJson(const std::string& topic, const std::function<bool(const json&, bool)>& pred,
                               std::chrono::milliseconds timeout) {
    std::optional<json> found;
    waitFor(
        [&](const std::vector<Msg>& ms) {
          for (auto it = ms.rbegin(); it != ms.rend(); ++it) {
            if (it->topic != topic) continue;
            json j = json::parse(it->payload, nullptr, false);
            if (!j.is_discarded() && pred(j, it->retain)) {
              found = j;
              return true;
            }
          }
          return false;
        },
        timeout);
    return found;
  }

 private:
  mosquitto* m_ = nullptr;
  std::mutex mu_;
  std::vector<Msg> msgs_;
  std::atomic<bool> connected_{false};
  bool connect_ok_ = false;
};

std::size_t countOf(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

/// demo.toml (tight gaps) with a channel prefix for the daemon.
std::string daemonConfig(const std::filesystem::path& dir, const std::string& prefix) {
  std::string text = readFile(HOIST_DEMO_CONFIG);
  const auto pos = text.find("[service]\n");
  EXPECT_NE(pos, std::string::npos);
  text.insert(pos + 10, "channel_prefix = \"" + prefix + "\"\n");
  const auto path = (dir / "twin.toml").string();
  std::ofstream(path) << text;
  return path;
}

class MqttBridge : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!loopbackMulticastWorks(urlFor(7930), why)) GTEST_FAIL() << kMulticastHelp << " (" << why << ")";
  }
  std::string log(const std::string& name) { return (dir_ / name).string(); }
  std::filesystem::path dir_;
};

bool isWarningActive(const json& j) {
  return j.value("active", false) && j.value("level", "") == "WARNING" && j.contains("warning") &&
         j["warning"].is_object();
}

}  // namespace

// State and alarms arrive with the right JSON and retained flags; a late
// subscriber gets the active alarm at once; an ack command reaches the daemon
// and the alarm turns acknowledged; malformed commands are rejected and counted.
TEST_F(MqttBridge, StateAlarmsLateSubscriberAckAndBadCommands) {
  dir_ = testDir("mqtt_state_alarms");
  const std::string url = urlFor(7931);
  Broker broker(dir_, freeTcpPort());
  broker.start();
  Client early(broker.port(), "early");
  ASSERT_TRUE(early.connected());
  early.subscribe("hoist/#");

  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[bridge]\nhealth_period = 0.5\n";
  Process bridge({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--channel-prefix",
                  "north/", "--client-id", "bridge-a"},
                 log("bridge.log"));
  Listener lcm(url);
  lcm.subscribe("north/HOIST_.*");
  auto twind = startDaemonAndWait(lcm, {HOIST_TWIND, "--config", daemonConfig(dir_, "north/"), "--lcm-url", url},
                                  log("twind.log"), "north/HOIST_HEALTH");
  Process replay({HOIST_REPLAY, "--profile", "rest:t_end=60", "--lcm-url", url, "--channel-prefix", "north/"},
                 log("replay.log"));

  // The bridge's status is online (retained) and its LWT is set.
  auto status = early.waitJson("hoist/_bridge/bridge-a/status", [](const json& j, bool) { return j.value("online", false); }, 10s);
  ASSERT_TRUE(status) << readFile(log("bridge.log"));

  // Cage state: the message's fields as JSON, not retained, decimated to ~10 Hz.
  auto cage = early.waitJson("hoist/north/cage", [](const json& j, bool) { return j.value("input_seq", -1) >= 0; }, 10s);
  ASSERT_TRUE(cage) << readFile(log("bridge.log")) << readFile(log("twind.log"));
  for (const char* k : {"utime", "seq", "instance_id", "t", "l", "v", "a", "x_c", "y_c", "theta", "y_top", "y_bottom",
                        "min_clearance", "alarm_level", "degraded"})
    EXPECT_TRUE(cage->contains(k)) << k << " missing in " << cage->dump();
  ASSERT_TRUE((*cage)["lambdas"].is_array());
  EXPECT_EQ((*cage)["lambdas"].size(), 5u);
  EXPECT_NEAR((*cage)["l"].get<double>(), 50.0, 1e-6);  // the paper's l0, at rest
  EXPECT_GT(std::abs((*cage)["lambdas"][0].get<double>()), 7000.0);  // m g + Fa ~ 8848 N
  for (const auto& m : early.on("hoist/north/cage")) EXPECT_FALSE(m.retain);
  const auto n0 = early.on("hoist/north/cage").size();
  std::this_thread::sleep_for(2s);
  const auto n_cage = early.on("hoist/north/cage").size() - n0;
  EXPECT_GE(n_cage, 12u) << "cage states in 2 s at 10 Hz";
  EXPECT_LE(n_cage, 28u) << "cage states in 2 s at 10 Hz (the daemon publishes 100 Hz)";

  // Health: the daemon's health_t as JSON.
  auto health = early.waitJson("hoist/north/health", [](const json& j, bool) { return j.contains("instance_id"); }, 5s);
  ASSERT_TRUE(health);
  EXPECT_EQ((*health)["clock"], "wall");
  EXPECT_TRUE((*health)["reject_reason"].is_array());

  // Forecast: a forecast_t on north/HOIST_FORECAST (synthetic: the
  // daemon's forecast worker is elsewhere) -> hoist/north/forecast as JSON
  // with its nested scenarios, not retained.
  {
    hoist::forecast_t f{};
    f.utime = 1;
    f.seq = 5;
    // As the daemon (the bridge drops data of any other instance than the shaft's).
    f.instance_id = lcm.decoded<hoist::health_t>("north/HOIST_HEALTH").back().instance_id;
    f.t_start = 20.0;
    f.plan_seq = -1;
    f.num_scenarios = 1;
    f.scenarios.resize(1);
    f.scenarios[0].name = "estop";
    f.scenarios[0].min_clearance = 0.0125;
    f.scenarios[0].t_critical = 2.5;
    f.scenarios[0].t_warning = 1.5;
    f.scenarios[0].num_points = 2;
    f.scenarios[0].series_t = {10.0, 20.0};
    f.scenarios[0].series_min_clearance = {0.02, 0.0125};
    f.scenarios[0].series_lambda0_min = {8000.0, 2400.0};
    f.scenarios[0].series_lambda0_max = {9000.0, 15000.0};
    lcm.lcm().publish("north/HOIST_FORECAST", &f);
  }
  auto fc = early.waitJson("hoist/north/forecast", [](const json& j, bool) { return j.value("seq", -1) == 5; }, 5s);
  ASSERT_TRUE(fc) << readFile(log("bridge.log"));
  ASSERT_EQ((*fc)["scenarios"].size(), 1u);
  EXPECT_EQ((*fc)["scenarios"][0]["name"], "estop");
  EXPECT_DOUBLE_EQ((*fc)["scenarios"][0]["t_critical"].get<double>(), 2.5);
  EXPECT_EQ((*fc)["scenarios"][0]["series_lambda0_max"].size(), 2u);
  for (const auto& m : early.on("hoist/north/forecast")) EXPECT_FALSE(m.retain);

  // The alarm: CAGE_POS_Y WARNING active (demo.toml's 16 mm gap, ~11 mm lean).
  auto alarm = early.waitJson("hoist/north/alarm/CAGE_POS_Y", [](const json& j, bool) { return isWarningActive(j); }, 15s);
  ASSERT_TRUE(alarm) << readFile(log("bridge.log")) << readFile(log("twind.log"));
  EXPECT_EQ((*alarm)["shaft"], "north");
  EXPECT_EQ((*alarm)["kind"], "CAGE_POS_Y");
  EXPECT_TRUE((*alarm)["unacked"].get<bool>());
  EXPECT_EQ((*alarm)["warning"]["kind"], "CAGE_POS_Y");
  EXPECT_EQ((*alarm)["warning"]["level"], +hoist::alarm_t::LEVEL_WARNING);
  EXPECT_TRUE((*alarm)["warning"]["active"].get<bool>());
  EXPECT_GT((*alarm)["warning"]["value"].get<double>(), (*alarm)["warning"]["threshold"].get<double>());
  EXPECT_TRUE((*alarm)["critical"].is_null());

  // A late subscriber gets the active alarm at once, RETAINED; nothing else
  // it receives at once is retained except alarm states and the bridge status.
  Client late(broker.port(), "late");
  ASSERT_TRUE(late.connected());
  late.subscribe("hoist/#");
  auto retained = late.waitJson("hoist/north/alarm/CAGE_POS_Y", [](const json& j, bool r) { return r && isWarningActive(j); }, 3s);
  EXPECT_TRUE(retained) << "a late subscriber must see the active alarm as a retained message";
  std::this_thread::sleep_for(500ms);
  for (const auto& m : late.messages()) {
    if (m.retain) {
      EXPECT_TRUE(m.topic.rfind("hoist/north/alarm/", 0) == 0 || m.topic == "hoist/_bridge/bridge-a/status") << m.topic;
    }
  }
  EXPECT_FALSE(late.on("hoist/north/cage").empty());

  // Malformed commands: rejected, counted, never forwarded, never echoed.
  const std::size_t acks_before = lcm.count("north/HOIST_ALARM_ACK");
  const std::vector<std::string> bad = {
      "garbage-PAYLOAD-123",                                          // not JSON
      std::string(5000, '{'),                                         // oversized
      "[1,2,3]",                                                      // not an object
      std::string("\xff\xfe\x00\x01", 4),                            // binary
      R"({"kind":"NO_SUCH_KIND","level":0,"action":1})",             // unknown kind
      R"({"kind":"CAGE_POS_Y","level":0,"action":9})",               // unknown action
      R"({"kind":"CAGE_POS_Y","level":0,"action":1,"evil":"x"})",    // unknown key
  };
  for (const auto& p : bad) early.publish("hoist/north/cmd/ack", p);
  auto bh = early.waitJson("hoist/_bridge/bridge-a/health",
                           [](const json& j, bool) { return j["commands"]["rejected"].get<int>() >= 7; }, 5s);
  ASSERT_TRUE(bh) << readFile(log("bridge.log"));
  const json& c = (*bh)["commands"];
  EXPECT_EQ(c["received"], 7);
  EXPECT_EQ(c["rejected"], 7);
  EXPECT_EQ(c["forwarded"], 0);
  EXPECT_EQ(c["rejected_by_reason"]["not_json"], 2);
  EXPECT_EQ(c["rejected_by_reason"]["oversized"], 1);
  EXPECT_EQ(c["rejected_by_reason"]["not_object"], 1);
  EXPECT_EQ(c["rejected_by_reason"]["unknown_kind"], 1);
  EXPECT_EQ(c["rejected_by_reason"]["bad_action"], 1);
  EXPECT_EQ(c["rejected_by_reason"]["bad_fields"], 1);
  EXPECT_EQ((*bh)["connection"]["state"], "connected");
  EXPECT_EQ((*bh)["lcm"]["decode_errors"], 0);
  EXPECT_GE((*bh)["shafts"][0]["forecasts_in"].get<int>(), 1);
  lcm.pump(300ms);
  EXPECT_EQ(lcm.count("north/HOIST_ALARM_ACK"), acks_before) << "a rejected command reached LCM";
  const std::string blog = readFile(log("bridge.log"));
  EXPECT_EQ(blog.find("garbage-PAYLOAD-123"), std::string::npos) << "raw payload echoed in the log";
  EXPECT_NE(blog.find("rejected command on hoist/north/cmd/ack"), std::string::npos) << blog;

  // An ack command reaches the daemon, and the alarm turns acknowledged.
  early.publish("hoist/north/cmd/ack", R"({"kind":"CAGE_POS_Y","level":0,"action":1,"user":"scada-op"})");
  ASSERT_TRUE(lcm.waitFor([&] { return lcm.count("north/HOIST_ALARM_ACK") > acks_before; }, 5s))
      << "no HOIST_ALARM_ACK on LCM; bridge log:\n" << readFile(log("bridge.log"));
  const auto acks = lcm.decoded<hoist::alarm_ack_t>("north/HOIST_ALARM_ACK");
  ASSERT_FALSE(acks.empty());
  EXPECT_EQ(acks.back().kind, "CAGE_POS_Y");
  EXPECT_EQ(acks.back().action, +hoist::alarm_ack_t::ACTION_ACK);
  EXPECT_EQ(acks.back().user, "scada-op");
  auto acked = early.waitJson(
      "hoist/north/alarm/CAGE_POS_Y",
      [](const json& j, bool) { return j["warning"].is_object() && j["warning"]["acked"].get<bool>(); }, 5s);
  ASSERT_TRUE(acked) << readFile(log("twind.log"));
  EXPECT_EQ((*acked)["last_event"], "ACK");
  EXPECT_FALSE((*acked)["unacked"].get<bool>());
  EXPECT_TRUE((*acked)["active"].get<bool>());
  // The daemon's log is written by its own thread: give it a moment.
  for (int i = 0; i < 100 && readFile(log("twind.log")).find("operator 'scada-op': acknowledge") == std::string::npos; ++i)
    std::this_thread::sleep_for(20ms);
  EXPECT_NE(readFile(log("twind.log")).find("operator 'scada-op': acknowledge"), std::string::npos);

  // The load estimator's live calibration (issue 30) goes the same way: the
  // daemon's own command, its fields as sent.
  const std::size_t acks_now = lcm.count("north/HOIST_ALARM_ACK");
  early.publish("hoist/north/cmd/ack",
                R"({"kind":"","level":0,"action":5,"known_fa":250,"known_b":-0.5,"calibrate_duration":60,"user":"eng"})");
  ASSERT_TRUE(lcm.waitFor([&] { return lcm.count("north/HOIST_ALARM_ACK") > acks_now; }, 5s))
      << "no calibrate on LCM; bridge log:\n" << readFile(log("bridge.log"));
  const hoist::alarm_ack_t cal = lcm.decoded<hoist::alarm_ack_t>("north/HOIST_ALARM_ACK").back();
  EXPECT_EQ(cal.action, +hoist::alarm_ack_t::ACTION_CALIBRATE);
  EXPECT_EQ(cal.known_fa, 250.0);
  EXPECT_EQ(cal.known_b, -0.5);
  EXPECT_EQ(cal.calibrate_duration, 60.0);
  EXPECT_EQ(cal.user, "eng");

  // Stop: the bridge says it is offline (retained) and exits 0.
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0) << readFile(log("bridge.log"));
  // (On a loaded machine the broker may have seen a keepalive lapse earlier:
  // its last will, "connection lost (last will)", is then among the status
  // messages too, and the bridge reconnected.  The stop's own is "shutdown".)
  auto off = early.waitJson(
      "hoist/_bridge/bridge-a/status",
      [](const json& j, bool) { return !j.value("online", true) && j.value("reason", "") == "shutdown"; }, 3s);
  ASSERT_TRUE(off) << readFile(log("bridge.log"));
  EXPECT_EQ((*off)["reason"], "shutdown");
  replay.signal(SIGTERM);
  stopDaemonCleanly(*twind, log("twind.log"));
}

// The broker is down at start and restarts mid-run: the bridge retries with
// backoff, logs once per state change, buffers a bounded number of messages
// (dropping cage states, never alarm transitions), reconnects, re-subscribes
// and republishes the retained alarm states; nothing crashes.  A killed
// bridge leaves its last will (offline).
TEST_F(MqttBridge, BrokerDownAtStartAndRestarted) {
  dir_ = testDir("mqtt_restart");
  const std::string url = urlFor(7932);
  Broker broker(dir_, freeTcpPort());
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[broker]\nreconnect_min = 0.1\nreconnect_max = 0.5\n[bridge]\nhealth_period = 0.5\n"
                         "[buffer]\nmax_messages = 15\n";
  // Shafts discovered (no --channel-prefix); the daemon has no prefix: "default".
  Process bridge({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--client-id", "bridge-b"},
                 log("bridge.log"));
  Listener lcm(url);
  lcm.subscribe("HOIST_.*");
  auto twind = startDaemonAndWait(lcm, {HOIST_TWIND, "--config", daemonConfig(dir_, ""), "--lcm-url", url},
                                  log("twind.log"));
  Process replay({HOIST_REPLAY, "--profile", "rest:t_end=60", "--lcm-url", url}, log("replay.log"));
  // The alarm comes up while the broker is down.
  ASSERT_TRUE(lcm.waitFor([&] { return lcm.count("HOIST_ALARM") > 0; }, 10s)) << readFile(log("twind.log"));
  // A discovered shaft is bridged once its health has kept coming (3 messages over >= 1 s): then > 2 s of buffering.
  lcm.pump(4s);
  ASSERT_TRUE(bridge.running()) << readFile(log("bridge.log"));
  std::string blog = readFile(log("bridge.log"));
  EXPECT_EQ(countOf(blog, "cannot connect to the broker"), 1u) << "log once per state change:\n" << blog;

  broker.start();
  Client c1(broker.port(), "c1");
  ASSERT_TRUE(c1.connected());
  c1.subscribe("hoist/#");
  auto st = c1.waitJson("hoist/default/alarm/CAGE_POS_Y", [](const json& j, bool) { return isWarningActive(j); }, 10s);
  ASSERT_TRUE(st) << readFile(log("bridge.log"));
  auto h1 = c1.waitJson("hoist/_bridge/bridge-b/health",
                        [](const json& j, bool) { return j["connection"]["state"] == "connected"; }, 5s);
  ASSERT_TRUE(h1);
  EXPECT_EQ((*h1)["connection"]["connects"], 1);
  EXPECT_GE((*h1)["connection"]["connect_failures"].get<int>(), 2);
  EXPECT_GT((*h1)["buffer"]["dropped_cage"].get<int>(), 0) << "15 messages of buffer over > 2 s at 10 Hz";
  EXPECT_EQ((*h1)["buffer"]["dropped_alarm"], 0);
  ASSERT_EQ((*h1)["shafts"].size(), 1u);
  EXPECT_EQ((*h1)["shafts"][0]["name"], "default");
  EXPECT_EQ((*h1)["shafts"][0]["channel_prefix"], "");

  // Broker restart (it loses its retained messages: no persistence).
  broker.stop();
  std::this_thread::sleep_for(1500ms);
  ASSERT_TRUE(bridge.running()) << readFile(log("bridge.log"));
  broker.start();
  Client c2(broker.port(), "c2");
  ASSERT_TRUE(c2.connected());
  // Subscribe once the bridge is back.
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (countOf(readFile(log("bridge.log")), "connected to the broker") < 2 && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(50ms);
  ASSERT_EQ(countOf(readFile(log("bridge.log")), "connected to the broker"), 2u) << readFile(log("bridge.log"));
  std::this_thread::sleep_for(1s);  // the republication follows the log line
  c2.subscribe("hoist/#");
  auto again = c2.waitJson("hoist/default/alarm/CAGE_POS_Y", [](const json& j, bool r) { return r && isWarningActive(j); }, 5s);
  EXPECT_TRUE(again) << "the retained alarm state was not republished after the broker restart";
  EXPECT_TRUE(c2.waitJson("hoist/default/cage", [](const json&, bool) { return true; }, 3s));
  auto h2 = c2.waitJson("hoist/_bridge/bridge-b/health", [](const json& j, bool) { return j["connection"]["connects"] == 2; }, 5s);
  ASSERT_TRUE(h2);
  EXPECT_EQ((*h2)["connection"]["disconnects"], 1);
  // Commands work on the new connection (re-subscribed).  (Drain the LCM
  // socket first: unread for seconds, it is full and would drop the ack.)
  lcm.pump(300ms);
  const std::size_t acks_before = lcm.count("HOIST_ALARM_ACK");
  c2.publish("hoist/default/cmd/ack", R"({"kind":"*","level":0,"action":1})");
  EXPECT_TRUE(lcm.waitFor([&] { return lcm.count("HOIST_ALARM_ACK") > acks_before; }, 5s));
  blog = readFile(log("bridge.log"));
  EXPECT_EQ(countOf(blog, "lost:"), 1u) << blog;
  EXPECT_EQ(countOf(blog, "connected to the broker"), 2u) << blog;

  // A killed bridge: the broker publishes its last will (offline, retained).
  bridge.signal(SIGKILL);
  bridge.wait(5s);
  Client c3(broker.port(), "c3");
  ASSERT_TRUE(c3.connected());
  c3.subscribe("hoist/_bridge/bridge-b/status");
  auto will = c3.waitJson("hoist/_bridge/bridge-b/status", [](const json& j, bool) { return !j.value("online", true); }, 10s);
  ASSERT_TRUE(will) << "no last will after the bridge was killed";
  EXPECT_EQ((*will)["reason"], "connection lost (last will)");
  replay.signal(SIGTERM);
  stopDaemonCleanly(*twind, log("twind.log"));
}

// --no-commands: nothing on hoist/<shaft>/cmd/ack reaches LCM.
TEST_F(MqttBridge, NoCommandsIgnoresCommands) {
  dir_ = testDir("mqtt_no_commands");
  const std::string url = urlFor(7933);
  Broker broker(dir_, freeTcpPort());
  broker.start();
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[bridge]\nhealth_period = 0.3\n";
  Process bridge({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--channel-prefix",
                  "south/", "--no-commands", "--client-id", "bridge-c"},
                 log("bridge.log"));
  Client c(broker.port(), "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/_bridge/#");
  ASSERT_TRUE(c.waitJson("hoist/_bridge/bridge-c/health", [](const json&, bool) { return true; }, 5s))
      << readFile(log("bridge.log"));
  Listener lcm(url);
  lcm.subscribe("south/HOIST_ALARM_ACK");
  for (int i = 0; i < 3; ++i) c.publish("hoist/south/cmd/ack", R"({"kind":"*","level":0,"action":1})");
  lcm.pump(1500ms);
  EXPECT_EQ(lcm.count("south/HOIST_ALARM_ACK"), 0u);
  auto h = c.waitJson("hoist/_bridge/bridge-c/health", [](const json&, bool) { return true; }, 2s);
  ASSERT_TRUE(h);
  EXPECT_FALSE((*h)["commands"]["enabled"].get<bool>());
  EXPECT_EQ((*h)["commands"]["received"], 0);
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0);
}

// Bad configuration: exit status 2 and a message naming file, line and key.
TEST_F(MqttBridge, BadConfigurationExits2) {
  dir_ = testDir("mqtt_bad_config");
  const auto bcfg = (dir_ / "bad.toml").string();
  std::ofstream(bcfg) << "[bridge]\ncage_rate = -1\n";
  EXPECT_EQ(runProcess({HOIST_MQTT, "--config", bcfg}, log("out.log"), 10s), 2);
  EXPECT_NE(readFile(log("out.log")).find("bad.toml:2: bridge.cage_rate: must be in (0, 1000]"), std::string::npos)
      << readFile(log("out.log"));
  EXPECT_EQ(runProcess({HOIST_MQTT, "--broker", "http://x"}, log("out2.log"), 10s), 2);
  EXPECT_NE(readFile(log("out2.log")).find("broker.url"), std::string::npos) << readFile(log("out2.log"));
  EXPECT_EQ(runProcess({HOIST_MQTT, "--help"}, log("out3.log"), 10s), 0);
}

// TLS with a CA file and username/password (password from a file): the
// bridge connects to a TLS listener that requires both; with a wrong
// password it is refused, says so once, keeps retrying and never exits.
TEST_F(MqttBridge, TlsWithPasswordFile) {
  dir_ = testDir("mqtt_tls");
  auto path = [&](const char* f) { return (dir_ / f).string(); };
  auto run = [&](std::vector<std::string> argv) {
    const int rc = runProcess(std::move(argv), path("openssl.log"), 60s);
    ASSERT_EQ(rc, 0) << readFile(path("openssl.log"));
  };
  // A private CA and a server certificate for localhost / 127.0.0.1.
  std::ofstream(path("ext.cnf")) << "subjectAltName=DNS:localhost,IP:127.0.0.1\n";
  run({HOIST_OPENSSL, "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", path("ca.key"), "-out",
       path("ca.crt"), "-days", "2", "-subj", "/CN=hoist-test-ca"});
  run({HOIST_OPENSSL, "req", "-newkey", "rsa:2048", "-nodes", "-keyout", path("server.key"), "-out",
       path("server.csr"), "-subj", "/CN=localhost"});
  run({HOIST_OPENSSL, "x509", "-req", "-in", path("server.csr"), "-CA", path("ca.crt"), "-CAkey", path("ca.key"),
       "-CAcreateserial", "-out", path("server.crt"), "-days", "2", "-extfile", path("ext.cnf")});
  run({HOIST_MOSQUITTO_PASSWD, "-b", "-c", path("passwd"), "hoist", "s3cret"});
  std::filesystem::permissions(path("server.key"), std::filesystem::perms::owner_read | std::filesystem::perms::group_read |
                                                       std::filesystem::perms::others_read);
  // Listener 1: plain, anonymous (the test's client); listener 2: TLS + password (the bridge).
  const int plain = freeTcpPort(), tls = freeTcpPort();
  std::ofstream(path("mosquitto.conf")) << "per_listener_settings true\npersistence false\nlog_dest stdout\n"
                                        << "listener " << plain << " 127.0.0.1\nallow_anonymous true\n"
                                        << "listener " << tls << " 127.0.0.1\nallow_anonymous false\n"
                                        << "password_file " << path("passwd") << "\ncafile " << path("ca.crt")
                                        << "\ncertfile " << path("server.crt") << "\nkeyfile " << path("server.key")
                                        << "\n";
  Process broker({HOIST_MOSQUITTO, "-c", path("mosquitto.conf")}, path("mosquitto.log"));
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (!(tcpOpen(plain) && tcpOpen(tls)) && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(20ms);
  ASSERT_TRUE(tcpOpen(tls)) << readFile(path("mosquitto.log"));
  Client c(plain, "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/_bridge/#");

  std::ofstream(path("pw")) << "s3cret\n";
  std::ofstream(path("badpw")) << "Wr0ngPw-xyz\n";
  auto config = [&](const char* name, const char* pwfile) {
    std::ofstream(path(name)) << "[broker]\nurl = \"mqtts://localhost:" << tls << "\"\nusername = \"hoist\"\n"
                              << "password_file = \"" << path(pwfile) << "\"\nreconnect_min = 0.1\nreconnect_max = 0.3\n"
                              << "[tls]\nca_file = \"" << path("ca.crt") << "\"\n[bridge]\nhealth_period = 0.5\n";
  };
  config("good.toml", "pw");
  config("bad.toml", "badpw");
  Process good({HOIST_MQTT, "--config", path("good.toml"), "--lcm-url", urlFor(7934), "--client-id", "tls-good"},
               path("good.log"));
  Process bad({HOIST_MQTT, "--config", path("bad.toml"), "--lcm-url", urlFor(7934), "--client-id", "tls-bad"},
              path("bad.log"));
  auto st = c.waitJson("hoist/_bridge/tls-good/status", [](const json& j, bool) { return j.value("online", false); }, 15s);
  ASSERT_TRUE(st) << readFile(path("good.log")) << readFile(path("mosquitto.log"));
  std::this_thread::sleep_for(1500ms);
  EXPECT_TRUE(bad.running());
  EXPECT_TRUE(c.on("hoist/_bridge/tls-bad/status").empty());
  const std::string blog = readFile(path("bad.log"));
  EXPECT_EQ(countOf(blog, "cannot connect to the broker"), 1u) << blog;
  EXPECT_NE(blog.find("not authorised"), std::string::npos) << blog;
  EXPECT_EQ(blog.find("s3cret"), std::string::npos);
  EXPECT_EQ(blog.find("Wr0ngPw-xyz"), std::string::npos) << "the password must never be logged";
  good.signal(SIGTERM);
  bad.signal(SIGTERM);
  EXPECT_EQ(good.wait(5s), 0);
  EXPECT_EQ(bad.wait(5s), 0);
}

// The command path (threats: retained replays, floods, ambiguous JSON, control
// characters): a retained command is never executed, neither when the bridge
// starts nor when it restarts, and the bridge deletes it from the broker; a
// flood from one user is cut to the per-user burst while another user still
// gets through; a payload with a key given twice, a user with control
// characters (C0, DEL, C1) and a stale client utime are refused, counted by
// reason and never reach LCM.
TEST_F(MqttBridge, RetainedFloodedAndAmbiguousCommandsAreRefused) {
  dir_ = testDir("mqtt_cmd_hardening");
  const std::string url = urlFor(7935);
  Broker broker(dir_, freeTcpPort());
  broker.start();
  Client c(broker.port(), "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/#");
  // A retained "shelve everything for an hour", left on the broker before the bridge starts.
  c.publish("hoist/east/cmd/ack", R"({"kind":"*","level":0,"action":2,"shelve_duration":3600,"user":"evil"})", true);
  std::this_thread::sleep_for(300ms);

  Listener lcm(url);
  lcm.subscribe("east/HOIST_ALARM_ACK");
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[bridge]\nhealth_period = 0.3\ncommand_rate = 0.5\ncommand_burst = 5\n";
  std::vector<std::string> argv{HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url,
                                "--channel-prefix", "east/", "--client-id", "bridge-h"};
  auto bridge = std::make_unique<Process>(argv, log("bridge.log"));
  auto h = c.waitJson("hoist/_bridge/bridge-h/health",
                      [](const json& j, bool) { return j["commands"]["rejected_by_reason"]["retained"] == 1; }, 10s);
  ASSERT_TRUE(h) << readFile(log("bridge.log"));
  EXPECT_EQ((*h)["commands"]["forwarded"], 0);
  lcm.pump(300ms);
  EXPECT_EQ(lcm.count("east/HOIST_ALARM_ACK"), 0u) << "a retained command was executed";
  // Restarted: the retained command is gone (deleted by the bridge), so nothing is replayed.
  bridge->signal(SIGTERM);
  EXPECT_EQ(bridge->wait(5s), 0);
  bridge = std::make_unique<Process>(argv, log("bridge2.log"));
  h = c.waitJson("hoist/_bridge/bridge-h/health", [](const json& j, bool) { return j["uptime"].get<double>() > 0.5 &&
                                                                                 j["commands"]["received"] == 0; }, 10s);
  ASSERT_TRUE(h) << readFile(log("bridge2.log"));
  lcm.pump(300ms);
  EXPECT_EQ(lcm.count("east/HOIST_ALARM_ACK"), 0u);
  {
    Client late(broker.port(), "late");
    ASSERT_TRUE(late.connected());
    late.subscribe("hoist/east/cmd/#");
    std::this_thread::sleep_for(500ms);
    for (const auto& m : late.messages()) EXPECT_FALSE(m.retain) << m.topic << ": " << m.payload;
  }

  // Ambiguous or unsafe payloads: refused by reason.
  const auto now_us = std::chrono::duration_cast<std::chrono::microseconds>(
                          std::chrono::system_clock::now().time_since_epoch()).count();
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"duplicate_key", R"({"kind":"CAGE_POS_Y","level":0,"action":1,"kind":"*"})"},
      {"duplicate_key", R"({"kind":"*","level":0,"action":3,"action":2,"shelve_duration":60})"},
      {"bad_user", R"({"kind":"*","level":0,"action":1,"user":"op\u001b[2J"})"},
      {"bad_user", R"({"kind":"*","level":0,"action":1,"user":"op\nAUDIT operator 'x'"})"},
      {"bad_user", R"({"kind":"*","level":0,"action":1,"user":"op\u007f"})"},
      {"bad_user", R"({"kind":"*","level":0,"action":1,"user":"op\u009b31m"})"},
      {"bad_user", R"({"kind":"*","level":0,"action":1,"user":""})"},
      {"stale_utime", R"({"kind":"*","level":0,"action":1,"utime":)" + std::to_string(now_us - 3'600'000'000LL) + "}"},
  };
  for (const auto& [why, p] : bad) c.publish("hoist/east/cmd/ack", p);
  h = c.waitJson("hoist/_bridge/bridge-h/health",
                 [&](const json& j, bool) { return j["commands"]["rejected"].get<std::size_t>() >= bad.size(); }, 10s);
  ASSERT_TRUE(h) << readFile(log("bridge2.log"));
  EXPECT_EQ((*h)["commands"]["rejected_by_reason"]["duplicate_key"], 2);
  EXPECT_EQ((*h)["commands"]["rejected_by_reason"]["bad_user"], 5);
  EXPECT_EQ((*h)["commands"]["rejected_by_reason"]["stale_utime"], 1);
  lcm.pump(300ms);
  EXPECT_EQ(lcm.count("east/HOIST_ALARM_ACK"), 0u);
  EXPECT_EQ(readFile(log("bridge2.log")).find('\x1b'), std::string::npos) << "a control character reached the log";

  // A flood from one user: at most its burst (5) and what the rate refills
  // (0.5/s) is forwarded; another user still gets through.
  for (int i = 0; i < 40; ++i)
    c.publish("hoist/east/cmd/ack", R"({"kind":"CAGE_POS_Y","level":0,"action":3,"user":"flooder"})");
  h = c.waitJson("hoist/_bridge/bridge-h/health",
                 [&](const json& j, bool) { return j["commands"]["received"].get<int>() >= int(bad.size()) + 40; }, 10s);
  ASSERT_TRUE(h) << readFile(log("bridge2.log"));
  ASSERT_TRUE(lcm.waitFor([&] { return lcm.count("east/HOIST_ALARM_ACK") >= 5; }, 5s));
  lcm.pump(300ms);
  const auto flooded = lcm.count("east/HOIST_ALARM_ACK");
  EXPECT_GE(flooded, 5u);
  EXPECT_LE(flooded, 8u) << "a 40-command flood from one user must be cut near its burst of 5";
  EXPECT_GE((*h)["commands"]["rejected_by_reason"]["rate_limited"].get<int>(), 32);
  c.publish("hoist/east/cmd/ack", R"({"kind":"CAGE_POS_Y","level":0,"action":3,"user":"operator-2"})");
  ASSERT_TRUE(lcm.waitFor([&] { return lcm.count("east/HOIST_ALARM_ACK") > flooded; }, 5s))
      << "another user's command was blocked by one user's flood";
  EXPECT_EQ(lcm.decoded<hoist::alarm_ack_t>("east/HOIST_ALARM_ACK").back().user, "operator-2");
  bridge->signal(SIGTERM);
  EXPECT_EQ(bridge->wait(5s), 0);
}

namespace {
hoist::health_t forgedHealth(std::int64_t instance) {
  hoist::health_t h{};
  h.utime = 1;
  h.instance_id = instance;
  h.clock = "wall";
  return h;
}
}  // namespace

// Discovery cannot be poisoned: one forged north_HOIST_HEALTH sent before the
// real north/ daemon, and 70 forged prefixes (single datagrams), bind nothing
// for good: the real daemon's shaft is bridged, its commands go to
// north/HOIST_ALARM_ACK.  A second prefix claiming "north" at the health rate
// is reported with the first (discovery.conflicts) and commands are refused
// while it lasts.  A full table (max_shafts) is a log line and
// discovery.table_full while it lasts.
TEST_F(MqttBridge, DiscoveryIsNotPoisoned) {
  dir_ = testDir("mqtt_discovery");
  const std::string url = urlFor(7936);
  Broker broker(dir_, freeTcpPort());
  broker.start();
  Client c(broker.port(), "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/#");
  Listener lcm(url);
  lcm.subscribe("north.HOIST_(HEALTH|ALARM_ACK)");
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[bridge]\nhealth_period = 0.3\ndiscovery_timeout = 2.0\nmax_shafts = 64\n";
  Process bridge({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--client-id", "bridge-d"},
                 log("bridge.log"));
  ASSERT_TRUE(c.waitJson("hoist/_bridge/bridge-d/status", [](const json& j, bool) { return j.value("online", false); }, 10s));
  // The forgeries: north_ once, then 70 prefixes once each (health with an instance id, and a cage state).
  auto h = forgedHealth(666);
  lcm.lcm().publish("north_HOIST_HEALTH", &h);
  hoist::cage_state_t cage{};
  for (int i = 0; i < 70; ++i) {
    const std::string p = "forged" + std::to_string(i) + "/";
    h.instance_id = 1000 + i;
    lcm.lcm().publish(p + "HOIST_HEALTH", &h);
    lcm.lcm().publish(p + "HOIST_CAGE", &cage);
  }
  lcm.pump(300ms);
  // The real daemon.
  auto twind = startDaemonAndWait(lcm, {HOIST_TWIND, "--config", daemonConfig(dir_, "north/"), "--lcm-url", url},
                                  log("twind.log"), "north/HOIST_HEALTH");
  const auto real_instance = lcm.decoded<hoist::health_t>("north/HOIST_HEALTH").back().instance_id;
  auto mh = c.waitJson("hoist/north/health", [&](const json& j, bool) { return j["instance_id"] == real_instance; }, 10s);
  ASSERT_TRUE(mh) << "the real shaft was not bridged:\n" << readFile(log("bridge.log"));
  for (const auto& m : c.on("hoist/north/health"))
    EXPECT_EQ(json::parse(m.payload)["instance_id"], real_instance) << "a forged health was published as north's";
  for (const auto& m : c.messages()) EXPECT_EQ(m.topic.rfind("hoist/forged", 0), std::string::npos) << m.topic;
  auto bh = c.waitJson("hoist/_bridge/bridge-d/health", [](const json& j, bool) {
    return j["shafts"].size() == 1 && j["discovery"]["candidates"] == 0; }, 10s);  // the forgeries aged out
  ASSERT_TRUE(bh) << readFile(log("bridge.log"));
  EXPECT_EQ((*bh)["shafts"][0]["channel_prefix"], "north/");
  EXPECT_GE((*bh)["discovery"]["aged_out"].get<int>(), 71);
  // A command for north goes to the real daemon's channel.
  lcm.pump(200ms);
  // (Besides the commands, the bridge asked the real daemon, once, for its
  // alarm states: alarm_ack_t ACTION_REANNOUNCE.  The forged prefixes were asked nothing.)
  auto commandsOn = [&](const std::string& ch, bool requests = false) {
    std::size_t n = 0;
    for (const auto& a : lcm.decoded<hoist::alarm_ack_t>(ch))
      n += (a.action == hoist::alarm_ack_t::ACTION_REANNOUNCE) == requests;
    return n;
  };
  c.publish("hoist/north/cmd/ack", R"({"kind":"*","level":0,"action":3,"user":"op"})");
  ASSERT_TRUE(lcm.waitFor([&] { return commandsOn("north/HOIST_ALARM_ACK") == 1; }, 5s)) << readFile(log("bridge.log"));
  EXPECT_EQ(lcm.count("north_HOIST_ALARM_ACK"), 0u);
  EXPECT_EQ(commandsOn("north/HOIST_ALARM_ACK", true), 1u);

  // Another prefix claims "north" at the health rate: both reported, and the
  // name stays with the daemon first heard (issue 33: the forged name costs
  // the forger, never the real shaft): commands go on to north/.
  auto claim = [&](const std::vector<std::string>& prefixes, std::chrono::milliseconds d) {
    const auto end = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < end) {
      for (std::size_t i = 0; i < prefixes.size(); ++i) {
        auto f = forgedHealth(777 + static_cast<std::int64_t>(i));
        lcm.lcm().publish(prefixes[i] + "HOIST_HEALTH", &f);
      }
      lcm.pump(250ms);
    }
  };
  claim({"north_"}, 2000ms);
  bh = c.waitJson("hoist/_bridge/bridge-d/health", [](const json& j, bool) { return !j["discovery"]["conflicts"].empty(); }, 3s);
  ASSERT_TRUE(bh) << readFile(log("bridge.log"));
  EXPECT_EQ((*bh)["discovery"]["conflicts"][0]["shaft"], "north");
  EXPECT_EQ((*bh)["discovery"]["conflicts"][0]["bridged_prefix"], "north/");
  EXPECT_EQ((*bh)["discovery"]["conflicts"][0]["prefixes"], json::array({"north/", "north_"}));
  c.publish("hoist/north/cmd/ack", R"({"kind":"*","level":0,"action":3,"user":"op"})");
  EXPECT_TRUE(lcm.waitFor([&] { return commandsOn("north/HOIST_ALARM_ACK") == 2; }, 5s)) << readFile(log("bridge.log"));
  EXPECT_EQ(lcm.count("north_HOIST_ALARM_ACK"), 0u);
  bh = c.waitJson("hoist/_bridge/bridge-d/health", [](const json& j, bool) {
    return j["commands"]["forwarded"] == 2 && !j["discovery"]["conflicts"].empty(); }, 3s);
  ASSERT_TRUE(bh) << readFile(log("bridge.log"));
  EXPECT_EQ((*bh)["commands"]["rejected_by_reason"]["ambiguous_shaft"], 0);
  EXPECT_NE(readFile(log("bridge.log")).find("shaft name 'north' is already bridged from prefix 'north/'"),
            std::string::npos) << readFile(log("bridge.log"));
  EXPECT_NE(readFile(log("bridge.log")).find("prefix 'north_' (daemon instance 777) claims it too"),
            std::string::npos) << readFile(log("bridge.log"));
  lcm.pump(2500ms);  // the claim stops: it ages out
  bh = c.waitJson("hoist/_bridge/bridge-d/health", [](const json& j, bool) { return j["discovery"]["conflicts"].empty(); }, 3s);
  EXPECT_TRUE(bh);
  stopDaemonCleanly(*twind, log("twind.log"));
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0);
}

// A full shaft table is loud: a log line and discovery.table_full (with the
// refused prefix) while it lasts, and room again once a shaft's health stops.
TEST_F(MqttBridge, DiscoveryFullTableIsReported) {
  dir_ = testDir("mqtt_discovery_full");
  const std::string url = urlFor(7937);
  Broker broker(dir_, freeTcpPort());
  broker.start();
  Client c(broker.port(), "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/#");
  Listener lcm(url);
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[bridge]\nhealth_period = 0.3\ndiscovery_timeout = 1.5\nmax_shafts = 2\n";
  Process bridge({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--client-id", "bridge-f"},
                 log("bridge.log"));
  ASSERT_TRUE(c.waitJson("hoist/_bridge/bridge-f/status", [](const json& j, bool) { return j.value("online", false); }, 10s));
  auto beat = [&](const std::vector<std::string>& prefixes, std::chrono::milliseconds d) {
    const auto end = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < end) {
      for (std::size_t i = 0; i < prefixes.size(); ++i) {
        auto f = forgedHealth(500 + static_cast<std::int64_t>(i));
        lcm.lcm().publish(prefixes[i] + "HOIST_HEALTH", &f);
      }
      lcm.pump(250ms);
    }
  };
  beat({"a/", "b/"}, 1800ms);
  beat({"a/", "b/", "c/"}, 1800ms);
  auto bh = c.waitJson("hoist/_bridge/bridge-f/health", [](const json& j, bool) { return j["discovery"]["table_full"] == true; }, 3s);
  ASSERT_TRUE(bh) << readFile(log("bridge.log"));
  EXPECT_EQ((*bh)["discovery"]["refused"], json::array({"c/"}));
  EXPECT_EQ((*bh)["shafts"].size(), 2u);
  EXPECT_NE(readFile(log("bridge.log")).find("the shaft table is full"), std::string::npos) << readFile(log("bridge.log"));
  // b/ stops: c/ takes its slot; the table has room for no one else but refuses no one.
  beat({"a/", "c/"}, 3000ms);
  bh = c.waitJson("hoist/_bridge/bridge-f/health", [](const json& j, bool) { return j["discovery"]["table_full"] == false; }, 3s);
  ASSERT_TRUE(bh) << readFile(log("bridge.log"));
  std::vector<std::string> names;
  for (const auto& s : (*bh)["shafts"]) names.push_back(s["name"]);
  EXPECT_EQ(names, (std::vector<std::string>{"a", "c"}));
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0);
}

namespace {
hoist::alarm_t alarmEvent(const std::string& kind, int event, bool active) {
  hoist::alarm_t a{};
  a.utime = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  a.instance_id = 4244;  // forgedHealth(4244) is sent first: the instance the bridge follows
  static std::int64_t next_id = 0;
  a.id = ++next_id;      // the daemon numbers its events (+1 each)
  a.kind = kind;
  a.level = hoist::alarm_t::LEVEL_WARNING;
  a.event_type = static_cast<std::int8_t>(event);
  a.active = active;
  a.message = "test";
  a.user = "";
  return a;
}
}  // namespace

// Every command is answered on hoist/<shaft>/cmd/result: accepted (forwarded),
// or refused and why; an acknowledge that matches no active, unacknowledged
// alarm is logged, answered and not forwarded.  After an outage the buffered
// cage states arrive marked "stale", the alarm transitions of the outage all
// arrive, and live cage states are not marked.
TEST_F(MqttBridge, CommandResultsAndStaleBacklog) {
  dir_ = testDir("mqtt_results");
  const std::string url = urlFor(7938);
  Broker broker(dir_, freeTcpPort());
  broker.start();
  Client c(broker.port(), "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/#");
  Listener lcm(url);
  lcm.subscribe("west/HOIST_ALARM_ACK");
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[broker]\nreconnect_min = 1.0\nreconnect_max = 1.0\n"
                         "[bridge]\nhealth_period = 0.3\nalarm_sync_time = 0.5\n[buffer]\nstale_after = 0.5\n";
  Process bridge({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--channel-prefix",
                  "west/", "--client-id", "bridge-r"},
                 log("bridge.log"));
  ASSERT_TRUE(c.waitJson("hoist/_bridge/bridge-r/status", [](const json& j, bool) { return j.value("online", false); }, 10s));
  const auto west_health = forgedHealth(4244);
  lcm.lcm().publish("west/HOIST_HEALTH", &west_health);
  lcm.pump(200ms);
  auto raise = alarmEvent("CAGE_POS_Y", hoist::alarm_t::EVENT_RAISE, true);
  lcm.lcm().publish("west/HOIST_ALARM", &raise);
  ASSERT_TRUE(c.waitJson("hoist/west/alarm/CAGE_POS_Y", [](const json& j, bool) { return j["active"] == true; }, 5s));
  std::this_thread::sleep_for(600ms);  // alarm_sync_time

  auto result = [&](const std::string& user) {
    return c.waitJson("hoist/west/cmd/result", [&](const json& j, bool) {
      return j.contains("command") ? j["command"]["user"] == user : j["detail"].get<std::string>().find(user) != std::string::npos; }, 5s);
  };
  c.publish("hoist/west/cmd/ack", R"({"kind":"CAGE_POS_Y","level":0,"action":1,"user":"op-ok"})");
  auto r = result("op-ok");
  ASSERT_TRUE(r) << readFile(log("bridge.log"));
  EXPECT_EQ((*r)["result"], "accepted");
  EXPECT_EQ((*r)["reason"], "forwarded");
  EXPECT_EQ((*r)["command"]["kind"], "CAGE_POS_Y");
  ASSERT_TRUE(lcm.waitFor([&] {
    for (const auto& a : lcm.decoded<hoist::alarm_ack_t>("west/HOIST_ALARM_ACK"))
      if (a.user == "op-ok") return true;
    return false;
  }, 5s));

  c.publish("hoist/west/cmd/ack", R"({"kind":"GUIDE_ROPE","level":0,"action":1,"user":"op-none"})");
  r = result("op-none");
  ASSERT_TRUE(r) << readFile(log("bridge.log"));
  EXPECT_EQ((*r)["result"], "refused");
  EXPECT_EQ((*r)["reason"], "no_matching_alarm");
  c.publish("hoist/west/cmd/ack", R"({"kind":"CAGE_POS_Y","level":2,"action":1,"user":"op-crit"})");
  r = result("op-crit");
  ASSERT_TRUE(r);
  EXPECT_EQ((*r)["reason"], "no_matching_alarm") << "no CRITICAL CAGE_POS_Y is active";
  c.publish("hoist/west/cmd/ack", R"({"kind":"CAGE_POS_Y","level":0,"action":1,"user":"op-dup","user":"x"})");
  auto dup = c.waitJson("hoist/west/cmd/result", [](const json& j, bool) { return j["reason"] == "duplicate_key"; }, 5s);
  ASSERT_TRUE(dup);
  EXPECT_EQ((*dup)["result"], "refused");
  lcm.pump(300ms);
  std::size_t forwarded = 0;  // not the bridge's own re-announce request (sent on west/'s first health)
  for (const auto& a : lcm.decoded<hoist::alarm_ack_t>("west/HOIST_ALARM_ACK"))
    forwarded += a.action != hoist::alarm_ack_t::ACTION_REANNOUNCE;
  EXPECT_EQ(forwarded, 1u) << "a refused command was forwarded";
  EXPECT_NE(readFile(log("bridge.log")).find("matches no alarm"), std::string::npos) << readFile(log("bridge.log"));
  for (const auto& m : c.on("hoist/west/cmd/result")) EXPECT_FALSE(m.retain);

  // An outage: cage states and alarm transitions while the broker is down.
  broker.stop();
  hoist::cage_state_t cage{};
  cage.instance_id = 4244;
  for (int i = 0; i < 30; ++i) {
    cage.seq = i;
    lcm.lcm().publish("west/HOIST_CAGE", &cage);
    if (i == 10) {
      auto clear = alarmEvent("CAGE_POS_Y", hoist::alarm_t::EVENT_CLEAR, false);
      lcm.lcm().publish("west/HOIST_ALARM", &clear);
    }
    if (i == 20) {
      auto tilt = alarmEvent("CAGE_TILT", hoist::alarm_t::EVENT_RAISE, true);
      lcm.lcm().publish("west/HOIST_ALARM", &tilt);
    }
    std::this_thread::sleep_for(50ms);
  }
  broker.start();
  Client c2(broker.port(), "c2");  // subscribed before the bridge's next attempt (1 s)
  ASSERT_TRUE(c2.connected());
  c2.subscribe("hoist/#");
  auto clear = c2.waitJson("hoist/west/alarm/CAGE_POS_Y", [](const json& j, bool) { return j["last_event"] == "CLEAR"; }, 10s);
  EXPECT_TRUE(clear) << "an alarm transition of the outage was not sent";
  EXPECT_TRUE(c2.waitJson("hoist/west/alarm/CAGE_TILT", [](const json& j, bool) { return j["active"] == true; }, 5s));
  auto stale = c2.waitJson("hoist/west/cage", [](const json& j, bool) { return j.value("stale", false); }, 5s);
  ASSERT_TRUE(stale) << "the backlog's cage states are not marked stale:\n" << readFile(log("bridge.log"));
  EXPECT_GE((*stale)["stale_age"].get<double>(), 0.5);
  // Live again: new cage states are not marked.
  cage.seq = 1000;
  for (int i = 0; i < 5; ++i) {
    lcm.lcm().publish("west/HOIST_CAGE", &cage);
    std::this_thread::sleep_for(150ms);
  }
  auto live = c2.waitJson("hoist/west/cage", [](const json& j, bool) { return j["seq"] == 1000; }, 5s);
  ASSERT_TRUE(live);
  EXPECT_FALSE(live->contains("stale")) << live->dump();
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0);
}

// The unit's credentials (LoadCredential=mqtt-password:...): the bridge runs
// as a dynamic user that cannot read the 0600 password file named in its
// configuration; systemd hands the password over in $CREDENTIALS_DIRECTORY
// and the bridge connects with it.  Without the credential the unreadable
// file is a configuration error (exit 2), as before.
TEST_F(MqttBridge, PasswordFromSystemdCredential) {
  dir_ = testDir("mqtt_credentials");
  auto path = [&](const char* f) { return (dir_ / f).string(); };
  ASSERT_EQ(runProcess({HOIST_MOSQUITTO_PASSWD, "-b", "-c", path("passwd"), "hoist", "cr3d-pw"}, path("pw.log"), 30s), 0);
  const int port = freeTcpPort(), plain = freeTcpPort();
  std::ofstream(path("mosquitto.conf")) << "per_listener_settings true\npersistence false\nlog_dest stdout\n"
                                        << "listener " << plain << " 127.0.0.1\nallow_anonymous true\n"
                                        << "listener " << port << " 127.0.0.1\nallow_anonymous false\n"
                                        << "password_file " << path("passwd") << "\n";
  Process broker({HOIST_MOSQUITTO, "-c", path("mosquitto.conf")}, path("mosquitto.log"));
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (!(tcpOpen(port) && tcpOpen(plain)) && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(20ms);
  ASSERT_TRUE(tcpOpen(port)) << readFile(path("mosquitto.log"));
  Client c(plain, "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/_bridge/#");
  std::ofstream(path("bridge.toml")) << "[broker]\nurl = \"mqtt://127.0.0.1:" << port << "\"\nusername = \"hoist\"\n"
                                     << "password_file = \"/etc/hoist-twin/mqtt/no-such-site.password\"\n";
  // Without the credential: the unreadable file is bad configuration.
  EXPECT_EQ(runProcess({HOIST_MQTT, "--config", path("bridge.toml"), "--lcm-url", urlFor(7941)}, path("nocred.log"), 10s), 2);
  EXPECT_NE(readFile(path("nocred.log")).find("broker.password_file"), std::string::npos) << readFile(path("nocred.log"));
  // With it (as systemd passes it: a directory in $CREDENTIALS_DIRECTORY).
  std::filesystem::create_directories(dir_ / "creds");
  std::ofstream(path("creds/mqtt-password")) << "cr3d-pw\n";
  std::ofstream(path("creds/mqtt-tls-key")) << "\n";  // blank: the unit's default when no key file exists
  Process bridge({"/usr/bin/env", "CREDENTIALS_DIRECTORY=" + path("creds"), HOIST_MQTT, "--config", path("bridge.toml"),
                  "--lcm-url", urlFor(7941), "--client-id", "bridge-cred"},
                 path("bridge.log"));
  auto st = c.waitJson("hoist/_bridge/bridge-cred/status", [](const json& j, bool) { return j.value("online", false); }, 10s);
  ASSERT_TRUE(st) << readFile(path("bridge.log")) << readFile(path("mosquitto.log"));
  EXPECT_NE(readFile(path("bridge.log")).find("using the systemd credential mqtt-password"), std::string::npos);
  EXPECT_EQ(readFile(path("bridge.log")).find("cr3d-pw"), std::string::npos) << "the password must never be logged";
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0);
}

// The load estimate (HOIST_ESTIMATE, published by the daemon at the cage rate)
// on hoist/<shaft>/estimate: JSON with the .lcm's field names, QoS 0, not
// retained, the latest one at [bridge] cage_rate like the cage state.  The
// test publishes estimate_t itself (realistic values), 100 Hz for 2 s, into a
// bridge with cage_rate = 5 (LCM port 7841, broker port 18900).
TEST_F(MqttBridge, EstimateAtTheCageRateNotRetained) {
  dir_ = testDir("mqtt_estimate");
  const std::string url = urlFor(7841);
  Broker broker(dir_, 18900);
  broker.start();
  Client c(broker.port(), "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/#");
  Listener lcm(url);
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[bridge]\ncage_rate = 5\nhealth_period = 0.5\nchannel_prefixes = [\"north/\"]\n";
  Process bridge({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--client-id", "bridge-e"},
                 log("bridge.log"));
  ASSERT_TRUE(c.waitJson("hoist/_bridge/bridge-e/status", [](const json& j, bool) { return j.value("online", false); }, 10s))
      << readFile(log("bridge.log"));
  auto estimate = [](std::int64_t seq) {
    hoist::estimate_t e{};
    e.utime = 1'700'000'000'000'000 + seq * 10'000;
    e.seq = seq;
    e.t = 0.01 * static_cast<double>(seq);
    e.l = 100.0 + 0.045 * static_cast<double>(seq);
    e.v = 4.5;
    e.Fa = 1500.0 + 0.01 * static_cast<double>(seq);
    e.sigma_Fa = 3.0;
    e.b = 0.6;
    e.sigma_b = 0.01;
    e.moment = e.Fa * e.b;
    e.sigma_moment = 15.0;
    e.theta = 6.5e-4;
    e.sigma_theta = 1e-5;
    e.theta_open = 8.3e-4;
    for (int i = 0; i < 5; ++i) {
      e.lambdas[i] = i == 0 ? 31000.0 : 40.0 * i;
      e.sigma_lambdas[i] = 1.0 + i;
    }
    e.nis_dof = 300;
    e.nis_window = 306.0;
    e.nis_lower = 253.9;
    e.nis_upper = 349.9;
    e.nis_bound = 372.0;
    e.sensors = 7;
    e.imu_age = 0.004;
    e.rope_load_age = 0.009;
    e.fa_observed = 1;
    e.moment_observed = 1;
    return e;
  };
  const std::int64_t n = 200;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::int64_t i = 1; i <= n; ++i) {
    auto e = estimate(i);
    if (i == n) e.sigma_b = -1.0;  // the last one: b not observed
    lcm.lcm().publish("north/HOIST_ESTIMATE", &e);
    lcm.pump(10ms);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string topic = "hoist/north/estimate";
  // The latest estimate arrives (within one cage period and a bit).
  auto last = c.waitJson(topic, [&](const json& j, bool) { return j.value("seq", 0) == n; }, 5s);
  ASSERT_TRUE(last) << readFile(log("bridge.log"));
  EXPECT_DOUBLE_EQ((*last)["Fa"].get<double>(), 1500.0 + 0.01 * n);
  EXPECT_DOUBLE_EQ((*last)["sigma_Fa"].get<double>(), 3.0);
  EXPECT_LT((*last)["sigma_b"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ((*last)["theta_open"].get<double>(), 8.3e-4);
  ASSERT_TRUE((*last)["lambdas"].is_array());
  EXPECT_EQ((*last)["lambdas"].size(), 5u);
  EXPECT_DOUBLE_EQ((*last)["sigma_lambdas"][4].get<double>(), 5.0);
  EXPECT_EQ((*last)["nis_dof"].get<int>(), 300);
  EXPECT_DOUBLE_EQ((*last)["nis_bound"].get<double>(), 372.0);
  EXPECT_EQ((*last)["sensors"].get<int>(), 7);
  const auto got = c.on(topic);
  for (const auto& m : got) EXPECT_FALSE(m.retain) << m.payload;
  // Rate handling as for the cage: at most about cage_rate per second, not every message.
  EXPECT_GE(got.size(), 2u);
  EXPECT_LE(static_cast<double>(got.size()), 5.0 * (seconds + 1.5) + 2.0) << got.size() << " in " << seconds << " s";
  EXPECT_LT(got.size(), static_cast<std::size_t>(n / 4));
  // Counted in the bridge's health.
  auto bh = c.waitJson("hoist/_bridge/bridge-e/health", [&](const json& j, bool) {
    return !j["shafts"].empty() && j["shafts"][0].value("estimates_in", 0) >= n - 5;
  }, 3s);
  ASSERT_TRUE(bh) << readFile(log("bridge.log"));
  EXPECT_EQ((*bh)["shafts"][0]["estimates_out"].get<std::size_t>(), c.on(topic).size());
  // Not retained: a late subscriber gets none.
  Client late(broker.port(), "late");
  ASSERT_TRUE(late.connected());
  late.subscribe(topic);
  std::this_thread::sleep_for(700ms);
  EXPECT_TRUE(late.on(topic).empty());
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0);
}

// An alarm raised before the bridge starts is published on MQTT right after
// the bridge hears the daemon -- as its current state (active, WARNING), never
// first as a CLEAR -- without waiting for the periodic re-announce (an hour
// here): the bridge asks the daemon to re-announce (alarm_ack_t
// ACTION_REANNOUNCE).  A configured shaft and a discovered one.  LCM port 8001.
TEST_F(MqttBridge, AnAlarmRaisedBeforeTheBridgeStartsAppearsAtOnce) {
  dir_ = testDir("mqtt_alarm_at_start");
  const std::string url = urlFor(8001);
  Broker broker(dir_, freeTcpPort());
  broker.start();
  Client c(broker.port(), "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/#");
  Listener lcm(url);
  lcm.subscribe("north/HOIST_(HEALTH|ALARM|ALARM_ACK)");
  std::string twin = readFile(daemonConfig(dir_, "north/"));
  const auto pos = twin.find("reannounce = ");
  ASSERT_NE(pos, std::string::npos);
  twin.replace(pos, twin.find('\n', pos) - pos, "reannounce = 3600.0");
  std::ofstream((dir_ / "twin_quiet.toml").string()) << twin;
  auto twind = startDaemonAndWait(lcm, {HOIST_TWIND, "--config", (dir_ / "twin_quiet.toml").string(), "--lcm-url", url},
                                  log("twind.log"), "north/HOIST_HEALTH");
  Process replay({HOIST_REPLAY, "--profile", "rest:t_end=60", "--lcm-url", url, "--channel-prefix", "north/"},
                 log("replay.log"));
  // CAGE_POS_Y WARNING (demo.toml's 16 mm gap) is raised before any bridge runs.
  ASSERT_TRUE(lcm.waitFor([&] {
    for (const auto& a : lcm.decoded<hoist::alarm_t>("north/HOIST_ALARM"))
      if (a.kind == "CAGE_POS_Y" && a.event_type == hoist::alarm_t::EVENT_RAISE) return true;
    return false;
  }, 15s)) << readFile(log("twind.log"));
  lcm.pump(500ms);

  auto firstState = [&](const std::string& topic) -> std::optional<json> {
    for (const auto& m : c.on(topic)) return json::parse(m.payload, nullptr, false);
    return std::nullopt;
  };
  const auto t0 = std::chrono::steady_clock::now();
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[bridge]\nhealth_period = 0.5\n";
  Process configured({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--channel-prefix",
                      "north/", "--client-id", "bridge-s"},
                     log("bridge.log"));
  std::optional<json> alarm;
  lcm.waitFor([&] {
    alarm = c.waitJson("hoist/north/alarm/CAGE_POS_Y", [](const json& j, bool) { return isWarningActive(j); }, 0ms);
    return alarm.has_value();
  }, 10s);
  ASSERT_TRUE(alarm) << readFile(log("bridge.log")) << readFile(log("twind.log"));
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(took, 8.0) << "not the periodic re-announce (3600 s)";
  EXPECT_EQ((*alarm)["last_event"], "REANNOUNCE");
  EXPECT_TRUE((*alarm)["unacked"].get<bool>());
  const auto first = firstState("hoist/north/alarm/CAGE_POS_Y");
  ASSERT_TRUE(first);
  EXPECT_TRUE((*first)["active"].get<bool>()) << "the first state published is the alarm's state, not a CLEAR: "
                                              << first->dump();
  // Alarms that never had a state are not invented.
  EXPECT_TRUE(c.on("hoist/north/alarm/GUIDE_ROPE").empty());
  configured.signal(SIGTERM);
  EXPECT_EQ(configured.wait(5s), 0);

  // A discovering bridge (no --channel-prefix) asks when it confirms the shaft.
  Client c2(broker.port(), "c2");
  ASSERT_TRUE(c2.connected());
  c2.subscribe("hoist/+/alarm/#");
  lcm.pump(300ms);
  const std::size_t retained_seen = c2.on("hoist/north/alarm/CAGE_POS_Y").size();  // the first bridge's retained state
  const auto t1 = std::chrono::steady_clock::now();
  Process discovering({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--client-id",
                       "bridge-d2"},
                      log("bridge2.log"));
  ASSERT_TRUE(lcm.waitFor([&] { return c2.on("hoist/north/alarm/CAGE_POS_Y").size() > retained_seen; }, 15s))
      << readFile(log("bridge2.log"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count(), 10.0);
  const json fresh = json::parse(c2.on("hoist/north/alarm/CAGE_POS_Y")[retained_seen].payload);
  EXPECT_TRUE(isWarningActive(fresh)) << fresh.dump();
  auto requests = [&] {
    std::size_t n = 0;
    for (const auto& a : lcm.decoded<hoist::alarm_ack_t>("north/HOIST_ALARM_ACK"))
      n += a.action == hoist::alarm_ack_t::ACTION_REANNOUNCE;
    return n;
  };
  lcm.waitFor([&] { return requests() >= 2; }, 3s);
  lcm.pump(500ms);
  EXPECT_EQ(requests(), 2u) << "one request per bridge";
  discovering.signal(SIGTERM);
  EXPECT_EQ(discovering.wait(5s), 0);
  stopDaemonCleanly(*twind, log("twind.log"));
}

// Issue 33: operator commands carry an identity the broker vouches for.  The
// shipped example mosquitto.conf and ACL (tools/mqtt/config), with this
// test's port and files: an operator writes only hoist/<shaft>/cmd/ack/<its
// user>; another user's flood on its own topic never takes the operator's
// share; a forged topic never reaches the bridge; a payload naming somebody
// else is refused; a 2 MiB payload is stopped by the broker (max_packet_size).
TEST_F(MqttBridge, PerUserCommandTopicsWithTheExampleAcl) {
  dir_ = testDir("mqtt_acl");
  auto path = [&](const std::string& f) { return (dir_ / f).string(); };
  const std::string url = urlFor(7976);
  bool first = true;
  for (const auto& [user, pw] : std::vector<std::pair<std::string, std::string>>{
           {"hoist-bridge", "b-pw"}, {"op1", "op1-pw"}, {"mallory", "m-pw"}, {"scada", "s-pw"}}) {
    std::vector<std::string> cmd{HOIST_MOSQUITTO_PASSWD, "-b"};
    if (first) cmd.push_back("-c");
    first = false;
    for (const auto& a : {path("passwd"), user, pw}) cmd.push_back(a);
    ASSERT_EQ(runProcess(cmd, path("pw.log"), 30s), 0) << readFile(path("pw.log"));
  }
  const int port = freeTcpPort();
  std::string conf = readFile(HOIST_MQTT_CONFIG_DIR "/mosquitto.conf");
  auto replace = [&](const std::string& from, const std::string& to) {  // every occurrence
    ASSERT_NE(conf.find(from), std::string::npos) << from;
    for (auto at = conf.find(from); at != std::string::npos; at = conf.find(from, at + to.size()))
      conf.replace(at, from.size(), to);
  };
  replace("listener 8883", "listener " + std::to_string(port) + " 127.0.0.1");
  replace("/etc/mosquitto/hoist.passwd", path("passwd"));
  replace("/etc/mosquitto/hoist-acl.conf", HOIST_MQTT_CONFIG_DIR "/mosquitto-acl.conf");
  std::ofstream(path("mosquitto.conf")) << conf << "persistence false\nlog_dest stdout\n";
  Process broker({HOIST_MOSQUITTO, "-c", path("mosquitto.conf")}, path("mosquitto.log"));
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (!tcpOpen(port) && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(20ms);
  ASSERT_TRUE(tcpOpen(port)) << readFile(path("mosquitto.log"));

  std::ofstream(path("bridge.pw")) << "b-pw\n";
  ::chmod(path("bridge.pw").c_str(), 0600);
  std::ofstream(path("bridge.toml")) << "[broker]\nurl = \"mqtt://127.0.0.1:" << port << "\"\nusername = \"hoist-bridge\"\n"
                                     << "password_file = \"" << path("bridge.pw") << "\"\n"
                                     << "[bridge]\nchannel_prefixes = [\"north/\"]\nhealth_period = 0.3\n"
                                     << "command_rate = 0.2\ncommand_burst = 3\n";
  Listener lcm(url);
  lcm.subscribe("north/HOIST_ALARM_ACK");
  Process bridge({HOIST_MQTT, "--config", path("bridge.toml"), "--lcm-url", url, "--client-id", "bridge-acl"},
                 log("bridge.log"));
  Client scada(port, "scada-c", "scada", "s-pw");
  ASSERT_TRUE(scada.connected()) << readFile(path("mosquitto.log"));
  scada.subscribe("hoist/#");
  ASSERT_TRUE(scada.waitJson("hoist/_bridge/bridge-acl/health", [](const json& j, bool) {
    return j["connection"]["state"] == "connected"; }, 10s)) << readFile(log("bridge.log"));
  Client op1(port, "op1-c", "op1", "op1-pw"), mallory(port, "mallory-c", "mallory", "m-pw");
  ASSERT_TRUE(op1.connected() && mallory.connected()) << readFile(path("mosquitto.log"));
  op1.subscribe("hoist/north/cmd/result");
  const std::string unshelve = R"({"kind":"*","level":0,"action":3})";
  for (int i = 0; i < 40; ++i) mallory.publish("hoist/north/cmd/ack/mallory", unshelve);
  for (int i = 0; i < 5; ++i) mallory.publish("hoist/north/cmd/ack/op1", unshelve);  // the ACL drops these
  mallory.publish("hoist/north/cmd/ack/mallory", std::string(2u << 20, 'x'));  // over max_packet_size
  std::this_thread::sleep_for(500ms);
  for (int i = 0; i < 3; ++i) op1.publish("hoist/north/cmd/ack/op1", unshelve);
  auto usersOn = [&](const std::string& user) {
    std::size_t n = 0;
    for (const auto& a : lcm.decoded<hoist::alarm_ack_t>("north/HOIST_ALARM_ACK"))
      n += a.action == hoist::alarm_ack_t::ACTION_UNSHELVE && a.user == user;
    return n;
  };
  EXPECT_TRUE(lcm.waitFor([&] { return usersOn("op1") == 3; }, 10s)) << readFile(log("bridge.log"));
  lcm.pump(500ms);
  EXPECT_EQ(usersOn("op1"), 3u) << "a forged cmd/ack/op1 reached the daemon";
  EXPECT_LE(usersOn("mallory"), 3u) << "mallory got more than its own burst";
  EXPECT_GE(usersOn("mallory"), 1u);
  // A payload naming somebody else is refused (the topic's user is the identity).
  op1.publish("hoist/north/cmd/ack/op1", R"({"kind":"*","level":0,"action":3,"user":"mallory"})");
  auto refused = op1.waitJson("hoist/north/cmd/result", [](const json& j, bool) { return j["reason"] == "bad_user"; }, 5s);
  EXPECT_TRUE(refused) << readFile(log("bridge.log"));
  auto h = scada.waitJson("hoist/_bridge/bridge-acl/health", [](const json& j, bool) {
    return j["commands"]["rejected_by_reason"]["bad_user"] == 1; }, 5s);
  ASSERT_TRUE(h) << readFile(log("bridge.log"));
  EXPECT_EQ((*h)["commands"]["rejected_by_reason"]["oversized"], 0) << "the 2 MiB payload reached the bridge";
  EXPECT_GE((*h)["commands"]["rejected_by_reason"]["rate_limited"].get<int>(), 30);
  EXPECT_TRUE(bridge.running());
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0) << readFile(log("bridge.log"));

  // Sparkplug DCMDs carry no host identity: the example ACL is what tells
  // hosts apart.  Only the primary host's user ("scada") may write DCMD, so
  // mallory's never reach a Sparkplug bridge behind it (and cannot take the
  // primary host's command budget); the primary host's own junk DCMD does
  // (counted bad_payload).
  std::ofstream(path("sp.toml")) << "[broker]\nurl = \"mqtt://127.0.0.1:" << port << "\"\nusername = \"hoist-bridge\"\n"
                                 << "password_file = \"" << path("bridge.pw") << "\"\n"
                                 << "[bridge]\nchannel_prefixes = [\"north/\"]\nhealth_period = 0.3\n"
                                 << "[sparkplug]\nenabled = true\ngroup_id = \"Mine\"\nedge_node_id = \"Edge1\"\n";
  Process sp({HOIST_MQTT, "--config", path("sp.toml"), "--lcm-url", url, "--client-id", "bridge-sp"},
             log("bridge-sp.log"));
  ASSERT_TRUE(scada.waitJson("hoist/_bridge/bridge-sp/health", [](const json& j, bool) {
    return j["connection"]["state"] == "connected"; }, 10s)) << readFile(log("bridge-sp.log"));
  const std::string junk("\xff\xff\xff\xff\xff", 5);
  for (int i = 0; i < 5; ++i) mallory.publish("spBv1.0/Mine/DCMD/Edge1/north", junk);
  std::this_thread::sleep_for(300ms);
  scada.publish("spBv1.0/Mine/DCMD/Edge1/north", junk);
  auto badPayload = [](const json& j) { return j["commands"]["rejected_by_reason"].value("bad_payload", 0); };
  ASSERT_TRUE(scada.waitJson("hoist/_bridge/bridge-sp/health", [&](const json& j, bool) { return badPayload(j) >= 1; },
                             10s)) << readFile(log("bridge-sp.log"));
  std::this_thread::sleep_for(500ms);
  auto last = scada.waitJson("hoist/_bridge/bridge-sp/health", [](const json&, bool) { return true; }, 5s);
  ASSERT_TRUE(last);
  EXPECT_EQ(badPayload(*last), 1) << "a DCMD of a user who is not the primary host reached the bridge";
  sp.signal(SIGTERM);
  EXPECT_EQ(sp.wait(5s), 0) << readFile(log("bridge-sp.log"));
  broker.signal(SIGTERM);
  broker.wait(5s);
}

// Issue 33: a dropped alarm transition is never silent -- counted, logged
// (rate-limited) and the bridge's health is WARNING.  The broker is down at
// start and the memory buffer holds one alarm transition; five arrive.
TEST_F(MqttBridge, DroppedAlarmTransitionsAreLoggedAndWarn) {
  dir_ = testDir("mqtt_alarm_drops");
  const std::string url = urlFor(7977);
  const int port = freeTcpPort();
  Broker broker(dir_, port);
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[broker]\nreconnect_min = 0.2\nreconnect_max = 0.5\n[bridge]\nhealth_period = 0.3\n"
                      << "channel_prefixes = [\"north/\"]\n[buffer]\nmax_alarm_events = 1\n";
  Listener lcm(url);
  Process bridge({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--client-id", "bridge-w"},
                 log("bridge.log"));
  std::this_thread::sleep_for(500ms);
  const auto north_health = forgedHealth(4245);
  lcm.lcm().publish("north/HOIST_HEALTH", &north_health);
  lcm.pump(200ms);
  for (int i = 0; i < 5; ++i) {
    hoist::alarm_t a{};
    a.instance_id = 4245;
    a.id = i + 1;
    a.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::system_clock::now().time_since_epoch()).count();
    a.kind = "CAGE_POS_Y";
    a.level = 1;
    a.active = (i % 2) == 0;
    a.event_type = a.active ? hoist::alarm_t::EVENT_RAISE : hoist::alarm_t::EVENT_CLEAR;
    lcm.lcm().publish("north/HOIST_ALARM", &a);
    lcm.pump(50ms);
  }
  const auto end = std::chrono::steady_clock::now() + 10s;
  while (readFile(log("bridge.log")).find("alarm transitions dropped") == std::string::npos &&
         std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(50ms);
  const std::string text = readFile(log("bridge.log"));
  EXPECT_NE(text.find("alarm transitions dropped from the memory buffer ([buffer] max_alarm_events = 1"),
            std::string::npos) << text;
  broker.start();
  Client c(port, "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/_bridge/#");
  // (Health messages queued before the drops arrive first: wait for a later one.)
  auto h = c.waitJson("hoist/_bridge/bridge-w/health", [](const json& j, bool) {
    return j["buffer"]["dropped_alarm"] == 4; }, 10s);
  ASSERT_TRUE(h) << readFile(log("bridge.log"));
  EXPECT_EQ((*h)["level"], "WARNING") << h->dump();
  EXPECT_EQ((*h)["buffer"]["dropped_alarm"], 4) << h->dump();
  ASSERT_EQ((*h)["warnings"].size(), 1u) << h->dump();
  EXPECT_NE((*h)["warnings"][0].get<std::string>().find("4 alarm transitions dropped"), std::string::npos);
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0);
  broker.stop();
}

// Issue 33: one forged alarm_t CLEAR of the active CAGE_POS_Y on HOIST_ALARM,
// from another daemon instance, turned the retained hoist/north/alarm/CAGE_POS_Y
// inactive, and nothing logged it.  Now the bridge accepts alarm events only
// from the instance whose health it follows: the retained state stays active,
// the drop is counted (health lcm.foreign_instance) and logged.  A forged
// health stream of another instance under the same prefix while the daemon
// talks is an impostor: dropped and logged, never a "restart" that clears the
// shaft's alarms, and commands still reach the daemon.
TEST_F(MqttBridge, ForgedAlarmClearAndImpostorHealthCostOnlyTheForger) {
  dir_ = testDir("mqtt_forged_alarm");
  const std::string url = urlFor(7981);
  Broker broker(dir_, freeTcpPort());
  broker.start();
  Client c(broker.port(), "c");
  ASSERT_TRUE(c.connected());
  c.subscribe("hoist/#");
  Listener lcm(url);
  lcm.subscribe("north/HOIST_(HEALTH|ALARM|ALARM_ACK)");
  auto twind = startDaemonAndWait(lcm, {HOIST_TWIND, "--config", daemonConfig(dir_, "north/"), "--lcm-url", url},
                                  log("twind.log"), "north/HOIST_HEALTH");
  Process replay({HOIST_REPLAY, "--profile", "rest:t_end=60", "--lcm-url", url, "--channel-prefix", "north/"},
                 log("replay.log"));
  const auto bcfg = (dir_ / "bridge.toml").string();
  std::ofstream(bcfg) << "[bridge]\nhealth_period = 0.3\n";
  Process bridge({HOIST_MQTT, "--broker", broker.url(), "--config", bcfg, "--lcm-url", url, "--channel-prefix",
                  "north/", "--client-id", "bridge-f"},
                 log("bridge.log"));
  ASSERT_TRUE(c.waitJson("hoist/north/alarm/CAGE_POS_Y", [](const json& j, bool) { return isWarningActive(j); }, 15s))
      << readFile(log("bridge.log")) << readFile(log("twind.log"));
  const auto real = lcm.decoded<hoist::health_t>("north/HOIST_HEALTH").back().instance_id;
  const std::size_t before = c.on("hoist/north/alarm/CAGE_POS_Y").size();
  hoist::alarm_t forged{};
  forged.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                     std::chrono::system_clock::now().time_since_epoch()).count();
  forged.kind = "CAGE_POS_Y";
  forged.level = hoist::alarm_t::LEVEL_WARNING;
  forged.event_type = hoist::alarm_t::EVENT_CLEAR;
  forged.acked = 1;
  forged.message = "all clear";
  forged.user = "";
  forged.instance_id = real + 1;
  lcm.lcm().publish("north/HOIST_ALARM", &forged);
  // The impostor's health, at 10 Hz for a second, under the real prefix.
  for (int i = 0; i < 10; ++i) {
    const auto h = forgedHealth(real + 2);
    lcm.lcm().publish("north/HOIST_HEALTH", &h);
    lcm.pump(100ms);
  }
  // Commands keep going to the real shaft.
  c.publish("hoist/north/cmd/ack", R"({"kind":"CAGE_POS_Y","level":0,"action":1,"user":"scada-op"})");
  EXPECT_TRUE(lcm.waitFor([&] {
    for (const auto& a : lcm.decoded<hoist::alarm_ack_t>("north/HOIST_ALARM_ACK"))
      if (a.user == "scada-op") return true;
    return false;
  }, 5s)) << readFile(log("bridge.log"));
  auto health = c.waitJson("hoist/_bridge/bridge-f/health", [](const json& j, bool) {
    return j["lcm"]["foreign_instance"].value("HOIST_ALARM", 0) >= 1 && j["lcm"].value("impostor_health", 0) >= 1;
  }, 5s);
  EXPECT_TRUE(health) << readFile(log("bridge.log"));
  const auto states = c.on("hoist/north/alarm/CAGE_POS_Y");
  for (std::size_t i = before; i < states.size(); ++i) {
    const json j = json::parse(states[i].payload);
    EXPECT_NE(j.value("last_event", ""), "CLEAR") << "the forged CLEAR was published: " << j.dump();
    EXPECT_TRUE(j["active"].get<bool>()) << j.dump();
  }
  for (const auto& m : c.on("hoist/north/health"))
    EXPECT_EQ(json::parse(m.payload)["instance_id"], real) << "an impostor's health was published as north's";
  bridge.signal(SIGTERM);
  EXPECT_EQ(bridge.wait(5s), 0);
  const std::string text = readFile(log("bridge.log"));
  EXPECT_NE(text.find("dropped HOIST_ALARM of daemon instance " + std::to_string(real + 1)), std::string::npos) << text;
  EXPECT_NE(text.find("health of another daemon instance " + std::to_string(real + 2)), std::string::npos) << text;
  EXPECT_EQ(text.find("new daemon instance"), std::string::npos) << "the impostor was taken for a restart:\n" << text;
  stopDaemonCleanly(*twind, log("twind.log"));
}
