// Operator commands under a junk flood on HOIST_ALARM_ACK (docs/security.md):
// junk -- undecodable datagrams and well-formed but invalid commands --
// costs the daemon a decode, never a genuine command's place in the
// per-tick command budget.  The daemon runs in-process (its loop driven by
// this thread, so its run figures can be read between polls) over loopback
// multicast, ports 7950-7951; a second thread floods junk at a paced rate
// while genuine SHELVE/UNSHELVE commands are sent one at a time, each of
// which must be applied within a tick or two.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <sstream>
#include <spdlog/sinks/ostream_sink.h>
#include <thread>
#include <vector>

#include "daemon.hpp"
#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"

using namespace hoist;
using namespace hoist::service;
using namespace std::chrono_literals;

namespace {

std::vector<std::uint8_t> encode(const hoist::alarm_ack_t& m) {
  std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

hoist::alarm_ack_t command(std::int8_t action, const std::string& kind) {
  hoist::alarm_ack_t m{};
  m.utime = 1;
  m.kind = kind;
  m.level = 0;
  m.action = action;
  m.shelve_duration = action == hoist::alarm_ack_t::ACTION_SHELVE ? 600.0 : 0.0;
  m.user = "operator";
  return m;
}

struct StarvationCase {
  int junk_per_s;
  int port;
};

class CommandStarvation : public ::testing::TestWithParam<StarvationCase> {};

}  // namespace

TEST_P(CommandStarvation, GenuineCommandsAreAppliedWithinATickUnderAJunkFlood) {
  const StarvationCase tc = GetParam();
  const std::string url = "udpm://239.255.76.67:" + std::to_string(tc.port) + "?ttl=0";
  {
    ::lcm::LCM probe(url);
    if (!probe.good())
      GTEST_FAIL() << "UDP multicast on loopback is off: run scripts/setup.sh or, as root, "
                      "ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo";
  }
  std::ostringstream logs;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(logs);
  auto logger = std::make_shared<spdlog::logger>("starvation", sink);
  DaemonOptions opt;
  TwinConfig cfg;
  cfg.shaft.n = 10;
  cfg.service.rate = 100.0;  // max_commands_per_tick = 4 (the default)
  opt.shafts = {cfg};
  opt.lcm_url = url;
  Daemon d(std::move(opt), logger);
  ASSERT_TRUE(d.start());
  auto loopFor = [&](std::chrono::duration<double> span) {
    const auto until = std::chrono::steady_clock::now() + span;
    while (std::chrono::steady_clock::now() < until) {
      d.poll();
      std::this_thread::sleep_for(50us);
    }
  };

  // Junk: every other datagram a truncated command (undecodable), the rest a
  // well-formed command naming no alarm kind (invalid).
  const std::vector<std::uint8_t> good_shape = encode(command(hoist::alarm_ack_t::ACTION_SHELVE, "*"));
  const std::vector<std::uint8_t> truncated(good_shape.begin(), good_shape.begin() + 20);
  const std::vector<std::uint8_t> invalid = encode(command(hoist::alarm_ack_t::ACTION_SHELVE, "NOT_A_KIND"));
  std::atomic<bool> flooding{true};
  std::atomic<std::int64_t> junk_sent{0};
  std::thread flood([&] {
    ::lcm::LCM out(url);
    const int per_ms = tc.junk_per_s / 1000;
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; flooding.load(); ++k) {
      std::this_thread::sleep_until(t0 + std::chrono::milliseconds(k));
      for (int i = 0; i < per_ms; ++i) {
        const auto& b = (i % 2 == 0) ? truncated : invalid;
        out.publish("HOIST_ALARM_ACK", b.data(), static_cast<unsigned>(b.size()));
        junk_sent.fetch_add(1, std::memory_order_relaxed);
      }
    }
  });

