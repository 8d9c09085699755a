// Hostile bytes and look-alike prefixes through real LCM (UDP multicast on loopback, ports 7751-7753):
//   * hoist-twind receives the 37-byte alarm_ack_t with a string length of 0
//     and of 0x80000000 (it used to die), health_t/guide_shape_t payloads with
//     huge and negative counts on its input channels, and truncations of a
//     valid command: it stays alive, counts every one ("command_decode" and
//     "decode" in HOIST_HEALTH), keeps publishing, still obeys a valid
//     command, and stops cleanly;
//   * hoist-monitor receives an alarm_t whose message carries terminal escape
//     sequences, health_t with impossible counts and garbage: no control
//     character reaches its output, the undecodable messages are counted, it
//     says STALE when the daemon goes quiet, and it exits 0 with bounded memory;
//   * hoist-monitor --channel-prefix "mine.1/" does not show the look-alike
//     shaft "mineX1/" (LCM's subscribe takes a regular expression).
//   * hoist-monitor shows HOIST_FORECAST (port 7757): per scenario
//     the worst clearance and the time to violation, scenario names
//     terminal-safe, a forecast with a lying nested count dropped and counted.
#include <gtest/gtest.h>

#include <map>

#include "lcm_fixtures.hpp"
#include "attack_bytes.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/winder_t.hpp"
#include "process.hpp"

using namespace hoist::test;
namespace atk = hoist::test::attack;

