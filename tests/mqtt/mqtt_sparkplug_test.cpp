// hoist-mqtt in Sparkplug B mode against an independent Sparkplug host: a
// real mosquitto (ports 18620-18639), the real bridge, and a host written in
// Node with the Eclipse Tahu payload package (npm sparkplug-payload) and
// mqtt.js (tests/mqtt/sparkplug_host/host.js).  The test publishes known LCM
// messages (loopback multicast, ports 8060-8079) and listens for
// HOIST_ALARM_ACK as the daemon would.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "lcm_fixtures.hpp"
#include "tcp.hpp"
#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/health_t.hpp"

using namespace std::chrono_literals;
using namespace hoist::test;
using json = nlohmann::json;

namespace {

/// The last lines of a log (failure messages stay readable).
std::string tail(const std::string& path, std::size_t bytes = 3000) {
  const std::string t = readFile(path);
  return t.size() > bytes ? "...\n" + t.substr(t.size() - bytes) : t;
}

bool have(const char* path) { return path[0] != '\0' && std::filesystem::exists(path); }

/// The broker, the host and the bridge of one test.
class MqttSparkplug : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have(HOIST_MOSQUITTO)) GTEST_SKIP() << "mosquitto not found (scripts/setup.sh installs it)";
    if (!have(HOIST_NODE)) GTEST_SKIP() << "node not found (scripts/setup.sh installs it)";
    if (!std::filesystem::exists(std::string(HOIST_SPARKPLUG_HOST_DIR) + "/node_modules/sparkplug-payload"))
      GTEST_SKIP() << "npm packages of tests/mqtt/sparkplug_host missing (scripts/setup.sh runs npm ci there)";
    std::string why;
    if (!loopbackMulticastWorks(urlFor(8060), why)) GTEST_FAIL() << kMulticastHelp << " (" << why << ")";
    dir_ = testDir(std::string("sparkplug_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override {
    if (host_) command("quit");
    bridge_.reset();
    if (host_) host_->wait(3s);
    host_.reset();
    broker_.reset();
  }

  void start(int port, int lcm_port, const std::string& extra_toml = "", const std::vector<std::string>& args = {}) {
    port_ = port;
    lcm_url_ = urlFor(lcm_port);
    const auto conf = (dir_ / "mosquitto.conf").string();
    std::ofstream(conf) << "listener " << port << " 127.0.0.1\nallow_anonymous true\npersistence false\n"
                        << "max_queued_messages 20000\nlog_dest stdout\n";
    broker_ = std::make_unique<Process>(std::vector<std::string>{HOIST_MOSQUITTO, "-c", conf},
                                        (dir_ / "mosquitto.log").string());
    const auto end = std::chrono::steady_clock::now() + 10s;
    while (!tcpOpen(port) && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(20ms);
    ASSERT_TRUE(tcpOpen(port)) << readFile((dir_ / "mosquitto.log").string());
    cmd_file_ = (dir_ / "host.cmd").string();
    std::ofstream(cmd_file_, std::ios::trunc).flush();
    host_log_ = (dir_ / "host.log").string();
    host_ = std::make_unique<Process>(
        std::vector<std::string>{HOIST_NODE, std::string(HOIST_SPARKPLUG_HOST_DIR) + "/host.js",
                                 "mqtt://127.0.0.1:" + std::to_string(port), "Mine", "Edge1", cmd_file_},
        host_log_);
    ASSERT_TRUE(waitLog("READY", 15s)) << tail(host_log_);
    config_ = (dir_ / "bridge.toml").string();
    std::ofstream(config_) << "[bridge]\nhealth_period = 0.3\ncage_rate = 50\nchannel_prefixes = [\"north/\"]\n"
                           << "[sparkplug]\nenabled = true\ngroup_id = \"Mine\"\nedge_node_id = \"Edge1\"\n"
                           << extra_toml;
    startBridge(args);
  }

  void startBridge(const std::vector<std::string>& more = {}) {
    std::vector<std::string> argv{HOIST_MQTT, "--config", config_, "--broker", "mqtt://127.0.0.1:" + std::to_string(port_),
                                  "--lcm-url", lcm_url_, "--client-id", "sp-bridge"};
    argv.insert(argv.end(), more.begin(), more.end());
    bridge_ = std::make_unique<Process>(argv, (dir_ / ("bridge" + std::to_string(++bridges_) + ".log")).string());
  }

  void command(const std::string& line) {
    std::ofstream(cmd_file_, std::ios::app) << line << "\n";
  }

  bool waitLog(const std::string& what, std::chrono::milliseconds timeout, std::size_t n = 1) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      const std::string t = readFile(host_log_);
      std::size_t c = 0;
      for (auto p = t.find(what); p != std::string::npos; p = t.find(what, p + 1)) ++c;
      if (c >= n) return true;
      std::this_thread::sleep_for(30ms);
    }
    return false;
  }

  /// Every MSG line of the host, decoded.
  std::vector<json> messages() {
    std::vector<json> out;
    std::istringstream in(readFile(host_log_));
    for (std::string line; std::getline(in, line);)
      if (line.rfind("MSG ", 0) == 0) {
        json j = json::parse(line.substr(4), nullptr, false);
        if (!j.is_discarded()) out.push_back(j);
      }
    return out;
  }
  std::vector<json> ofType(const std::string& type) {
    std::vector<json> out;
    for (auto& m : messages())
      if (m.value("type", "") == type) out.push_back(m);
    return out;
  }
  /// Waits for a message satisfying pred.
  std::optional<json> waitMsg(const std::function<bool(const json&)>& pred, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    do {
      for (auto& m : messages())
        if (pred(m)) return m;
      std::this_thread::sleep_for(30ms);
    } while (std::chrono::steady_clock::now() < end);
    return std::nullopt;
  }
  json report() {
    const std::string marker = "REPORT ";
    const std::size_t before = [&] {
      const std::string t = readFile(host_log_);
      std::size_t c = 0;
      for (auto p = t.find(marker); p != std::string::npos; p = t.find(marker, p + 1)) ++c;
      return c;
    }();
    command("report");
    EXPECT_TRUE(waitLog(marker, 5s, before + 1));
    const std::string t = readFile(host_log_);
    const auto p = t.rfind(marker);
    return json::parse(t.substr(p + marker.size(), t.find('\n', p) - p - marker.size()), nullptr, false);
  }
  /// The DDATA carrying Cage/Seq = seq (the alias from the DBIRTH); with
  /// `historical`, only one whose is_historical flag is that.
  std::optional<json> cageSeqData(std::int64_t seq, std::optional<bool> historical, std::chrono::milliseconds timeout) {
    json alias;
    for (const auto& b : ofType("DBIRTH"))
      for (const auto& x : b["metrics"])
        if (x["name"] == "Cage/Seq") alias = x["alias"];
    return waitMsg(
        [&](const json& m) {
          if (m.value("type", "") != "DDATA") return false;
          for (const auto& x : m["metrics"])
            if (x["alias"] == alias && x["value"] == seq)
              return !historical || x.value("historical", false) == *historical;
          return false;
        },
        timeout);
  }
  /// The bridge's latest health (hoist/_bridge/<id>/health) satisfying pred.
  std::optional<json> waitHealth(const std::function<bool(const json&)>& pred, std::chrono::milliseconds timeout) {
    auto m = waitMsg([&](const json& j) { return j.contains("json") && j["json"].is_object() && pred(j["json"]); },
                     timeout);
    return m ? std::optional<json>((*m)["json"]) : std::nullopt;
  }

  std::filesystem::path dir_;
  int port_ = 0;
  std::string lcm_url_, cmd_file_, host_log_, config_;
  std::unique_ptr<Process> broker_, host_, bridge_;
  int bridges_ = 0;
};