  loopFor(0.3s);  // the flood is on
  ::lcm::LCM genuine(url);
  ASSERT_TRUE(genuine.good());
  constexpr int kCommands = 40;
  int applied = 0;
  std::int64_t max_ticks = 0;
  const auto flood_t0 = std::chrono::steady_clock::now();
  const std::int64_t junk0 = junk_sent.load();
  for (int i = 0; i < kCommands; ++i) {
    // Shelve all, then unshelve all, ...: each one changes state (effective).
    const auto b = encode(command(i % 2 == 0 ? hoist::alarm_ack_t::ACTION_SHELVE : hoist::alarm_ack_t::ACTION_UNSHELVE, "*"));
    const ShaftTwin& shaft = d.shaft(0);
    const std::int64_t applied0 = shaft.stats().in.commands_applied, ticks0 = shaft.ticks();
    ASSERT_EQ(genuine.publish("HOIST_ALARM_ACK", b.data(), static_cast<unsigned>(b.size())), 0);
    const auto deadline = std::chrono::steady_clock::now() + 1s;
    while (std::chrono::steady_clock::now() < deadline) {
      d.poll();
      if (shaft.stats().in.commands_applied > applied0) break;
      std::this_thread::sleep_for(50us);
    }
    if (shaft.stats().in.commands_applied > applied0) {
      ++applied;
      max_ticks = std::max(max_ticks, shaft.ticks() - ticks0);
    }
    // One genuine command per tick (the budget is for valid commands: more
    // than max_commands_per_tick of them in one tick are dropped by design).
    const std::int64_t tick = shaft.ticks();
    while (shaft.ticks() == tick) {
      d.poll();
      std::this_thread::sleep_for(50us);
    }
  }
  const double flood_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - flood_t0).count();
  const std::int64_t junk_during = junk_sent.load() - junk0;
  loopFor(0.1s);  // the junk still in the socket is counted
  flooding = false;
  flood.join();
  const InputStats end = d.shaft(0).stats().in;
  d.requestStop("test over");
  d.finish();

  EXPECT_EQ(applied, kCommands) << "genuine commands lost to the junk (" << tc.junk_per_s << "/s)";
  // Applied in the tick it arrived in, or the next when a tick fell between
  // the send and the drain (a tick or two late on a loaded machine).
  EXPECT_LE(max_ticks, 2) << "a genuine command waited " << max_ticks << " ticks";
  EXPECT_EQ(end.commands_dropped, 0) << "junk used the command budget";
  // The flood was real and reached the daemon: most of the junk was decoded
  // and counted invalid (the kernel may drop some of it).
  EXPECT_GE(static_cast<double>(junk_during), 0.5 * tc.junk_per_s * flood_s);
  EXPECT_GE(end.commands_invalid, junk_during / 2) << "sent " << junk_sent.load();
  std::printf("junk %d/s: %d/%d genuine commands applied, at most %lld ticks after sending; %lld junk datagrams "
              "sent in %.2f s, %lld counted invalid\n",
              tc.junk_per_s, applied, kCommands, static_cast<long long>(max_ticks),
              static_cast<long long>(junk_sent.load()), flood_s, static_cast<long long>(end.commands_invalid));
}

INSTANTIATE_TEST_SUITE_P(JunkRates, CommandStarvation,
                         ::testing::Values(StarvationCase{5000, 7950}, StarvationCase{50000, 7951}),
                         [](const ::testing::TestParamInfo<StarvationCase>& info) {
                           return "Junk" + std::to_string(info.param.junk_per_s) + "PerSecond";
                         });

