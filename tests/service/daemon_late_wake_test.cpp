// A loop that wakes late with inputs queued on its socket (issue 35 item 5),
// in-process over loopback multicast (ports 7930-7931):
//   * the winder streams at 100 Hz (INPUT_STALE after 150 ms);
//   * two shafts on one schedule; a tick of the first one takes 200 ms
//     (TestHooks::slow_tick_at), so the second one's tick starts 200 ms late
//     with 20 of its inputs queued on the socket;
//   * then the daemon's loop is not run for 200 ms three times (a late
//     wake-up: timer and socket both ready when it runs again);
//   * staleness is judged after the queued inputs are read, so no
//     INPUT_STALE is raised or cleared on either shaft, and no cage state
//     carries the held v = a = 0 of a stale input.
// Before the fix the second shaft's tick found its last input 200 ms old,
// raised INPUT_STALE, and the next drain cleared it (a raise/clear pair in
// the same millisecond, and an RTN UNACK row).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <spdlog/sinks/ostream_sink.h>
#include <sstream>
#include <thread>

#include "daemon.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/winder_t.hpp"
#include "lcm_fixtures.hpp"

using namespace hoist;
using namespace hoist::service;
using namespace std::chrono_literals;

namespace {

std::int64_t nowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

TEST(DaemonLateWake, QueuedInputsAreReadBeforeStalenessIsJudged) {
  const std::string url = hoist::test::urlFor(7930), url_out = hoist::test::urlFor(7931);
  std::string why;
  if (!hoist::test::loopbackMulticastWorks(url, why)) GTEST_FAIL() << why << ".\n" << hoist::test::kMulticastHelp;
  std::ostringstream logs;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(logs);
  auto log = std::make_shared<spdlog::logger>("late", sink);
  DaemonOptions opt;
  for (const char* p : {"a/", "b/"}) {
    TwinConfig c;
    c.shaft.n = 6;  // cheap: the test is about the loop, not the model
    c.service.rate = 100.0;
    c.service.channel_prefix = p;
    c.service.shape_rate = 0.0;
    c.service.envelope_points = 21;
    c.service.shape_points = 11;
    c.forecast.enabled = false;
    // INPUT_STALE after 150 ms without input: under the 200 ms of the slow
    // tick and of the late wake-ups (so the test fails without the fix), but
    // far over what a busy machine delays the feeder thread by.
    c.service.stale_periods = 0.0;
    c.service.stale_timeout = 0.15;
    opt.shafts.push_back(c);
    opt.labels.push_back(p);
  }
  opt.hooks.slow_tick_at = 1.5;  // [s] after the start, on a live stream
  opt.hooks.slow_tick_ms = 200.0;
  opt.lcm_url = url;
  opt.lcm_url_out = url_out;
  Daemon d(std::move(opt), log);
  hoist::test::Listener listener(url_out);
  ASSERT_TRUE(listener.good());
  listener.subscribe("[ab]/HOIST_(ALARM|CAGE)");
  ASSERT_TRUE(d.start()) << logs.str();

  // The winder's stream on a thread of its own: it goes on while the loop is
  // busy or asleep.
  constexpr double kV = 2.0;  // m/s, descending
  std::atomic<bool> stop_feed{false};
  std::thread feeder([&] {
    ::lcm::LCM out(url);
    const std::int64_t u0 = nowUs();
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; !stop_feed; ++k) {
      std::this_thread::sleep_until(t0 + std::chrono::milliseconds(10 * k));
      winder_t m{};
      m.utime = u0 + 10000 * k;
      m.seq = k;
      m.has_length = true;
      m.length = 300.0 + kV * 0.01 * k;
      m.v = kV;
      out.publish("a/HOIST_WINDER", &m);
      out.publish("b/HOIST_WINDER", &m);
    }
  });
  auto runFor = [&](std::chrono::duration<double> span) {
    const auto until = std::chrono::steady_clock::now() + span;
    while (std::chrono::steady_clock::now() < until) {
      d.poll();
      for (int i = 0; i < 512 && listener.lcm().handleTimeout(0) > 0; ++i) {
      }
      std::this_thread::sleep_for(200us);
    }
  };
  runFor(1.0s);  // started and running on a live stream
  ASSERT_GE(d.shaft(0).startTick(), 0) << logs.str();
  ASSERT_GE(d.shaft(1).startTick(), 0) << logs.str();
  const std::size_t cages_before = listener.messages("b/HOIST_CAGE").size();
  runFor(1.0s);  // the slow tick
  // Three late wake-ups of the loop, each with 20 inputs queued.
  for (int late = 0; late < 3; ++late) {
    std::this_thread::sleep_for(200ms);
    runFor(300ms);
  }
  stop_feed = true;
  feeder.join();
  d.requestStop("test over");
  d.finish();
  for (int i = 0; i < 512 && listener.lcm().handleTimeout(0) > 0; ++i) {
  }

  EXPECT_NE(logs.str().find("deadline miss"), std::string::npos) << "the slow tick happened";
  for (const char* p : {"a/", "b/"})
    for (const auto& a : listener.decoded<alarm_t>(std::string(p) + "HOIST_ALARM"))
      EXPECT_NE(a.kind, "INPUT_STALE") << p << ": event " << int(a.event_type) << " at t = " << a.t << "\n"
                                       << logs.str();
  const auto cages = listener.decoded<cage_state_t>("b/HOIST_CAGE");
  ASSERT_GT(cages.size(), cages_before + 50) << "the twin kept publishing after the late wake-ups";
  for (std::size_t i = cages_before; i < cages.size(); ++i)
    EXPECT_NEAR(cages[i].v, kV, 1e-9) << "cage state " << i << " at t = " << cages[i].t
                                      << ": a late wake-up fed v = 0 to the twin";
}
