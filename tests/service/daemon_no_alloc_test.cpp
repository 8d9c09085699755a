// The daemon's loop allocates nothing after start-up: the model step, the
// alarm evaluation, message encoding, LCM publish and receive, log lines.
//
// malloc/calloc/realloc/aligned allocation are interposed for the whole
// process (this executable's definitions take precedence over libc's for
// every library, LCM and GLib included) and counted only on the thread that
// runs the daemon's loop while it is being watched.  The loop hosts two
// shafts (1 kHz n = 50, and 100 Hz n = 20 on prefix "B/"), fed by a winder
// stream over real UDP multicast (loopback, ttl=0) that moves the cage (the
// clearance alarms raise and clear) and pauses (INPUT_STALE raises and
// clears), so every event path runs inside the watched window.  Both shafts
// run look-ahead forecasts: the loop saves the solver state into
// the preallocated mailbox slot and hands it to the worker pool, takes the
// results, publishes HOIST_FORECAST and feeds PREDICTED_* alarms; trip plans
// arrive on HOIST_TRIP_PLAN -- all inside the watched window.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <unistd.h>
#include <spdlog/sinks/ostream_sink.h>
#include <sstream>
#include <thread>

#include "daemon.hpp"
#include "hoist/alarm_ack_t.hpp"
#include "hoist/cage_imu_t.hpp"
#include "hoist/profile.hpp"
#include "hoist/trip_plan_t.hpp"
#include "hoist/winder_t.hpp"

#include "limit_malloc.hpp"

using hoist::test::AllocationWatch;
using hoist::test::watchedAllocationCount;

using namespace hoist;
using namespace hoist::service;
using namespace std::chrono_literals;

namespace {

const char* kUrl = "udpm://239.255.76.67:7811?ttl=0";

std::shared_ptr<spdlog::logger> captureLogger(std::ostringstream& os) {
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(os);
  auto log = std::make_shared<spdlog::logger>("no-alloc", sink);
  log->set_level(spdlog::level::info);
  return log;
}

TwinConfig shaftConfig(double rate, int n, const std::string& prefix) {
  TwinConfig c;
  c.shaft.n = n;
  c.service.rate = rate;
  c.service.channel_prefix = prefix;
  c.service.shape_rate = 10.0;
  c.service.health_rate = 5.0;
  // Small gaps: the moving cage raises and clears the clearance alarms.
  c.alarms.gap_pos_y = 2e-4;
  c.alarms.gap_neg_y = 2e-4;
  c.alarms.guide_rope_gap = 2e-4;
  c.alarms.on_delay = 0.0;
  c.alarms.off_delay = 0.0;
  c.alarms.reannounce = 0.5;
  c.alarms.latch_critical = false;
  c.forecast.enabled = true;
  c.forecast.rate = 5.0;
  c.forecast.horizon = 0.5;
  c.forecast.amax = 1.5;  // the winder's limit: the feeder's plans use amax 1.5
  c.estimator.enabled = prefix.empty();  // shaft A: the load estimator too, fed by an IMU
  return c;
}

/// Publishes the paper's trapezoid on both shafts' channels at 1 kHz, with
/// the given pauses (no input: INPUT_STALE).
class Feeder {
 public:
  Feeder() : lcm_(kUrl) {}
  bool good() { return lcm_.good(); }
  void run(std::chrono::duration<double> total, double pause_from, double pause_to) {
    const HoistProfile prof = HoistProfile::trapezoid();
    const auto t0 = std::chrono::steady_clock::now();
    std::int64_t seq = 0;
    for (int k = 0;; ++k) {
      const auto due = t0 + std::chrono::microseconds(1000 * k);
      std::this_thread::sleep_until(due);
      const double t = 1e-3 * k;
      if (t >= total.count()) break;
      if (t >= pause_from && t < pause_to) continue;
      const Kinematics kin = prof.at(t);
      winder_t m{};
      m.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                    std::chrono::system_clock::now().time_since_epoch()).count();
      m.seq = seq++;
      m.v = kin.v;
      m.a = kin.a;
      m.has_length = true;
      m.length = kin.l;
      lcm_.publish("HOIST_WINDER", &m);
      lcm_.publish("B/HOIST_WINDER", &m);
      if (k % 10 == 5) {  // the cage IMU of shaft A at 100 Hz: its estimator runs and its forecasts start from it
        cage_imu_t imu{};
        imu.utime = m.utime;
        imu.seq = k;
        imu.f_y = 0.0;
        imu.omega = 0.0;
        lcm_.publish("HOIST_CAGE_IMU", &imu);
      }
      sent_ = seq;
      if (k == 1500) {  // an operator adopts a guide-rope preload on A (issue 32): built off the loop, used at rest
        alarm_ack_t ack{};
        ack.utime = m.utime;
        ack.action = alarm_ack_t::ACTION_ADOPT_PRELOAD;
        ack.preload_scale = 0.8;
        ack.user = "eng";
        lcm_.publish("HOIST_ALARM_ACK", &ack);
      }
      if (k % 100 == 50) {  // a trip plan every 0.1 s (it fits the motion: accepted)
        trip_plan_t p{};
        p.utime = m.utime;
        p.seq = k;
        p.target_length = 300.0;
        p.vmax = 5.0;
        p.amax = 1.5;
        p.jerk = 100.0;
        lcm_.publish("HOIST_TRIP_PLAN", &p);
        lcm_.publish("B/HOIST_TRIP_PLAN", &p);
      }
    }
  }
  std::int64_t sent() const { return sent_; }