// A client that starts late asks for the alarms' current states
// (alarm_ack_t ACTION_REANNOUNCE): the daemon re-announces every alarm that
// has a state at once, without waiting for the periodic re-announce (an hour
// here); a burst of requests is honoured once at once and once more a second
// later (merged), never more often; the request changes no state.  Port 8002.
TEST(ReannounceRequest, HonouredAtOnceThenAtMostOnceASecondAndChangesNothing) {
  const std::string url = "udpm://239.255.76.67:8002?ttl=0";
  {
    ::lcm::LCM probe(url);
    if (!probe.good()) GTEST_FAIL() << "UDP multicast on loopback is off: run scripts/setup.sh";
  }
  std::ostringstream logs;
  auto logger = std::make_shared<spdlog::logger>("reannounce", std::make_shared<spdlog::sinks::ostream_sink_mt>(logs));
  DaemonOptions opt;
  TwinConfig cfg;
  cfg.shaft.n = 6;
  cfg.service.rate = 100.0;
  cfg.service.stale_timeout = 0.2;  // no winder: INPUT_STALE raises at once
  cfg.alarms.reannounce = 3600.0;
  opt.shafts = {cfg};
  opt.lcm_url = url;
  Daemon d(std::move(opt), logger);
  struct Seen {
    std::vector<std::pair<hoist::alarm_t, std::chrono::steady_clock::time_point>> events;
    void on(const ::lcm::ReceiveBuffer*, const std::string&, const hoist::alarm_t* m) {
      events.emplace_back(*m, std::chrono::steady_clock::now());
    }
    int count(std::int8_t type) const {
      int n = 0;
      for (const auto& [e, t] : events) n += e.event_type == type;
      return n;
    }
  } seen;
  ::lcm::LCM listen(url);
  listen.subscribe("HOIST_ALARM", &Seen::on, &seen);
  ASSERT_TRUE(d.start());
  auto loopFor = [&](std::chrono::duration<double> span) {
    const auto until = std::chrono::steady_clock::now() + span;
    while (std::chrono::steady_clock::now() < until) {
      d.poll();
      listen.handleTimeout(0);
      std::this_thread::sleep_for(100us);
    }
  };
  const auto raise_deadline = std::chrono::steady_clock::now() + 5s;
  while (seen.count(hoist::alarm_t::EVENT_RAISE) == 0 && std::chrono::steady_clock::now() < raise_deadline)
    loopFor(0.05s);
  ASSERT_EQ(seen.count(hoist::alarm_t::EVENT_RAISE), 1) << logs.str();
  loopFor(0.2s);
  const std::size_t before = seen.events.size();
  ::lcm::LCM client(url);
  hoist::alarm_ack_t req = command(hoist::alarm_ack_t::ACTION_REANNOUNCE, "*");
  req.user = "hoist-mqtt-test";
  const auto t_sent = std::chrono::steady_clock::now();
  for (int i = 0; i < 5; ++i) client.publish("HOIST_ALARM_ACK", &req);
  loopFor(2.5s);
  std::vector<std::chrono::steady_clock::time_point> answers;
  for (std::size_t i = before; i < seen.events.size(); ++i) {
    const hoist::alarm_t& e = seen.events[i].first;
    ASSERT_EQ(e.event_type, +hoist::alarm_t::EVENT_REANNOUNCE) << "only re-announces follow the requests";
    EXPECT_EQ(e.kind, "INPUT_STALE") << "alarms without a state are not announced";
    EXPECT_TRUE(e.active);
    EXPECT_FALSE(e.acked);
    answers.push_back(seen.events[i].second);
  }
  ASSERT_EQ(answers.size(), 2u) << "five requests: honoured at once, then once (merged) a second later\n" << logs.str();
  // (Receive times: the second answer is honoured a full second after the
  // first; the margin is for a loaded machine delaying the first delivery.)
  EXPECT_LT(std::chrono::duration<double>(answers[0] - t_sent).count(), 0.9) << "the first is answered at once";
  EXPECT_GE(std::chrono::duration<double>(answers[1] - answers[0]).count(), 0.8) << "at most one a second";
  const InputStats st = d.shaft(0).stats().in;
  EXPECT_EQ(st.commands_applied, 0) << "a re-announce changes nothing (no AUDIT)";
  d.requestStop("test over");
  d.finish();
  EXPECT_NE(logs.str().find("alarm re-announce requests: 5 (2 honoured, 3 merged"), std::string::npos) << logs.str();
}
