// The daemon's miss record and its start budget, in-process over loopback
// multicast (ports 8020-8023; outputs on their own port):
//   * many twins (32) whose first inputs arrive in the same period start at most
//     [service] max_starts_per_tick per tick, all within a bounded number of
//     ticks, and report HOIST_HEALTH.starting (and publish no HOIST_CAGE)
//     while they wait;
//   * a slow tick injected on purpose (TestHooks::slow_tick_at) is a miss
//     whose record -- in the daemon, in HOIST_HEALTH and in the run report --
//     puts the lost time in the model step;
//   * the ring keeps the latest records and counts the dropped ones;
//   * lockstep shafts on a moving trip share the schedule's budget of exact
//     guide-rope envelopes ([service] max_exact_envelopes_per_tick): the
//     schedule with a budget defers some, the one without defers none
//     (ports 8024-8025).
// No wall-clock-tight assertions: bounds are in ticks, and times are checked
// only against the injected delay with a wide margin.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <spdlog/sinks/ostream_sink.h>
#include <sstream>
#include <thread>

#include "daemon.hpp"
#include "hoist/health_t.hpp"
#include "hoist/profile.hpp"
#include "hoist/winder_t.hpp"
#include "lcm_fixtures.hpp"

using namespace hoist;
using namespace hoist::service;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {

std::shared_ptr<spdlog::logger> captureLogger(std::ostringstream& os) {
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(os);
  auto log = std::make_shared<spdlog::logger>("misses", sink);
  log->set_level(spdlog::level::info);
  return log;
}

TwinConfig smallShaft(const std::string& prefix) {
  TwinConfig c;
  c.shaft.n = 6;  // cheap: the test is about the loop, not the model
  c.service.rate = 100.0;
  c.service.channel_prefix = prefix;
  c.service.shape_rate = 0.0;
  c.service.envelope_points = 21;
  c.service.shape_points = 11;
  c.forecast.enabled = false;  // (on by default; not what these tests are about)
  return c;
}

std::int64_t nowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// Drives the daemon and the listener on this thread for `span`.
void loopFor(Daemon& d, hoist::test::Listener& l, std::chrono::duration<double> span) {
  const auto until = std::chrono::steady_clock::now() + span;
  while (std::chrono::steady_clock::now() < until) {
    d.poll();
    for (int i = 0; i < 512 && l.lcm().handleTimeout(0) > 0; ++i) {
    }
    std::this_thread::sleep_for(100us);
  }
}

}  // namespace

TEST(MissLog, KeepsTheLatestRecordsAndCountsTheDropped) {
  auto log = std::make_unique<MissLog>();
  EXPECT_EQ(log->kept(), 0u);
  EXPECT_EQ(log->worst(), nullptr);
  const std::int64_t n = static_cast<std::int64_t>(MissLog::kCapacity) + 37;
  for (std::int64_t i = 0; i < n; ++i) {
    MissRecord& r = log->begin();
    r.tick = 1000 + i;
    r.late_us = i == 10 ? 1e9 : (i == n - 5 ? 5e6 : 10.0 + static_cast<double>(i % 7));
    log->commit();
  }
  EXPECT_EQ(log->total(), n);
  EXPECT_EQ(log->kept(), MissLog::kCapacity);
  EXPECT_EQ(log->dropped(), 37);
  EXPECT_EQ(log->at(0).tick, 1000 + 37) << "oldest kept first";
  EXPECT_EQ(log->at(0).seq, 37);
  EXPECT_EQ(log->at(MissLog::kCapacity - 1).tick, 1000 + n - 1);
  ASSERT_NE(log->worst(), nullptr);
  EXPECT_EQ(log->worst()->seq, n - 5) << "the record of lateness 1e9 was dropped; the worst kept one is 5e6";
}

