// Channel-name spam against the tools that subscribe to LCM (UDP multicast on loopback,
// port 7864): LCM 1.3.1 keeps a handler-table entry for every channel name
// it ever receives and never frees it (about 11 MB per 100 000 names), so a
// sender cycling names grew hoist-dash, hoist-mqtt, hoist-monitor and
// hoist-timing-test's listener (and
// the daemon, fixed before: DaemonAttack.MillionDistinctChannelNamesKeepMemoryFlat)
// without bound.  They now read udpm:// through hoist/bus/udpm_receiver.hpp,
// which stores nothing per name: 300 000 distinct names, RSS growth < 2 MB
// each; then the hostile attack bytes on the channels they decode; they
// stay up and still work (the monitor shows the next cage).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <thread>

#include "attack_bytes.hpp"
#include "hoist/cage_state_t.hpp"
#include "lcm_fixtures.hpp"

using namespace hoist::test;

namespace {

struct Tool {
  std::string name;
  std::unique_ptr<Process> p;
  long rss0 = 0;
};

class ToolAttack : public LcmProcessTest {};

}  // namespace

TEST_F(ToolAttack, ChannelNameSpamKeepsToolMemoryFlat) {
  start(7864, "tool_chanspam");
  std::vector<Tool> tools;
  auto add = [&](const std::string& name, std::vector<std::string> argv) {
    tools.push_back({name, std::make_unique<Process>(argv, (dir_ / (name + ".log")).string())});
    ASSERT_TRUE(tools.back().p->started()) << name;
  };
  add("hoist-monitor", {HOIST_MONITOR, "--lcm-url", url_, "--period", "0.5", "--duration", "30"});
  // Waiting for a daemon's first HOIST_HEALTH (none comes) the whole time.
  add("hoist-timing-test", {HOIST_TIMING_TEST, "--lcm-url", url_, "--shafts", "2", "--health-timeout", "60",
                            "--duration", "1", "-q"});
#ifdef HOIST_DASH
  add("hoist-dash", {HOIST_DASH, "--lcm-url", url_, "--port", "0"});
#endif
#ifdef HOIST_MQTT
  // No broker there: the bridge retries the broker and keeps reading LCM.
  add("hoist-mqtt", {HOIST_MQTT, "--broker", "mqtt://127.0.0.1:9", "--lcm-url", url_});
#endif
  listener_.reset();  // the test's own LCM would cache the names too
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  for (auto& t : tools) {
    ASSERT_TRUE(t.p->running()) << t.name << ":\n" << readFile((dir_ / (t.name + ".log")).string());
    t.rss0 = vmRssKb(t.p->pid());
    ASSERT_GT(t.rss0, 0) << t.name;
  }
  {
    ::lcm::LCM pub(url_);  // publish only: no receive socket
    ASSERT_TRUE(pub.good());
    const char payload[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    char name[40];
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < 300'000; ++i) {
      // Names no tool subscribes to: LCM 1.3.1 cached every one of them anyway.
      std::snprintf(name, sizeof name, "SPAM_%07d", i);
      pub.publish(name, payload, sizeof payload);
      if (i % 1000 == 999) std::this_thread::sleep_until(t0 + std::chrono::microseconds(10 * (i + 1)));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    // The hostile attack bytes (attack_bytes.hpp) on the channels they decode.
    namespace atk = hoist::test::attack;
    auto raw = [&](const char* ch, const atk::Bytes& b) { pub.publish(ch, b.data(), static_cast<unsigned>(b.size())); };
    for (std::int32_t n : {0x7fffffff, -1, INT32_MIN}) {
      raw("HOIST_HEALTH", atk::healthCount(n));
      raw("HOIST_GUIDE_SHAPE", atk::guideShapeCount(n));
      raw("HOIST_CAGE", atk::guideShapeCount(n));
    }
    for (std::uint32_t len : {0u, 0x80000000u, 0xffffffffu}) raw("HOIST_ALARM", atk::alarmStringLen(len));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    hoist::cage_state_t cage{};
    cage.t = 1.0;
    cage.l = 321.75;
    for (int i = 0; i < 3; ++i) {
      pub.publish("HOIST_CAGE", &cage);
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
    }
  }
  for (auto& t : tools) {
    ASSERT_TRUE(t.p->running()) << t.name << " died";
    const long rss1 = vmRssKb(t.p->pid());
    EXPECT_LT(rss1 - t.rss0, 2048) << t.name << ": RSS grew from " << t.rss0 << " to " << rss1 << " KiB";
    t.p->signal(SIGTERM);
    EXPECT_GE(t.p->wait(std::chrono::seconds(10)), 0) << t.name;
  }
  const std::string mon = readFile((dir_ / "hoist-monitor.log").string());
  EXPECT_NE(mon.find("321.75"), std::string::npos) << "the monitor stopped receiving:\n" << mon;
}