hoist::cage_state_t cage(int k) {
  hoist::cage_state_t m{};
  m.utime = 1'700'000'000'000'000 + k * 1000;
  m.seq = 100 + k;
  m.instance_id = 77;
  m.t = 10.0 + 0.02 * k;
  m.l = 300.0 + 1.25 * k;
  m.v = 0.5 * k;
  m.a = -0.125 * k;
  m.y_c = 0.001 * k;
  m.theta = 1e-4 * k;
  m.lambdas[0] = 51000.0 + k;
  m.min_clearance = 0.2 - 0.01 * k;
  m.alarm_level = static_cast<std::int8_t>(k % 3);
  m.degraded = k % 2 == 1;
  return m;
}

/// The test's own mapping of cage metrics to the LCM fields (not the bridge's table).
std::vector<std::pair<std::string, double>> cageFields(const hoist::cage_state_t& m) {
  return {{"Cage/Seq", double(m.seq)},         {"Cage/Model Time", m.t},  {"Cage/Length", m.l},
          {"Cage/Velocity", m.v},              {"Cage/Acceleration", m.a}, {"Cage/Lateral", m.y_c},
          {"Cage/Rotation", m.theta},          {"Cage/Rope Force", m.lambdas[0]},
          {"Cage/Min Clearance", m.min_clearance}, {"Cage/Alarm Level", double(m.alarm_level)},
          {"Cage/Degraded", m.degraded ? 1.0 : 0.0}};
}