TEST(DaemonStarts, ThirtyTwoFirstInputsInOnePeriodStartAtMostKPerTick) {
  const std::string url = hoist::test::urlFor(8020), url_out = hoist::test::urlFor(8021);
  std::string why;
  if (!hoist::test::loopbackMulticastWorks(url, why)) GTEST_FAIL() << why << ".\n" << hoist::test::kMulticastHelp;
  // (32 shafts, one start per tick: the starts take 32 ticks, as 64 at two
  // per tick would, at half the stepping cost -- a TSan build steps 64 small
  // twins slower than real time.)
  constexpr int kShafts = 32, kBudget = 1;
  std::ostringstream logs;
  DaemonOptions opt;
  for (int i = 0; i < kShafts; ++i) {
    TwinConfig c = smallShaft("s" + std::to_string(i) + "/");
    c.service.health_rate = 10.0;
    c.service.cage_rate = 10.0;  // (staggered by shaft: k + i a multiple of 10)
    c.service.max_starts_per_tick = kBudget;
    opt.shafts.push_back(c);
    opt.labels.push_back("s" + std::to_string(i));
  }
  opt.lcm_url = url;
  opt.lcm_url_out = url_out;
  Daemon d(std::move(opt), captureLogger(logs));
  hoist::test::Listener listener(url_out);
  ASSERT_TRUE(listener.good());
  // One subscription per shaft: each has its own LCM receive queue (30
  // messages), so a slow listener (a sanitizer build) loses nothing.
  for (int i = 0; i < kShafts; ++i) listener.subscribe("s" + std::to_string(i) + "/HOIST_(CAGE|HEALTH)");
  ASSERT_TRUE(d.start()) << logs.str();
  loopFor(d, listener, 0.2s);  // idle: no input yet
  for (int i = 0; i < kShafts; ++i) EXPECT_FALSE(d.shaft(i).starting());

  // Every shaft's winder stream, 100 Hz from the same period on.
  // (The stream goes on until the test has seen every shaft start and run:
  // on a slow machine -- a sanitizer build -- the last starts come after
  // 1.2 s, and a twin whose input has stopped publishes no cage state.)
  std::atomic<bool> fed{false}, stop_feed{false};
  std::thread feeder([&] {
    ::lcm::LCM out(url);
    const std::int64_t u0 = nowUs();
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < 2000 && !(k >= 120 && stop_feed); ++k) {
      std::this_thread::sleep_until(t0 + std::chrono::milliseconds(10 * k));
      for (int i = 0; i < kShafts; ++i) {
        winder_t m{};
        m.utime = u0 + 10000 * k;
        m.seq = k;
        m.has_length = true;
        m.length = 100.0 + i;
        out.publish("s" + std::to_string(i) + "/HOIST_WINDER", &m);
      }
    }
    fed = true;
  });
  const auto until = std::chrono::steady_clock::now() + 10s;
  auto allStarted = [&] {
    for (int i = 0; i < kShafts; ++i)
      if (d.shaft(i).startTick() < 0) return false;
    return true;
  };
  while (!allStarted() && std::chrono::steady_clock::now() < until) loopFor(d, listener, 20ms);
  loopFor(d, listener, 0.3s);  // a health message and a cage state of each shaft after its start
  stop_feed = true;
  while (!fed) loopFor(d, listener, 20ms);
  feeder.join();
  d.requestStop("test over");
  d.finish();

  // Each started, at most K per tick, all within N / K ticks (+ the ticks
  // over which the first inputs arrived), so not all at once either.
  std::map<std::int64_t, int> per_tick;
  std::int64_t first = INT64_MAX, last = -1;
  for (int i = 0; i < kShafts; ++i) {
    const std::int64_t t = d.shaft(i).startTick();
    ASSERT_GE(t, 0) << "shaft " << i << " never started\n" << logs.str();
    ++per_tick[t];
    first = std::min(first, t);
    last = std::max(last, t);
  }
  for (const auto& [tick, n] : per_tick) EXPECT_LE(n, kBudget) << "tick " << tick;
  EXPECT_GE(last - first, kShafts / kBudget - 1) << "the starts were spread by the budget";
  EXPECT_LE(last - first, kShafts / kBudget + 5) << "all started within a bounded number of ticks";

  // While waiting they said so, published no cage state, and were not
  // flagged degraded for it; afterwards they run.
  int reported_starting = 0, starting_fresh = 0;
  for (int i = 0; i < kShafts; ++i) {
    const std::string p = "s" + std::to_string(i) + "/";
    const auto& hm = listener.messages(p + "HOIST_HEALTH");
    const auto health = listener.decoded<health_t>(p + "HOIST_HEALTH");
    ASSERT_EQ(hm.size(), health.size());
    std::int64_t last_starting_recv = -1;
    for (std::size_t j = 0; j < health.size(); ++j)
      if (health[j].starting) {
        last_starting_recv = hm[j].recv_utime;
        // (A loop stalled by a loaded machine may find the input stale: that is degraded.)
        if (health[j].input_age >= 0.0 && health[j].input_age < 0.02) {
          EXPECT_FALSE(health[j].degraded) << p << ": waiting for the start budget is not degraded output";
          ++starting_fresh;
        }
      }
    if (last_starting_recv >= 0) ++reported_starting;
    const auto& cages = listener.messages(p + "HOIST_CAGE");
    ASSERT_FALSE(cages.empty()) << p << " published no cage state after its start";
    EXPECT_GT(cages.front().recv_utime, last_starting_recv) << p << ": a cage state before its start";
    ASSERT_FALSE(health.empty());
    EXPECT_FALSE(health.back().starting) << p;
    EXPECT_EQ(health.back().starts_deferred, 1) << p;
  }
  // Health goes out every 0.1 s per shaft and the starts take 32 ticks
  // (0.32 s or more): the shafts that started late said "starting" first.
  EXPECT_GE(reported_starting, kShafts / 4) << "shafts that published starting = true while waiting";
  EXPECT_GE(starting_fresh, 1) << "starting messages with a fresh input (not degraded)";
}