 private:
  ::lcm::LCM lcm_;
  std::int64_t sent_ = 0;
};

bool multicastWorks() {
  ::lcm::LCM l(kUrl);
  return l.good();
}

}  // namespace

TEST(DaemonNoAlloc, CounterSeesMallocOnTheWatchedThreadOnly) {
  // The interposer works (a test that cannot fail is a defect) ...
  void* volatile p = nullptr;
  std::vector<double>* v = nullptr;
  long seen = 0;
  {
    AllocationWatch watch;
    p = std::malloc(100);
    v = new std::vector<double>(10);
    seen = watch.count();
  }
  std::free(p);
  delete v;
  EXPECT_GE(seen, 2);
  // ... and ignores other threads.
  const long mid = watchedAllocationCount();
  std::thread([] { std::free(std::malloc(64)); }).join();
  EXPECT_EQ(watchedAllocationCount(), mid);
}

TEST(DaemonNoAlloc, LoopWithTwoShaftsAlarmsAndStaleInputAllocatesNothing) {
  if (!multicastWorks())
    GTEST_FAIL() << "UDP multicast on loopback is off: run scripts/setup.sh or, as root, "
                    "ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo";
  std::ostringstream logs;
  DaemonOptions opt;
  opt.shafts = {shaftConfig(1000.0, 50, ""), shaftConfig(100.0, 20, "B/")};
  opt.labels = {"A", "B"};
  // Many shafts: 15 more (unfed, default gaps) shafts at 100 Hz, so that the
  // loop drains its input socket between shafts within a tick (every
  // Daemon::kDrainEvery = 16 shafts) and the bounded envelope runs.
  for (int i = 1; i <= 15; ++i) {
    TwinConfig c;
    c.shaft.n = 10;
    c.service.rate = 100.0;
    c.service.channel_prefix = "C" + std::to_string(i) + "/";
    opt.shafts.push_back(c);
    opt.labels.push_back("C" + std::to_string(i));
  }
  // [history] on for A and B (issue 32): every step is copied into their
  // trip rooms' rings on the loop thread; the workers record the trips.
  const auto hdir = std::filesystem::temp_directory_path() / ("daemon_no_alloc_history_" + std::to_string(::getpid()));
  std::filesystem::create_directories(hdir);
  TripHistoryConfig hist;
  hist.enabled = true;
  hist.store.url = (hdir / "history.sqlite").string();
  hist.config_dir = hdir.string();
  hist.shaft = "A";
  opt.history = {hist, hist};
  opt.history[1].shaft = "B";
  opt.lcm_url = kUrl;
  Daemon d(std::move(opt), captureLogger(logs));
  ASSERT_TRUE(d.start());

  Feeder feeder;
  ASSERT_TRUE(feeder.good());
  // 4.5 s of input with a 0.4 s pause at 2.5 s (INPUT_STALE raise and clear).
  std::thread feed([&] { feeder.run(4.5s, 2.5, 2.9); });

  auto loopFor = [&](std::chrono::duration<double> span) {
    const auto until = std::chrono::steady_clock::now() + span;
    while (std::chrono::steady_clock::now() < until) {
      d.poll();
      std::this_thread::sleep_for(50us);
    }
  };
  loopFor(1.0s);  // warm-up: first input, re-initialization, first events, first health
  // What the checks below read: the rooms' statistics plus the model's input
  // and envelope counters (the run report's sources).
  struct Snap {
    TickStats tick;
    InputStats in;
    OutputStats out;
    ForecastStats fc;
    std::int64_t accepted, envelope_exact, envelope_bounded;
  };
  auto snap = [&](int i) {
    const ShaftTwin& s = d.shaft(i);
    const ShaftStatsView v = s.stats();
    return Snap{v.tick, v.in, v.out, v.forecast, s.core().counters().accepted, s.core().envelope().exactEvaluations(),
                s.core().envelope().boundedEvaluations()};
  };
  const Snap a0 = snap(0), b0 = snap(1), c0 = snap(2);
  const std::int64_t trip_ticks0 = d.shaft(0).trips()->counters().ticks.load();
  const long adoptions0 = d.shaft(0).preloadAdoptions();
  long allocs = 0;
  {
    AllocationWatch watch;
    loopFor(3.3s);
    allocs = watch.count();
  }
  const Snap a1 = snap(0), b1 = snap(1), c1 = snap(2);
  const std::int64_t trip_ticks1 = d.shaft(0).trips()->counters().ticks.load();
  const long adoptions1 = d.shaft(0).preloadAdoptions();
  feed.join();
  d.requestStop("test over");
  d.finish();

  EXPECT_EQ(allocs, 0) << "heap allocations on the loop thread after start-up";
  // The trip room took every step of the window, none dropped.
  EXPECT_GT(trip_ticks1 - trip_ticks0, 1000);
  EXPECT_EQ(d.shaft(0).trips()->counters().dropped.load(), 0);
  EXPECT_TRUE(d.shaft(2).trips() == nullptr);
  std::error_code ec;
  std::filesystem::remove_all(hdir, ec);
  // The watched window did the real work.
  // (3.3 s at 1 kHz and 100 Hz: 3300 and 330 ticks on an idle machine; a
  // loaded one skips some -- the point is that the loop ran, alarms and all)
  EXPECT_GT(a1.tick.ticks - a0.tick.ticks, 1000);
  EXPECT_GT(b1.tick.ticks - b0.tick.ticks, 100);
  EXPECT_GT(a1.accepted - a0.accepted, 1500);
  EXPECT_GT(b1.accepted - b0.accepted, 1500);
  EXPECT_GT(a1.out.alarm_events - a0.out.alarm_events, 4) << logs.str();
  EXPECT_GT(b1.out.alarm_events - b0.out.alarm_events, 4) << logs.str();
  EXPECT_EQ(a1.out.publish_failures, 0);
  EXPECT_GT(c1.envelope_bounded - c0.envelope_bounded, 250) << "the bounded envelope ran in the window";
  EXPECT_GT(a1.envelope_exact - a0.envelope_exact, 0);
  EXPECT_GT(a1.tick.ns_model - a0.tick.ns_model, 0) << "cost split measured";
  EXPECT_GT(a1.tick.ns_publish - a0.tick.ns_publish, 0);
  // Forecasts ran and came back through the loop in the window (5 Hz).
  EXPECT_GE(a1.fc.forecasts - a0.fc.forecasts, 8) << logs.str();
  // ... some of them from the load estimate (its state shifted in the loop).
  EXPECT_GE(a1.fc.forecasts_from_estimate - a0.fc.forecasts_from_estimate, 4) << logs.str();
  EXPECT_GE(b1.fc.forecasts - b0.fc.forecasts, 8) << logs.str();
  EXPECT_GE(a1.in.plans_accepted - a0.in.plans_accepted, 20);
  EXPECT_EQ(a1.in.plansRejected(), 0) << logs.str();
  const std::string log = logs.str();
  EXPECT_NE(log.find("[A] ALARM INPUT_STALE"), std::string::npos) << log;
  EXPECT_NE(log.find("[B] alarm: INPUT_STALE WARNING cleared"), std::string::npos) << log;
  // The preload adopted in the window: requested while the cage moved (1.5 s),
  // swapped in at rest (the pause) -- on the loop, without an allocation.
  EXPECT_EQ(adoptions0, 0);
  EXPECT_EQ(adoptions1, 1) << log;
  EXPECT_NE(log.find("[A] AUDIT operator 'eng': adopt the guide-rope preloads x0.8"), std::string::npos) << log;
  EXPECT_NE(log.find("[A] AUDIT operator 'eng': the live twin now runs the guide-rope preloads x0.8"),
            std::string::npos) << log;
}