double asNumber(const json& v) {
  if (v.is_boolean()) return v.get<bool>() ? 1.0 : 0.0;
  if (v.is_number()) return v.get<double>();
  return std::nan("");
}

hoist::alarm_t raise(const std::string& kind) {
  hoist::alarm_t a{};
  a.utime = 1'700'000'001'000'000;
  a.id = 1;
  a.instance_id = 77;  // the daemon whose health the bridge follows (issue 33)
  a.kind = kind;
  a.level = hoist::alarm_t::LEVEL_WARNING;
  a.event_type = hoist::alarm_t::EVENT_RAISE;
  a.active = true;
  a.value = 0.01;
  a.threshold = 0.02;
  a.message = "test";
  a.user = "";
  return a;
}

const char* kAck = R"([{"name":"Alarms/CAGE_POS_Y/Ack","type":"Boolean","value":true}])";

/// The operator commands among what the bridge sent on `channel`: not the
/// re-announce requests (ACTION_REANNOUNCE) it sends when it first hears a
/// daemon, even with --no-commands (they change nothing).
template <class L>
std::vector<hoist::alarm_ack_t> operatorCommands(L& listener, const std::string& channel) {
  std::vector<hoist::alarm_ack_t> out;
  for (const auto& a : listener.template decoded<hoist::alarm_ack_t>(channel))
    if (a.action != hoist::alarm_ack_t::ACTION_REANNOUNCE) out.push_back(a);
  return out;
}

}  // namespace