TEST(DaemonMisses, ASlowTickIsRecordedWithItsSplitInHealthAndReport) {
  const std::string url = hoist::test::urlFor(8022), url_out = hoist::test::urlFor(8023);
  std::string why;
  if (!hoist::test::loopbackMulticastWorks(url, why)) GTEST_FAIL() << why << ".\n" << hoist::test::kMulticastHelp;
  const fs::path dir = fs::temp_directory_path() / ("hoist-misses-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string report = (dir / "report.json").string();
  constexpr double kSlowMs = 80.0;  // 8 periods at 100 Hz
  std::ostringstream logs;
  DaemonOptions opt;
  for (int i = 0; i < 4; ++i) {
    TwinConfig c = smallShaft("m" + std::to_string(i) + "/");
    c.service.health_rate = 5.0;
    opt.shafts.push_back(c);
    opt.labels.push_back("m" + std::to_string(i));
  }
  opt.lcm_url = url;
  opt.lcm_url_out = url_out;
  opt.report_path = report;
  opt.hooks.slow_tick_at = 0.4;
  opt.hooks.slow_tick_ms = kSlowMs;
  Daemon d(std::move(opt), captureLogger(logs));
  hoist::test::Listener listener(url_out);
  ASSERT_TRUE(listener.good());
  listener.subscribe("m0/HOIST_HEALTH");
  ASSERT_TRUE(d.start()) << logs.str();
  loopFor(d, listener, 1.6s);
  d.requestStop("test over");
  ASSERT_TRUE(d.finish());

  // In the daemon: a record whose split puts the injected time in the step.
  const MissLog& m = d.misses();
  ASSERT_GE(m.total(), 1) << logs.str();
  const MissRecord* slow = nullptr;
  for (std::size_t i = 0; i < m.kept(); ++i)
    if (m.at(i).work.step >= static_cast<std::int64_t>(0.5 * kSlowMs * 1e6)) slow = &m.at(i);
  ASSERT_NE(slow, nullptr) << "no miss record with the slow step in its split";
  EXPECT_GE(slow->skipped, 1);
  EXPECT_GE(slow->late_us, 1e4) << "more than a period late";
  EXPECT_EQ(slow->shafts, 4);
  EXPECT_EQ(slow->shafts_late, 4) << "every shaft of that tick began more than a period late";
  EXPECT_GE(slow->worst_late_us, slow->first_late_us);
  EXPECT_GT(slow->model_t, 0.3);
  EXPECT_GT(slow->wall, 0.3);
  const LoopSplit& w = slow->work;
  for (std::int64_t other : {w.receive, w.envelope, w.publish, w.forecast, w.start, w.health, w.other})
    EXPECT_LT(other, w.step) << "the step dominates the split";
  EXPECT_LE(1e-3 * static_cast<double>(w.sum()), slow->window_us + 1.0) << "the work fits the interval";
  // The busy-wait ran on the loop thread: its CPU time in the interval is
  // positive and no more than the interval (one thread).
  EXPECT_GT(slow->cpu_us, 0.0);
  EXPECT_LE(slow->cpu_us, slow->window_us * 1.05 + 1000.0);

  // In HOIST_HEALTH of the shaft that took part (all four did).
  const auto health = listener.decoded<health_t>("m0/HOIST_HEALTH");
  bool seen = false;
  for (const health_t& h : health) {
    ASSERT_GE(h.n_misses, 0);
    ASSERT_LE(h.n_misses, health_t::MAX_MISSES);
    for (int i = 0; i < h.n_misses; ++i) {
      if (h.miss_step_us[i] < 0.5 * kSlowMs * 1e3) continue;
      seen = true;
      EXPECT_GE(h.misses_recorded, 1);
      EXPECT_GE(h.miss_late_us[i], 1e4);
      EXPECT_GE(h.miss_skipped[i], 1);
      EXPECT_EQ(h.miss_shafts_late[i], 4);
      EXPECT_GT(h.miss_utime[i], 0);
      EXPECT_GE(h.miss_timer_us[i], 0.0);
    }
  }
  EXPECT_TRUE(seen) << health.size() << " health messages, none with the slow tick's miss";

  // In the run report: every record, bounded, with the worst one.
  std::ifstream in(report);
  ASSERT_TRUE(in.good());
  const auto j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.contains("misses"));
  const auto& jm = j["misses"];
  EXPECT_EQ(jm["recorded"].get<std::int64_t>(), m.total());
  EXPECT_EQ(jm["kept"].get<std::int64_t>(), m.total());
  EXPECT_EQ(jm["dropped"].get<std::int64_t>(), 0);
  ASSERT_EQ(jm["records"].size(), static_cast<std::size_t>(m.total()));
  bool in_report = false;
  for (const auto& r : jm["records"])
    if (r["split_us"]["step"].get<double>() >= 0.5 * kSlowMs * 1e3) {
      in_report = true;
      EXPECT_GE(r["skipped"].get<std::int64_t>(), 1);
      EXPECT_EQ(r["shafts"].get<int>(), 4);
      EXPECT_FALSE(r["worst_shaft"].get<std::string>().empty());
    }
  EXPECT_TRUE(in_report);
  EXPECT_GE(jm["worst"]["late_us"].get<double>(), 1e4);
  fs::remove_all(dir);
}