namespace {

std::map<std::string, std::int64_t> reasons(const hoist::health_t& h) {
  std::map<std::string, std::int64_t> m;
  for (int i = 0; i < h.n_reasons; ++i) m[h.reject_reason[i]] = h.rejected[i];
  return m;
}

/// The newest health message that passes the checked decoder.
bool latestHealth(const Listener& l, hoist::health_t& h) {
  const auto& ms = l.messages("HOIST_HEALTH");
  for (auto it = ms.rbegin(); it != ms.rend(); ++it)
    if (hoist::msg::checkedDecode(it->data.data(), it->data.size(), h) == hoist::msg::DecodeStatus::ok) return true;
  return false;
}

class DecodeAttack : public ::testing::Test {
 protected:
  void start(int port, const std::string& name) {
    url_ = urlFor(port);
    dir_ = testDir(name);
    std::string why;
    if (!loopbackMulticastWorks(url_, why)) FAIL() << why << ".\n" << kMulticastHelp;
    listener_ = std::make_unique<Listener>(url_);
    ASSERT_TRUE(listener_->good()) << kMulticastHelp;
    listener_->subscribe("HOIST_HEALTH");
    listener_->subscribe("HOIST_CAGE");
    listener_->subscribe("HOIST_ALARM");
  }
  void publish(const std::string& ch, const std::vector<std::uint8_t>& b) {
    ASSERT_EQ(listener_->lcm().publish(ch, b.data(), static_cast<unsigned>(b.size())), 0);
  }
  std::string url_;
  std::filesystem::path dir_;
  std::unique_ptr<Listener> listener_;
};

TEST_F(DecodeAttack, DaemonSurvivesAndCountsHostileCommandsAndCounts) {
  start(7751, "decode_attack_daemon");
  const std::string log = (dir_ / "twind.log").string();
  auto d = startDaemonAndWait(*listener_, {HOIST_TWIND, "--lcm-url", url_, "--clock", "wall"}, log);
  ASSERT_TRUE(d->running());

  int n_cmd = 0, n_winder = 0;
  // The two 37-byte commands that killed the daemon, several times each.
  for (int i = 0; i < 5; ++i) {
    publish("HOIST_ALARM_ACK", atk::alarmAckStringLen(0)), ++n_cmd;
    publish("HOIST_ALARM_ACK", atk::alarmAckStringLen(0x80000000u)), ++n_cmd;
  }
  // Every prefix of a valid command, and payloads of other types with
  // impossible counts on both input channels.
  hoist::alarm_ack_t ack{};
  ack.kind = "*";
  ack.action = hoist::alarm_ack_t::ACTION_ACK;
  ack.user = "tester";
  std::vector<std::uint8_t> good(static_cast<std::size_t>(ack.getEncodedSize()));
  ack.encode(good.data(), 0, static_cast<int>(good.size()));
  for (std::size_t n = 0; n < good.size(); ++n) {
    publish("HOIST_ALARM_ACK", std::vector<std::uint8_t>(good.begin(), good.begin() + static_cast<long>(n))), ++n_cmd;
    if (n % 10 == 9) listener_->pump(5ms);
  }
  for (std::int32_t c : {0x7fffffff, -1, INT32_MIN}) {
    publish("HOIST_ALARM_ACK", atk::healthCount(c)), ++n_cmd;
    publish("HOIST_ALARM_ACK", atk::guideShapeCount(c)), ++n_cmd;
    publish("HOIST_WINDER", atk::healthCount(c)), ++n_winder;
    publish("HOIST_WINDER", atk::guideShapeCount(c)), ++n_winder;
    publish("HOIST_WINDER", atk::alarmAckStringLen(0x80000000u)), ++n_winder;
  }
  listener_->pump(300ms);
  ASSERT_TRUE(d->running()) << readFile(log);

  // Still obeys a valid command after all that: with no winder input the
  // daemon raises INPUT_STALE; a valid ACK then acknowledges it.
  auto alarmEvent = [&](std::int8_t type) {
    for (const auto& m : listener_->messages("HOIST_ALARM")) {
      hoist::alarm_t a;
      if (hoist::msg::checkedDecode(m.data.data(), m.data.size(), a) == hoist::msg::DecodeStatus::ok &&
          a.event_type == type && a.kind == "INPUT_STALE")
        return true;
    }
    return false;
  };
  ASSERT_TRUE(listener_->waitFor([&] { return alarmEvent(hoist::alarm_t::EVENT_RAISE); }, 5s));
  publish("HOIST_ALARM_ACK", good);
  EXPECT_TRUE(listener_->waitFor([&] { return alarmEvent(hoist::alarm_t::EVENT_ACK); }, 3s))
      << "a valid command after the attack was not obeyed";
  hoist::health_t h{};
  const bool counted = listener_->waitFor(
      [&] {
        // A burst beyond [service] max_commands_per_tick is dropped (and
        // counted) before it is decoded: every hostile command is one or the other.
        return latestHealth(*listener_, h) && reasons(h)["command_decode"] + h.commands_dropped >= n_cmd &&
               reasons(h)["decode"] >= n_winder;
      },
      4s);
  EXPECT_TRUE(counted) << "command_decode=" << reasons(h)["command_decode"] << " + commands_dropped="
                       << h.commands_dropped << " (sent " << n_cmd << "), decode=" << reasons(h)["decode"]
                       << " (sent " << n_winder << ")";
  EXPECT_EQ(reasons(h)["handler_exception"], 0);
  EXPECT_TRUE(d->running());
  const std::size_t health_before = listener_->count("HOIST_HEALTH");
  listener_->pump(1200ms);
  EXPECT_GT(listener_->count("HOIST_HEALTH"), health_before) << "the daemon went quiet";
  stopDaemonCleanly(*d, log);
  const std::string text = readFile(log);
  EXPECT_NE(text.find("bad_string"), std::string::npos) << text;
  EXPECT_NE(text.find("command_decode"), std::string::npos) << "final report lists the rejections\n" << text;
}

TEST_F(DecodeAttack, MonitorSanitizesStringsAndFlagsStaleData) {
  start(7752, "decode_attack_monitor");
  const std::string out = (dir_ / "monitor.out").string();
  Process mon({HOIST_MONITOR, "--lcm-url", url_, "--period", "0.25", "--duration", "4.5"}, out);
  ASSERT_TRUE(mon.started());
  listener_->pump(500ms);  // let it subscribe
  hoist::cage_state_t cage{};
  cage.t = 1.0;
  cage.l = 100.0;
  listener_->lcm().publish("HOIST_CAGE", &cage);
  hoist::alarm_t a{};
  a.kind = "CAGE_POS_Y\x1b[5m";
  a.level = 2;
  a.event_type = hoist::alarm_t::EVENT_RAISE;
  a.active = 1;
  a.message = "\x1b[2J\x1b[H\x1b]0;owned\x07" "FAKE: all clear\r\n\x9b" "31m";
  a.user = "";
  listener_->lcm().publish("HOIST_ALARM", &a);
  for (std::int32_t c : {0x7fffffff, -1}) {
    publish("HOIST_HEALTH", atk::healthCount(c));
    publish("HOIST_GUIDE_SHAPE", atk::guideShapeCount(c));
    publish("HOIST_CAGE", atk::guideShapeCount(c));
  }
  publish("HOIST_ALARM", atk::alarmAckStringLen(0));
  // Then silence: the monitor must say STALE after 2 s.
  const int st = mon.wait(15s);
  const std::string text = readFile(out);
  EXPECT_EQ(st, 0) << text;
  EXPECT_EQ(text.find('\x1b'), std::string::npos) << "an escape character reached the terminal:\n" << text;
  EXPECT_EQ(text.find('\x07'), std::string::npos);
  EXPECT_EQ(text.find('\r'), std::string::npos);
  EXPECT_EQ(text.find("\xc2\x9b"), std::string::npos);
  EXPECT_NE(text.find("\\x1b[2J"), std::string::npos) << text;
  EXPECT_NE(text.find("FAKE: all clear"), std::string::npos) << text;  // shown, but inert
  EXPECT_NE(text.find("undecodable messages: 5"), std::string::npos) << text;
  EXPECT_NE(text.find("STALE: no HOIST_CAGE"), std::string::npos) << text;
}

TEST_F(DecodeAttack, MonitorPrefixIsALiteralNotARegex) {
  // Look-alike prefixes in hoist-monitor: its channels were regular expressions, so
  // the prefix "mine.1/" also showed the cage of "mineX1/".
  start(7753, "decode_attack_monitor_prefix");
  const std::string out = (dir_ / "monitor.out").string();
  Process mon({HOIST_MONITOR, "--lcm-url", url_, "--channel-prefix", "mine.1/", "--period", "0.25", "--duration",
               "2.5"},
              out);
  ASSERT_TRUE(mon.started());
  listener_->pump(700ms);  // let it subscribe
  hoist::cage_state_t cage{};
  cage.t = 1.0;
  cage.l = 123.45;
  for (int i = 0; i < 3; ++i) {
    listener_->lcm().publish("mineX1/HOIST_CAGE", &cage);
    listener_->pump(100ms);
  }
  listener_->pump(500ms);
  cage.l = 222.22;
  for (int i = 0; i < 3; ++i) {
    listener_->lcm().publish("mine.1/HOIST_CAGE", &cage);
    listener_->pump(100ms);
  }
  const int st = mon.wait(10s);
  const std::string text = readFile(out);
  EXPECT_EQ(st, 0) << text;
  EXPECT_EQ(text.find("123.45"), std::string::npos) << "the mineX1/ shaft reached a mine.1/ monitor:\n" << text;
  EXPECT_NE(text.find("222.22"), std::string::npos) << text;
}

TEST_F(DecodeAttack, MonitorShowsForecastWorstClearanceAndTimeToViolation) {
  start(7757, "decode_attack_monitor_forecast");
  const std::string out = (dir_ / "monitor.out").string();
  Process mon({HOIST_MONITOR, "--lcm-url", url_, "--period", "0.25", "--duration", "2.5"}, out);
  ASSERT_TRUE(mon.started());
  listener_->pump(500ms);  // let it subscribe
  hoist::cage_state_t cage{};
  cage.t = 20.0;
  cage.l = 150.0;
  cage.min_clearance = 0.05;
  listener_->lcm().publish("HOIST_CAGE", &cage);
  hoist::forecast_t f{};
  f.utime = 1;
  f.seq = 1;
  f.t_start = 20.0;
  f.plan_seq = -1;
  f.num_scenarios = 2;
  f.scenarios.resize(2);
  auto& e = f.scenarios[0];
  e.name = "estop";
  e.min_clearance = 0.0125;
  e.t_min_clearance = 2.0;
  e.t_warning = 1.5;
  e.t_critical = 2.5;
  e.lambda0_min = 2400.0;
  auto& c = f.scenarios[1];
  c.name = "cont\x1b[2Jinue";  // a name with an escape sequence
  c.min_clearance = 0.040;
  c.t_min_clearance = 6.0;
  c.t_warning = -1.0;
  c.t_critical = -1.0;
  c.lambda0_min = 8100.0;
  c.status = hoist::forecast_scenario_t::STATUS_LEFT_SHAFT;
  c.t_reached = 12.5;
  std::vector<std::uint8_t> b(static_cast<std::size_t>(f.getEncodedSize()));
  f.encode(b.data(), 0, static_cast<int>(b.size()));
  // First a lying copy: scenarios[0].num_points = 30000 (no points follow).
  auto bad = b;
  const std::size_t np = 8 + 9 * 8 + 1 + 4 + 6 + 1 + 112;
  ASSERT_EQ(bad[np + 1], 0);
  bad[np] = 0x75;
  bad[np + 1] = 0x30;
  publish("HOIST_FORECAST", bad);
  publish("HOIST_FORECAST", b);
  const int st = mon.wait(15s);
  const std::string text = readFile(out);
  EXPECT_EQ(st, 0) << text;
  EXPECT_NE(text.find("forecast from t=20.00 s: estop: worst 12.5 mm at +2.00 s, CRITICAL in 2.50 s, "
                      "WARNING in 1.50 s, F0 min 2.40 kN"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("| cont\\x1b[2Jinue: worst 40.0 mm at +6.00 s, CRITICAL none, WARNING none, F0 min 8.10 kN "
                      "[stopped at +12.50 s: left the shaft]"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find('\x1b'), std::string::npos) << "an escape character reached the terminal:\n" << text;
  EXPECT_NE(text.find("undecodable messages: 1"), std::string::npos) << text;
}

}  // namespace