TEST_F(MqttSparkplug, IndependentHostChecksBirthsDataRebirthAckAndDeath) {
  ASSERT_NO_FATAL_FAILURE(start(18620, 8060, "[sparkplug.deadbands]\n\"Health/Uptime\" = 1000\n"));
  Listener acks(lcm_url_);
  acks.subscribe("north/HOIST_ALARM_ACK");
  ::lcm::LCM pub(lcm_url_);

  // Births: NBIRTH (bdSeq, Rebirth) then the shaft's DBIRTH, before any LCM input.
  auto dbirth = waitMsg([](const json& m) { return m.value("type", "") == "DBIRTH"; }, 15s);
  ASSERT_TRUE(dbirth) << tail(host_log_) << tail((dir_ / "bridge1.log").string());
  EXPECT_EQ((*dbirth)["device"], "north");
  std::map<std::string, json> born;  // name -> metric
  for (const auto& m : (*dbirth)["metrics"]) born[m["name"]] = m;
  for (const char* name : {"Cage/Length", "Health/Degraded", "Alarms/CAGE_POS_Y/Level", "Alarms/CAGE_POS_Y/Active",
                           "Alarms/CAGE_POS_Y/Acked", "Alarms/CAGE_POS_Y/Shelved", "Alarms/MODEL_MISMATCH/Ack",
                           "Forecast/Min Clearance", "Estimate/Load Force"})
    EXPECT_TRUE(born.count(name)) << name;
  EXPECT_EQ(born["Cage/Length"]["type"], "Double");
  EXPECT_EQ(born["Cage/Length"]["units"], "m");
  EXPECT_EQ(born["Cage/Velocity"]["units"], "m/s");
  EXPECT_EQ(born["Alarms/CAGE_POS_Y/Active"]["type"], "Boolean");
  EXPECT_TRUE(born["Estimate/Load Force"]["value"].is_null()) << "no estimate yet: null";
  EXPECT_TRUE(born["Alarms/CAGE_POS_Y/Active"]["value"].is_null()) << "unknown until the daemon announces it";

  // Known LCM messages; each DDATA must carry exactly their values.
  std::map<std::int64_t, std::string> by_alias;  // alias -> name
  for (const auto& [n, m] : born) by_alias[m["alias"].get<std::int64_t>()] = n;
  std::map<std::string, json> state;  // the host's view: births + DDATA in order
  for (int k = 1; k <= 6; ++k) {
    const hoist::cage_state_t c = cage(k);
    ASSERT_EQ(pub.publish("north/HOIST_CAGE", &c), 0);
    ASSERT_TRUE(waitMsg(
        [&](const json& m) {
          if (m.value("type", "") != "DDATA") return false;
          for (const auto& x : m["metrics"])
            if (by_alias[x["alias"].get<std::int64_t>()] == "Cage/Seq" && x["value"] == c.seq) return true;
          return false;
        },
        5s))
        << "no DDATA for cage seq " << c.seq << "\n" << tail(host_log_);
  }
  hoist::health_t h{};
  h.utime = 1'700'000'002'000'000;
  h.instance_id = 77;
  h.uptime = 5.0;
  h.clock = "wall";
  h.alarms_active = 1;
  ASSERT_EQ(pub.publish("north/HOIST_HEALTH", &h), 0);
  hoist::health_t h77{};
  h77.instance_id = 77;  // alarm events pass only from the instance whose health the bridge follows
  h77.clock = "wall";
  ASSERT_EQ(pub.publish("north/HOIST_HEALTH", &h77), 0);
  std::this_thread::sleep_for(200ms);
  const hoist::alarm_t a = raise("CAGE_POS_Y");
  ASSERT_EQ(pub.publish("north/HOIST_ALARM", &a), 0);
  hoist::estimate_t e{};
  e.utime = 1'700'000'003'000'000;
  e.seq = 9;
  e.Fa = 1234.5;
  e.in_use = true;
  e.instance_id = 77;  // the daemon whose health the bridge follows (others' data is dropped)
  ASSERT_EQ(pub.publish("north/HOIST_ESTIMATE", &e), 0);
  hoist::forecast_t f{};
  f.utime = 1'700'000'004'000'000;
  f.seq = 3;
  f.instance_id = 77;
  f.num_scenarios = 1;
  f.scenarios.resize(1);
  f.scenarios[0].name = "estop";
  f.scenarios[0].min_clearance = 0.05;
  f.scenarios[0].t_warning = 2.5;
  f.scenarios[0].t_critical = -1.0;
  f.scenarios[0].lambda0_min = 100.0;
  f.scenarios[0].lambda0_max = 200.0;
  ASSERT_EQ(pub.publish("north/HOIST_FORECAST", &f), 0);
  auto has = [&](const char* name, const json& value) {
    return waitMsg(
               [&](const json& m) {
                 if (m.value("type", "") != "DDATA") return false;
                 for (const auto& x : m["metrics"])
                   if (by_alias[x["alias"].get<std::int64_t>()] == name && x["value"] == value) return true;
                 return false;
               },
               5s)
        .has_value();
  };
  EXPECT_TRUE(has("Alarms/CAGE_POS_Y/Active", true));
  EXPECT_TRUE(has("Alarms/CAGE_POS_Y/Level", 1));
  EXPECT_TRUE(has("Health/Alarms Active", 1));
  EXPECT_TRUE(has("Health/Instance Id", 77));
  h.uptime = 6.0;
  h.alarms_active = 2;
  ASSERT_EQ(pub.publish("north/HOIST_HEALTH", &h), 0);
  EXPECT_TRUE(has("Health/Alarms Active", 2));
  EXPECT_TRUE(has("Estimate/Load Force", 1234.5));
  EXPECT_TRUE(has("Forecast/Time To Warning", 2.5));
  EXPECT_TRUE(has("Forecast/Min Clearance", 0.05));

  // Replay the host's view: after the DDATA of cage k, every cage metric equals message k.
  for (const auto& [n, m] : born) state[n] = m["value"];
  int checked = 0;
  int uptime_reported = 0;
  for (const auto& m : messages()) {
    if (m.value("type", "") != "DDATA") continue;
    for (const auto& x : m["metrics"]) {
      state[by_alias[x["alias"].get<std::int64_t>()]] = x["value"];
      uptime_reported += by_alias[x["alias"].get<std::int64_t>()] == "Health/Uptime" ? 1 : 0;
      EXPECT_FALSE(x.value("historical", false));
    }
    for (int k = 1; k <= 6; ++k) {
      const auto c = cage(k);
      if (state["Cage/Seq"] != c.seq) continue;
      bool in_this = false;
      for (const auto& x : m["metrics"]) in_this = in_this || by_alias[x["alias"].get<std::int64_t>()] == "Cage/Seq";
      if (!in_this) continue;
      for (const auto& [name, value] : cageFields(c)) EXPECT_EQ(asNumber(state[name]), value) << name << " k=" << k;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 6);
  EXPECT_EQ(uptime_reported, 1) << "Health/Uptime: from null to 5 s, then 1 s < its deadband of 1000 s";

  // A DCMD acknowledge reaches the daemon's side as HOIST_ALARM_ACK.
  command(std::string("dcmd north ") + kAck);
  ASSERT_TRUE(acks.waitFor([&] { return !operatorCommands(acks, "north/HOIST_ALARM_ACK").empty(); }, 5s))
      << tail((dir_ / "bridge1.log").string());
  const auto ack = operatorCommands(acks, "north/HOIST_ALARM_ACK").at(0);
  EXPECT_EQ(ack.kind, "CAGE_POS_Y");
  EXPECT_EQ(ack.action, +hoist::alarm_ack_t::ACTION_ACK);
  EXPECT_EQ(ack.user, "sparkplug");

  // Rebirth: NBIRTH (same bdSeq) and DBIRTH again, aliases unchanged (the host checks).
  command(R"(ncmd [{"name":"Node Control/Rebirth","type":"Boolean","value":true}])");
  ASSERT_TRUE(waitMsg([&](const json&) { return ofType("DBIRTH").size() >= 2; }, 5s));
  const auto nbirths = ofType("NBIRTH");
  ASSERT_EQ(nbirths.size(), 2u);
  auto bdseq = [](const json& m) {
    for (const auto& x : m["metrics"])
      if (x["name"] == "bdSeq") return x["value"];
    return json();
  };
  EXPECT_EQ(bdseq(nbirths[0]), bdseq(nbirths[1]));

  // SIGKILL: the broker sends the will, NDEATH with the NBIRTH's bdSeq.
  bridge_->signal(SIGKILL);
  bridge_->wait(5s);
  auto death = waitMsg([](const json& m) { return m.value("type", "") == "NDEATH"; }, 10s);
  ASSERT_TRUE(death);
  EXPECT_EQ(bdseq(*death), bdseq(nbirths[1]));
  EXPECT_FALSE(death->contains("seq") && !(*death)["seq"].is_null());
  const json r = report();
  EXPECT_EQ(r["errors"], json::array()) << r.dump(1);
  EXPECT_EQ(r["counts"].value("ndeath_bdseq_match", 0), 1);

  // A new bridge process: bdSeq starts again; births come first.
  startBridge();
  ASSERT_TRUE(waitMsg([&](const json&) { return ofType("NBIRTH").size() >= 3; }, 10s));
  const json r2 = report();
  EXPECT_EQ(r2["errors"], json::array()) << r2.dump(1);
}

TEST_F(MqttSparkplug, BadCommandsAreRefusedAndCountedNothingLost) {
  ASSERT_NO_FATAL_FAILURE(start(18621, 8061));
  Listener acks(lcm_url_);
  acks.subscribe("north/HOIST_ALARM_ACK");
  ::lcm::LCM pub(lcm_url_);
  ASSERT_TRUE(waitMsg([](const json& m) { return m.value("type", "") == "DBIRTH"; }, 15s)) << tail(host_log_);
  hoist::health_t h77{};
  h77.instance_id = 77;  // alarm events pass only from the instance whose health the bridge follows
  h77.clock = "wall";
  ASSERT_EQ(pub.publish("north/HOIST_HEALTH", &h77), 0);
  std::this_thread::sleep_for(200ms);
  const hoist::alarm_t a = raise("CAGE_POS_Y");
  ASSERT_EQ(pub.publish("north/HOIST_ALARM", &a), 0);
  ASSERT_TRUE(waitMsg([](const json& m) { return m.value("type", "") == "DDATA"; }, 5s));

  const std::string big(4000, 'a');  // 2000 bytes > [bridge] max_command_bytes (1024)
  command("raw spBv1.0/Mine/DCMD/Edge1/north ffffffffff");
  command("raw spBv1.0/Mine/NCMD/Edge1 0a");
  command("raw spBv1.0/Mine/DCMD/Edge1/north " + big);
  command("raw spBv1.0/Mine/NCMD/Edge1 " + big);
  command(R"(dcmd north [{"alias":999999,"type":"Boolean","value":true}])");
  command(R"(dcmd north [{"name":"Alarms/NOPE/Ack","type":"Boolean","value":true}])");
  command(std::string("dcmd nosuchshaft ") + kAck);
  command(R"(ncmd [{"name":"Node Control/Reboot","type":"Boolean","value":true}])");
  command(R"(dcmd north [{"name":"Cage/Length","type":"Double","value":1.0}])");
  command(R"(ncmd [{"name":"bdSeq","type":"Int64","value":3}])");
  command(R"(dcmd north [{"name":"Alarms/CAGE_POS_Y/Ack","type":"Boolean","value":false}])");
  command(R"(dcmd north [{"name":"Alarms/CAGE_POS_Y/Shelve","type":"Double","value":-5}])");
  constexpr int kBad = 12, kFlood = 1000;
  auto h = waitHealth([](const json& j) { return j["commands"].value("received", 0) >= kBad; }, 10s);
  ASSERT_TRUE(h) << tail((dir_ / "bridge1.log").string());
  const json& by = (*h)["commands"]["rejected_by_reason"];
  EXPECT_EQ(by.value("bad_payload", 0), 2) << by.dump();
  EXPECT_EQ(by.value("oversized", 0), 2) << by.dump();
  EXPECT_EQ(by.value("unknown_metric", 0), 4) << by.dump();
  EXPECT_EQ(by.value("read_only", 0), 2) << by.dump();
  EXPECT_EQ(by.value("bad_value", 0), 1) << by.dump();
  EXPECT_EQ(by.value("bad_shelve_duration", 0), 1) << by.dump();
  EXPECT_EQ((*h)["commands"]["rejected"], kBad);
  EXPECT_EQ((*h)["commands"]["forwarded"], 0);

  // A flood of acknowledges at 1000/s: each one forwarded or refused (rate), none lost.
  command(std::string("flood north ") + std::to_string(kFlood) + " 1000 " + kAck);
  h = waitHealth([](const json& j) { return j["commands"].value("received", 0) >= kBad + kFlood; }, 15s);
  ASSERT_TRUE(h) << "the bridge did not count every command";
  const json& c = (*h)["commands"];
  EXPECT_EQ(c["received"], kBad + kFlood);
  EXPECT_EQ(c["forwarded"].get<int>() + c["rejected"].get<int>(), kBad + kFlood);
  const int forwarded = c["forwarded"];
  EXPECT_GE(forwarded, 1);
  EXPECT_LE(forwarded, 40) << "[bridge] command_rate 2/s, burst 10";
  EXPECT_EQ(c["rejected_by_reason"].value("rate_limited", 0), kFlood - forwarded);
  acks.waitFor([&] { return static_cast<int>(operatorCommands(acks, "north/HOIST_ALARM_ACK").size()) >= forwarded; },
               5s);
  acks.pump(300ms);
  EXPECT_EQ(static_cast<int>(operatorCommands(acks, "north/HOIST_ALARM_ACK").size()), forwarded);

  // Still alive and in the same session: the node's counters in NDATA, data flows.
  const hoist::cage_state_t cg = cage(1);
  ASSERT_EQ(pub.publish("north/HOIST_CAGE", &cg), 0);
  EXPECT_TRUE(waitMsg(
      [](const json& m) {
        return m.value("type", "") == "DDATA" && m["metrics"].size() > 5;  // a cage state's metrics
      },
      5s));
  EXPECT_TRUE(waitMsg([](const json& m) { return m.value("type", "") == "NDATA"; }, 5s));
  const json r = report();
  EXPECT_EQ(r["errors"], json::array()) << r.dump(1);
  EXPECT_EQ(ofType("NBIRTH").size(), 1u);
}

TEST_F(MqttSparkplug, NoCommandsRefusesAndCountsWrites) {
  ASSERT_NO_FATAL_FAILURE(start(18622, 8062, "", {"--no-commands"}));
  Listener acks(lcm_url_);
  acks.subscribe("north/HOIST_ALARM_ACK");
  ::lcm::LCM pub(lcm_url_);
  ASSERT_TRUE(waitMsg([](const json& m) { return m.value("type", "") == "DBIRTH"; }, 15s)) << tail(host_log_);
  hoist::health_t h77{};
  h77.instance_id = 77;  // alarm events pass only from the instance whose health the bridge follows
  h77.clock = "wall";
  ASSERT_EQ(pub.publish("north/HOIST_HEALTH", &h77), 0);
  std::this_thread::sleep_for(200ms);
  const hoist::alarm_t a = raise("CAGE_POS_Y");
  ASSERT_EQ(pub.publish("north/HOIST_ALARM", &a), 0);
  for (int i = 0; i < 3; ++i) command(std::string("dcmd north ") + kAck);
  auto h = waitHealth([](const json& j) { return j["commands"].value("received", 0) >= 3; }, 10s);
  ASSERT_TRUE(h);
  EXPECT_EQ((*h)["commands"]["rejected_by_reason"].value("disabled", 0), 3);
  EXPECT_EQ((*h)["commands"]["forwarded"], 0);
  acks.pump(300ms);
  EXPECT_EQ(operatorCommands(acks, "north/HOIST_ALARM_ACK").size(), 0u);
}

TEST_F(MqttSparkplug, PrimaryHostGatesBirthsAndStoredDataIsHistorical) {
  ASSERT_NO_FATAL_FAILURE(start(18623, 8063, "primary_host_id = \"scada\"\n"));
  ::lcm::LCM pub(lcm_url_);
  auto cageDdata = [&](std::int64_t seq, bool historical) { return cageSeqData(seq, historical, 5s); };
  // No primary host yet: connected, but nothing is published; data is stored.
  const auto c1 = cage(1);
  std::this_thread::sleep_for(500ms);
  ASSERT_EQ(pub.publish("north/HOIST_CAGE", &c1), 0);
  std::this_thread::sleep_for(700ms);
  EXPECT_TRUE(ofType("NBIRTH").empty()) << tail(host_log_);
  // (STATE timestamps are the host's wall clock: the bridge ignores one more
  // than Node::kStateFutureMs ahead of its own.)
  const std::int64_t t0 = std::chrono::duration_cast<std::chrono::milliseconds>(
                             std::chrono::system_clock::now().time_since_epoch()).count();
  command("state scada true " + std::to_string(t0));
  ASSERT_TRUE(waitMsg([](const json& m) { return m.value("type", "") == "DBIRTH"; }, 5s)) << tail(host_log_);
  EXPECT_TRUE(cageDdata(c1.seq, true)) << "stored before the births: sent after them, is_historical";
  // The host goes offline: the session ends (NDEATH), the bridge reconnects and stores.
  command("state scada false " + std::to_string(t0 + 1));
  ASSERT_TRUE(waitMsg([](const json& m) { return m.value("type", "") == "NDEATH"; }, 5s)) << tail(host_log_);
  const auto c2 = cage(2);
  std::this_thread::sleep_for(300ms);
  ASSERT_EQ(pub.publish("north/HOIST_CAGE", &c2), 0);
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(ofType("NBIRTH").size(), 1u);
  command("state scada true " + std::to_string(t0 + 2));
  ASSERT_TRUE(waitMsg([&](const json&) { return ofType("NBIRTH").size() >= 2; }, 10s)) << tail(host_log_);
  EXPECT_TRUE(cageDdata(c2.seq, true));
  // Live again.
  const auto c3 = cage(3);
  ASSERT_EQ(pub.publish("north/HOIST_CAGE", &c3), 0);
  EXPECT_TRUE(cageDdata(c3.seq, false));
  const auto births = ofType("NBIRTH");
  EXPECT_EQ(births[1]["metrics"][0]["value"], births[0]["metrics"][0]["value"].get<int>() + 1) << "bdSeq + 1 per CONNECT";
  const json r = report();
  EXPECT_EQ(r["errors"], json::array()) << r.dump(1);
}

// A forged STATE "offline" (issue 33) on a broker without the STATE ACL:
// Sparkplug 3.0 stamps the host's online and its death with one timestamp,
// so an offline stamped otherwise is no death of the session followed.  It
// still ends the session (the bridge cannot tell), but costs no data and
// locks nobody out: not retained, the reconnect reads the host's retained
// online again and the bridge is live at once; retained (it replaced the
// host's online on the broker), the host's republished online -- the same
// timestamp -- brings it back.  Before, both onlines were "older than the
// last STATE" and ignored until the host started a new session.
TEST_F(MqttSparkplug, ForgedOfflineCostsTheSessionNeverTheDataNorTheHostsReturn) {
  ASSERT_NO_FATAL_FAILURE(start(18624, 8064, "primary_host_id = \"scada\"\n"));
  ::lcm::LCM pub(lcm_url_);
  const auto now_ms = [] {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
        .count();
  };
  const std::int64_t t0 = now_ms();
  command("state scada true " + std::to_string(t0));
  ASSERT_TRUE(waitMsg([](const json& m) { return m.value("type", "") == "DBIRTH"; }, 5s)) << tail(host_log_);
  auto seqSeen = [&](std::int64_t seq) { return cageSeqData(seq, std::nullopt, 8s); };
  auto hexOf = [](const std::string& s) {
    std::string h;
    char b[3];
    for (unsigned char c : s) std::snprintf(b, sizeof b, "%02x", c), h += b;
    return h;
  };
  const std::string forged = R"({"online": false, "timestamp": )" + std::to_string(now_ms()) + "}";
  // 1. Not retained: NDEATH, reconnect, the retained online read again: births, live.
  command("raw spBv1.0/STATE/scada " + hexOf(forged));
  ASSERT_TRUE(waitMsg([](const json& m) { return m.value("type", "") == "NDEATH"; }, 5s)) << tail(host_log_);
  const auto c1 = cage(1);
  ASSERT_EQ(pub.publish("north/HOIST_CAGE", &c1), 0);
  ASSERT_TRUE(waitMsg([&](const json&) { return ofType("NBIRTH").size() >= 2; }, 10s))
      << "the host's own retained online brings the session back\n" << tail(host_log_);
  EXPECT_TRUE(seqSeen(c1.seq)) << "the sample of the outage is sent";
  // 2. Retained (the host's online replaced on the broker): stored until the
  // host republishes its online, with its session's timestamp.
  command("state scada false " + std::to_string(now_ms()));
  ASSERT_TRUE(waitMsg([&](const json&) { return ofType("NDEATH").size() >= 2; }, 5s)) << tail(host_log_);
  std::this_thread::sleep_for(1s);  // reconnected, the forged retained offline read: storing
  const auto c2 = cage(2);
  ASSERT_EQ(pub.publish("north/HOIST_CAGE", &c2), 0);
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(ofType("NBIRTH").size(), 2u) << "no births while the broker says offline";
  command("state scada true " + std::to_string(t0));  // the host republishes: the same session
  ASSERT_TRUE(waitMsg([&](const json&) { return ofType("NBIRTH").size() >= 3; }, 10s))
      << "the host's republished online (its session's timestamp) is accepted\n" << tail(host_log_);
  EXPECT_TRUE(seqSeen(c2.seq)) << "stored meanwhile, sent after the births";
  const auto h = waitHealth([](const json& j) { return j.contains("sparkplug") && j["sparkplug"].value("session", false) &&
                                                      j["sparkplug"].value("state_unverified", 0) >= 2; }, 5s);
  ASSERT_TRUE(h) << tail(host_log_);
  EXPECT_EQ((*h)["sparkplug"]["state_ignored"], 0) << h->dump(1);
  const json r = report();
  EXPECT_EQ(r["errors"], json::array()) << r.dump(1);
}