TEST(DaemonEnvelopes, LockstepShaftsOnAMovingTripShareTheExactEnvelopeBudget) {
  const std::string url = hoist::test::urlFor(8024), url_out = hoist::test::urlFor(8025);
  std::string why;
  if (!hoist::test::loopbackMulticastWorks(url, why)) GTEST_FAIL() << why << ".\n" << hoist::test::kMulticastHelp;
  // Two schedules of 6 shafts each, all fed the same accelerating trip:
  // at 100 Hz one exact envelope per tick across its shafts, at 50 Hz no
  // budget.  (The bounded envelope of one such twin needs an exact refresh
  // on a few % of its steps, all of them on the same steps.)
  constexpr int kPerGroup = 6;
  std::ostringstream logs;
  DaemonOptions opt;
  for (int i = 0; i < 2 * kPerGroup; ++i) {
    TwinConfig c = smallShaft("e" + std::to_string(i) + "/");
    c.shaft.n = 12;
    c.service.rate = i < kPerGroup ? 100.0 : 50.0;
    c.service.max_exact_envelopes_per_tick = i < kPerGroup ? 1 : 0;
    c.service.max_starts_per_tick = 0;
    opt.shafts.push_back(c);
    opt.labels.push_back("e" + std::to_string(i));
  }
  opt.lcm_url = url;
  opt.lcm_url_out = url_out;
  Daemon d(std::move(opt), captureLogger(logs));
  ASSERT_TRUE(d.start()) << logs.str();
  std::atomic<bool> fed{false};
  std::thread feeder([&] {
    ::lcm::LCM out(url);
    const HoistProfile prof = HoistProfile::trapezoid();
    const std::int64_t u0 = nowUs();
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < 400; ++k) {  // 4 s from the start of the trip at 100 Hz
      std::this_thread::sleep_until(t0 + std::chrono::milliseconds(10 * k));
      const Kinematics kin = prof.at(prof.startTime() + 0.01 * k);
      winder_t m{};
      m.utime = u0 + 10000 * k;
      m.seq = k;
      m.v = kin.v;
      m.a = kin.a;
      m.has_length = true;
      m.length = kin.l;
      for (int i = 0; i < 2 * kPerGroup; ++i) out.publish("e" + std::to_string(i) + "/HOIST_WINDER", &m);
    }
    fed = true;
  });
  hoist::test::Listener listener(url_out);
  ASSERT_TRUE(listener.good());
  while (!fed) loopFor(d, listener, 20ms);
  feeder.join();
  d.requestStop("test over");
  d.finish();

  std::int64_t deferred[2] = {0, 0}, exact[2] = {0, 0}, bounded[2] = {0, 0};
  for (int i = 0; i < 2 * kPerGroup; ++i) {
    const GuideRopeEnvelope& env = d.shaft(i).core().envelope();
    const int g = i < kPerGroup ? 0 : 1;
    deferred[g] += env.deferredEvaluations();
    exact[g] += env.exactEvaluations();
    bounded[g] += env.boundedEvaluations();
    EXPECT_EQ(env.deferredEvaluations() > 0, env.longestDeferral() > 0) << i;
  }
  std::printf("with a budget of 1 per tick: %lld exact, %lld bounded, %lld deferred; without: %lld exact, %lld "
              "bounded, %lld deferred\n",
              static_cast<long long>(exact[0]), static_cast<long long>(bounded[0]),
              static_cast<long long>(deferred[0]), static_cast<long long>(exact[1]),
              static_cast<long long>(bounded[1]), static_cast<long long>(deferred[1]));
  EXPECT_GT(bounded[0] + bounded[1], 0) << logs.str();
  EXPECT_GT(deferred[0], 0) << "lockstep shafts needed more than one exact envelope on some tick";
  EXPECT_EQ(deferred[1], 0) << "no budget, no deferral";
}
