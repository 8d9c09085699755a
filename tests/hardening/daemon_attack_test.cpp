// Adversarial classes (docs/hardening.md, 3b) against the real daemon over LCM
// (UDP multicast on loopback, ttl=0, ports 7851..7859, 7862-7863): the exact attacks,
// asserting the daemon stays alive and what it publishes and logs.
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <set>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/service/core/alarms.hpp"
#include "hoist/winder_t.hpp"
#include "lcm_fixtures.hpp"

using namespace hoist::test;
namespace fs = std::filesystem;

namespace {

std::int64_t nowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

hoist::winder_t winder(std::int64_t seq, std::int64_t utime, double v, double length) {
  hoist::winder_t m{};
  m.utime = utime;
  m.seq = seq;
  m.v = v;
  m.has_length = true;
  m.length = length;
  return m;
}

class DaemonAttack : public ::testing::Test {
 protected:
  void start(int port, const std::string& name, const std::string& prefix = "") {
    url_ = urlFor(port);
    dir_ = testDir(name);
    prefix_ = prefix;
    std::string why;
    if (!loopbackMulticastWorks(url_, why)) FAIL() << why << ".\n" << kMulticastHelp;
    listen();
  }
  void listen() {
    listener_ = std::make_unique<Listener>(url_);
    ASSERT_TRUE(listener_->good()) << kMulticastHelp;
    listener_->subscribe(".*HOIST_HEALTH");
    listener_->subscribe(".*HOIST_CAGE");
    listener_->subscribe(".*HOIST_ALARM");
  }
  std::string writeConfig(const std::string& file, const std::string& text) {
    const auto p = (dir_ / file).string();
    std::ofstream(p) << text;
    return p;
  }
  std::unique_ptr<Process> startDaemon(std::vector<std::string> extra, const std::string& log_name,
                                       const std::string& health = "HOIST_HEALTH") {
    std::vector<std::string> argv{HOIST_TWIND, "--lcm-url", url_, "--log-level", "info"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return startDaemonAndWait(*listener_, argv, (dir_ / log_name).string(), health);
  }
  hoist::health_t lastHealth(const std::string& ch = "HOIST_HEALTH") {
    auto hs = listener_->decoded<hoist::health_t>(ch);
    return hs.empty() ? hoist::health_t{} : hs.back();
  }
  hoist::health_t waitHealth(const std::function<bool(const hoist::health_t&)>& pred, std::chrono::milliseconds timeout,
                             const std::string& ch = "HOIST_HEALTH") {
    hoist::health_t h{};
    listener_->waitFor(
        [&] {
          auto hs = listener_->decoded<hoist::health_t>(ch);
          if (hs.empty()) return false;
          h = hs.back();
          return pred(h);
        },
        timeout);
    return h;
  }
  void feed(const std::string& channel, int n, double v = 0.0, double l0 = 100.0, std::int64_t seq0 = 0) {
    std::int64_t utime = nowUs();
    for (int k = 0; k < n; ++k, utime += 10000) {
      const auto m = winder(seq0 + k, utime, v, l0 + v * 0.01 * k);
      listener_->lcm().publish(channel, &m);
      listener_->pump(std::chrono::milliseconds(10));
    }
  }

  std::string url_, prefix_;
  fs::path dir_;
  std::unique_ptr<Listener> listener_;
};

}  // namespace

TEST_F(DaemonAttack, MillionDistinctChannelNamesKeepMemoryFlat) {
  // Channel-name spam: LCM 1.3.1 caches a handler entry per channel name seen
  // (11 MB per 100k names, never freed).  The daemon's own receive path
  // stores nothing per name: RSS growth < 2 MB after 1M distinct names.
  start(7851, "chanspam");
  auto d = startDaemon({}, "twind.log");
  const hoist::health_t h0 = waitHealth([](const hoist::health_t& h) { return h.rss_kb > 0; }, 3s);
  ASSERT_GT(h0.rss_kb, 0);
  // The listener would cache the names too: close it during the spam.  Send
  // distinct names in chunks until the daemon has received a million of
  // them (a loaded machine drops some in the socket buffer).
  hoist::health_t h1{};
  int sent = 0;
  while (sent < 3'000'000) {
    listener_.reset();
    {
      ::lcm::LCM pub(url_);  // publish only: no receive socket
      ASSERT_TRUE(pub.good());
      const char payload[8] = {1, 2, 3, 4, 5, 6, 7, 8};
      char name[40];
      const auto t0 = std::chrono::steady_clock::now();
      for (int i = 0; i < 200'000; ++i, ++sent) {
        std::snprintf(name, sizeof name, "SPAM_%07d", sent);
        pub.publish(name, payload, sizeof payload);
        if (i % 1000 == 999) std::this_thread::sleep_until(t0 + std::chrono::microseconds(10 * (i + 1)));
      }
    }
    const std::int64_t after = nowUs();
    listen();
    h1 = waitHealth([&](const hoist::health_t& h) { return h.utime > after; }, 5s);
    if (h1.datagrams_ignored >= 1'000'000) break;
  }
  EXPECT_TRUE(d->running());
  EXPECT_GE(h1.datagrams_ignored, 1'000'000) << "sent " << sent << " names";
  EXPECT_LT(h1.rss_kb - h0.rss_kb, 2048) << "RSS grew from " << h0.rss_kb << " to " << h1.rss_kb << " KiB";
  stopDaemonCleanly(*d, (dir_ / "twind.log").string());
}

TEST_F(DaemonAttack, ChannelPrefixIsALiteralNotARegex) {
  // Look-alike prefixes: "mine.1/" and "mine_1/" in one process; a feeder
  // on mine.1/ drives only that shaft, "mineX1/" drives none, a shelve on
  // mine_1/ reaches only mine_1/.
  start(7852, "prefix");
  const auto a = writeConfig("a.toml", "[service]\nchannel_prefix = \"mine.1/\"\n");
  const auto b = writeConfig("b.toml", "[service]\nchannel_prefix = \"mine_1/\"\n");
  auto d = startDaemon({"--config", a, "--config", b}, "twind.log", "mine_1/HOIST_HEALTH");
  feed("mineX1/HOIST_WINDER", 30);
  feed("mine.1/HOIST_WINDER", 50, 0.0, 100.0, 100);
  hoist::alarm_ack_t ack{};
  ack.kind = "*";
  ack.action = hoist::alarm_ack_t::ACTION_SHELVE;
  ack.shelve_duration = 60.0;
  ack.user = "op";
  listener_->lcm().publish("mine.1XHOIST_ALARM_ACK", &ack);
  listener_->lcm().publish("mine_1/HOIST_ALARM_ACK", &ack);
  listener_->pump(1500ms);
  const auto dot = lastHealth("mine.1/HOIST_HEALTH");
  const auto und = lastHealth("mine_1/HOIST_HEALTH");
  EXPECT_GE(dot.accepted, 40);
  EXPECT_LE(dot.accepted, 50) << "the mineX1/ feeder reached mine.1/";
  EXPECT_EQ(und.accepted, 0) << "mine_1/ followed another shaft's feeder";
  EXPECT_EQ(dot.alarms_shelved, 0);
  EXPECT_EQ(und.alarms_shelved, hoist::service::AlarmEngine::kSlots);  // every alarm of the shaft
  stopDaemonCleanly(*d, (dir_ / "twind.log").string());
}

TEST_F(DaemonAttack, SecondPublisherOnTheSameChannelsIsDetected) {
  // Two daemons with the same channels interleave contradictory
  // states; each must notice the other (instance_id) and alarm.
  start(7853, "duplicate");
  auto d1 = startDaemon({}, "twind1.log");
  auto d2 = startDaemon({}, "twind2.log");
  std::set<std::int64_t> ids;
  bool alarm = listener_->waitFor(
      [&] {
        for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM"))
          if (a.kind == "DUPLICATE_PUBLISHER" && a.event_type == hoist::alarm_t::EVENT_RAISE) return true;
        return false;
      },
      5s);
  EXPECT_TRUE(alarm);
  for (const auto& h : listener_->decoded<hoist::health_t>("HOIST_HEALTH")) ids.insert(h.instance_id);
  EXPECT_EQ(ids.size(), 2u);
  stopDaemonCleanly(*d1, (dir_ / "twind1.log").string());
  stopDaemonCleanly(*d2, (dir_ / "twind2.log").string());
  const std::string log = readFile((dir_ / "twind1.log").string()) + readFile((dir_ / "twind2.log").string());
  EXPECT_NE(log.find("another publisher"), std::string::npos);
}

TEST_F(DaemonAttack, AlarmEventOfAnotherInstanceOnItsOwnChannelRaisesDuplicatePublisher) {
  // Issue 33: one forged alarm_t on HOIST_ALARM (a CLEAR from another
  // instance) is a second publisher of the daemon's outputs, as forged health
  // is.  Before: nothing noticed it.  The daemon's own alarm events (a shelve
  // of CAGE_POS_Y: one event per level) raise nothing.
  start(7980, "forged_alarm");
  auto d = startDaemon({}, "twind.log");
  const hoist::health_t h = lastHealth();
  ASSERT_NE(h.instance_id, 0);
  auto duplicateRaised = [&] {
    for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM"))
      if (a.kind == "DUPLICATE_PUBLISHER" && a.event_type == hoist::alarm_t::EVENT_RAISE) return true;
    return false;
  };
  hoist::alarm_ack_t ack{};
  ack.kind = "CAGE_POS_Y";
  ack.action = hoist::alarm_ack_t::ACTION_SHELVE;
  ack.shelve_duration = 60.0;
  ack.user = "op";
  listener_->lcm().publish("HOIST_ALARM_ACK", &ack);
  ASSERT_TRUE(listener_->waitFor([&] { return listener_->count("HOIST_ALARM") > 0; }, 5s));
  listener_->pump(1500ms);
  for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM")) EXPECT_EQ(a.instance_id, h.instance_id);
  EXPECT_FALSE(duplicateRaised()) << "the daemon took its own alarm events for another publisher";
  hoist::alarm_t forged{};
  forged.utime = nowUs();
  forged.kind = "CAGE_POS_Y";
  forged.level = hoist::alarm_t::LEVEL_WARNING;
  forged.event_type = hoist::alarm_t::EVENT_CLEAR;
  forged.acked = 1;
  forged.message = "all clear";
  forged.user = "";
  forged.instance_id = h.instance_id + 1;
  listener_->lcm().publish("HOIST_ALARM", &forged);
  EXPECT_TRUE(listener_->waitFor(duplicateRaised, 5s)) << "a forged alarm event went unnoticed";
  // A forger who copies the instance id cannot use an event id the daemon has
  // not used yet without being noticed (and clients drop old event ids).
  forged.instance_id = h.instance_id;
  forged.id = 1'000'000;
  forged.utime = nowUs();
  listener_->lcm().publish("HOIST_ALARM", &forged);
  const auto until = std::chrono::steady_clock::now() + 5s;
  while (readFile((dir_ / "twind.log").string()).find("that it never published") == std::string::npos &&
         std::chrono::steady_clock::now() < until)
    listener_->pump(100ms);
  stopDaemonCleanly(*d, (dir_ / "twind.log").string());
  const std::string log = readFile((dir_ / "twind.log").string());
  EXPECT_NE(log.find("another publisher (instance " + std::to_string(h.instance_id + 1) + ") on HOIST_ALARM"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("an alarm event with this twin's instance id " + std::to_string(h.instance_id) +
                     " that it never published on HOIST_ALARM"),
            std::string::npos)
      << log;
}

TEST_F(DaemonAttack, SignalsAndADeadLogReaderDoNotKill) {
  // Before the fix: SIGHUP, SIGUSR1 and SIGPIPE killed the daemon at once.
  start(7854, "signals");
  // stderr into a pipe whose reader is gone: every log line hits EPIPE.
  int fds[2];
  ASSERT_EQ(::pipe2(fds, O_CLOEXEC), 0);  // the child keeps only its dup2'd copies of the write end
  Process d({HOIST_TWIND, "--lcm-url", url_, "--log-level", "debug"}, fds[1]);
  ASSERT_TRUE(d.started());
  ::close(fds[1]);
  ASSERT_TRUE(listener_->waitFor([&] { return listener_->count("HOIST_HEALTH") > 0; }, 10s));
  ::close(fds[0]);  // the log reader dies
  for (int sig : {SIGHUP, SIGUSR1, SIGUSR2, SIGPIPE, SIGHUP}) {
    d.signal(sig);
    listener_->pump(200ms);
  }
  feed("HOIST_WINDER", 50);  // log lines (debug health, stream start) onto the dead pipe
  const std::size_t before = listener_->count("HOIST_HEALTH");
  listener_->pump(1500ms);
  EXPECT_TRUE(d.running()) << "the daemon died (status " << d.wait(0ms) << ")";
  EXPECT_GT(listener_->count("HOIST_HEALTH"), before) << "no health after the signals";
  d.signal(SIGTERM);
  EXPECT_EQ(d.wait(2s), 0) << "not a clean exit after SIGTERM (128 + signal if killed)";
}

TEST_F(DaemonAttack, ConfigsThatCannotRunAreRefusedAndForcedOnesStayResponsive) {
  // Start-up budget: modes = 1000 at 1 kHz and max_step = 1e-9 started in silence.
  start(7855, "budget");
  const auto tiny = writeConfig("tiny.toml", "[service]\nmax_step = 1e-9\n");
  EXPECT_EQ(runProcess({HOIST_TWIND, "--config", tiny, "--lcm-url", url_}, (dir_ / "tiny.log").string(), 30s), 2);
  const std::string tiny_log = readFile((dir_ / "tiny.log").string());
  EXPECT_NE(tiny_log.find("service.max_step"), std::string::npos) << tiny_log;
  // modes = 400 at 1 kHz with 4 substeps per tick: about 3.5 ms per 1-ms
  // tick even on an idle machine (1000 modes would take longer to set up
  // than this test waits).
  const auto heavy =
      writeConfig("heavy.toml", "[model]\nmodes = 400\n[service]\nrate = 1000\nmax_step = 0.00025\n");
  EXPECT_EQ(runProcess({HOIST_TWIND, "--config", heavy, "--lcm-url", url_}, (dir_ / "heavy.log").string(), 60s), 2);
  const std::string heavy_log = readFile((dir_ / "heavy.log").string());
  EXPECT_NE(heavy_log.find("cannot run in real time"), std::string::npos) << heavy_log;
  EXPECT_NE(heavy_log.find("--force"), std::string::npos);
  // --force: it runs, overloaded, and stays responsive: health about 1 Hz,
  // SIGTERM honoured within a second.
  auto d = startDaemon({"--config", heavy, "--force"}, "forced.log");
  feed("HOIST_WINDER", 100, 1.0);
  const std::size_t n0 = listener_->count("HOIST_HEALTH");
  listener_->pump(3000ms);
  EXPECT_GE(listener_->count("HOIST_HEALTH") - n0, 2u) << "health went silent under overload";
  const auto t0 = std::chrono::steady_clock::now();
  d->signal(SIGTERM);
  EXPECT_EQ(d->wait(10s), 0);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  const std::string log = readFile((dir_ / "forced.log").string());
  EXPECT_NE(log.find("OVER BUDGET"), std::string::npos) << log;
  EXPECT_NE(log.find("the loop fell behind"), std::string::npos) << log;
}

TEST_F(DaemonAttack, TheBudgetCheckMeasuresTheWholeTickWithTheCageMoving) {
  // modes 400 at 1 kHz with 20001 envelope points and the shape published
  // every tick passed a check that measured the model step at rest (47 %),
  // then missed most ticks once the cage moved.  The whole tick -- step,
  // envelope, shape publication -- with the cage moving does not fit: exit 2,
  // naming the keys.
  start(8003, "budget_whole_tick");
  const auto cfg = writeConfig("whole.toml", "[model]\nmodes = 400\n[service]\nrate = 1000\nenvelope_points = 20001\n"
                                             "shape_rate = 1000\n");
  EXPECT_EQ(runProcess({HOIST_TWIND, "--config", cfg, "--lcm-url", url_}, (dir_ / "whole.log").string(), 60s), 2);
  const std::string text = readFile((dir_ / "whole.log").string());
  EXPECT_NE(text.find("cannot run in real time"), std::string::npos) << text;
  EXPECT_NE(text.find("cage moving"), std::string::npos) << text;
  for (const char* key : {"envelope_points = 20001", "shape_rate = 1000", "modes = 400", "--force"})
    EXPECT_NE(text.find(key), std::string::npos) << key << " not named in: " << text;
}

TEST_F(DaemonAttack, EffectiveCommandsAreAuditedWithTheirUser) {
  // Commands: five invalid commands, then a '*' shelve from "mallory":
  // the shelve is in HOIST_ALARM (user field) and the log, whatever the
  // junk limiter did.  A shelve beyond max_shelve states the clamp (15.4).
  start(7856, "audit");
  auto d = startDaemon({"--config", writeConfig("one.toml", "[service]\nlog_rate_limit = 1\n")}, "twind.log");
  hoist::alarm_ack_t bad{};
  bad.kind = "NOPE";
  bad.user = "junk";
  for (int i = 0; i < 5; ++i) listener_->lcm().publish("HOIST_ALARM_ACK", &bad);
  listener_->pump(50ms);
  hoist::alarm_ack_t ack{};
  ack.kind = "*";
  ack.action = hoist::alarm_ack_t::ACTION_SHELVE;
  ack.shelve_duration = 99999.0;
  ack.user = "mallory";
  listener_->lcm().publish("HOIST_ALARM_ACK", &ack);
  // The same command again: not effective, no events.
  for (int i = 0; i < 100; ++i) listener_->lcm().publish("HOIST_ALARM_ACK", &ack);
  listener_->pump(1000ms);
  int shelves = 0;
  for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM"))
    if (a.event_type == hoist::alarm_t::EVENT_SHELVE) {
      ++shelves;
      EXPECT_EQ(a.user, "mallory");
      EXPECT_NE(a.message.find("clamped to max_shelve = 3600 s"), std::string::npos) << a.message;
      EXPECT_NEAR(a.shelved_for, 3600.0, 1.0);
    }
  EXPECT_EQ(shelves, hoist::service::AlarmEngine::kSlots) << "one event per alarm, the repeats silent";
  stopDaemonCleanly(*d, (dir_ / "twind.log").string());
  const std::string log = readFile((dir_ / "twind.log").string());
  EXPECT_NE(log.find("AUDIT operator 'mallory': shelve */* for 3600 s (requested 99999 s, clamped to max_shelve)"),
            std::string::npos)
      << log;
}

TEST_F(DaemonAttack, AlarmAndCageShareOneTimeOrigin) {
  // Before the fix: HOIST_ALARM.t counted from daemon start, HOIST_CAGE.t from
  // the first input.  Idle 2 s, 1 s of input, silence: INPUT_STALE comes
  // within a stale timeout of the last cage state, on the same clock.
  start(7857, "origin");
  auto d = startDaemon({}, "twind.log");
  listener_->pump(2000ms);
  listener_->clear();
  feed("HOIST_WINDER", 100);
  listener_->pump(1500ms);
  const auto cages = listener_->decoded<hoist::cage_state_t>("HOIST_CAGE");
  ASSERT_FALSE(cages.empty());
  double stale_t = -1.0;
  for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM"))
    if (a.kind == "INPUT_STALE" && a.event_type == hoist::alarm_t::EVENT_RAISE) stale_t = a.t;
  ASSERT_GE(stale_t, 0.0);
  double last_fresh = 0.0;
  for (const auto& c : cages)
    if (!c.degraded) last_fresh = c.t;
  EXPECT_NEAR(stale_t, last_fresh, 0.6) << "alarm t " << stale_t << " vs cage t " << last_fresh;
  EXPECT_LT(cages.front().t, 0.5);
  stopDaemonCleanly(*d, (dir_ / "twind.log").string());
}

TEST_F(DaemonAttack, OutputsGoToLcmUrlOut) {
  // [service] lcm_url_out -- the daemon publishes there and does
  // not receive its own outputs on its input socket.
  start(7858, "urlout");
  const std::string out_url = urlFor(7859);
  Listener out(out_url);
  ASSERT_TRUE(out.good());
  out.subscribe("HOIST_.*");
  const auto cfg = writeConfig("out.toml", "[service]\nlcm_url_out = \"" + out_url + "\"\n");
  auto p = std::make_unique<Process>(std::vector<std::string>{HOIST_TWIND, "--config", cfg, "--lcm-url", url_},
                                     (dir_ / "twind.log").string());
  ASSERT_TRUE(out.waitFor([&] { return out.count("HOIST_HEALTH") > 0; }, 10s)) << readFile((dir_ / "twind.log").string());
  out.pump(200ms);
  feed("HOIST_WINDER", 50);
  out.pump(300ms);
  EXPECT_GT(out.count("HOIST_CAGE"), 20u);
  EXPECT_EQ(listener_->count("HOIST_CAGE"), 0u);
  EXPECT_EQ(listener_->count("HOIST_HEALTH"), 0u);
  stopDaemonCleanly(*p, (dir_ / "twind.log").string());
  const auto bad = writeConfig("bad.toml", "[service]\nlcm_url_out = \"nonsense\"\n");
  EXPECT_EQ(runProcess({HOIST_TWIND, "--config", bad, "--lcm-url", url_}, (dir_ / "bad.log").string(), 30s), 2);
  EXPECT_NE(readFile((dir_ / "bad.log").string()).find("service.lcm_url_out"), std::string::npos);
}

TEST_F(DaemonAttack, SecondPublisherIsDetectedOnASeparateOutputUrl) {
  // Two daemons with [service] lcm_url_out on another group: the input socket
  // never sees the outputs, so the daemon watches its own HOIST_HEALTH on the
  // output URL with a receive-only socket.  One daemon alone raises nothing
  // (it sees only its own id there); a second one with the same prefix and
  // the same output URL is detected by both.
  start(7862, "duplicate_out");
  const std::string out_url = urlFor(7863);
  std::string why;
  ASSERT_TRUE(loopbackMulticastWorks(out_url, why)) << why;
  Listener out(out_url);
  ASSERT_TRUE(out.good());
  out.subscribe("HOIST_HEALTH");
  out.subscribe("HOIST_ALARM");
  const auto cfg = writeConfig("out.toml", "[service]\nlcm_url_out = \"" + out_url + "\"\n");
  auto startOne = [&](const std::string& log) {
    auto p = std::make_unique<Process>(std::vector<std::string>{HOIST_TWIND, "--config", cfg, "--lcm-url", url_,
                                                                "--log-level", "info"},
                                       (dir_ / log).string());
    const std::size_t before = out.count("HOIST_HEALTH");
    EXPECT_TRUE(out.waitFor([&] { return out.count("HOIST_HEALTH") > before; }, 10s)) << readFile((dir_ / log).string());
    return p;
  };
  auto duplicateRaised = [&] {
    for (const auto& a : out.decoded<hoist::alarm_t>("HOIST_ALARM"))
      if (a.kind == "DUPLICATE_PUBLISHER" && a.event_type == hoist::alarm_t::EVENT_RAISE) return true;
    return false;
  };
  auto d1 = startOne("twind1.log");
  out.pump(2500ms);  // two health periods of its own messages on the output group
  EXPECT_FALSE(duplicateRaised()) << "a daemon alone took its own outputs for a second publisher";
  auto d2 = startOne("twind2.log");
  EXPECT_TRUE(out.waitFor(duplicateRaised, 5s)) << "no DUPLICATE_PUBLISHER with two daemons on one output URL";
  out.pump(1500ms);
  std::set<std::int64_t> ids;
  for (const auto& h : out.decoded<hoist::health_t>("HOIST_HEALTH")) ids.insert(h.instance_id);
  EXPECT_EQ(ids.size(), 2u);
  EXPECT_EQ(listener_->count("HOIST_HEALTH"), 0u) << "outputs on the input URL";
  stopDaemonCleanly(*d1, (dir_ / "twind1.log").string());
  stopDaemonCleanly(*d2, (dir_ / "twind2.log").string());
  // Both noticed the other.
  EXPECT_NE(readFile((dir_ / "twind1.log").string()).find("another publisher"), std::string::npos);
  EXPECT_NE(readFile((dir_ / "twind2.log").string()).find("another publisher"), std::string::npos);
}

TEST(DaemonFiles, RunReportWriteFailureIsExitOneWithPathAndErrno) {
  // Every file a program writes is checked; hoist-twind's run
  // report (--report) into a directory that does not exist: the option, the
  // path and the errno text (memq://: no network needed).  The path is
  // checked at start-up: exit 2 (bad input), before the run.
  const auto dir = testDir("report_fail");
  const std::string report = (dir / "no" / "such" / "r.json").string();
  const std::string log = (dir / "twind.log").string();
  EXPECT_EQ(runProcess({HOIST_TWIND, "--lcm-url", "memq://", "--duration", "0.5", "--report", report}, log, 30s), 2)
      << readFile(log);
  const std::string text = readFile(log);
  EXPECT_NE(text.find("--report " + report + ": directory " + (dir / "no" / "such").string() +
                      ": No such file or directory"),
            std::string::npos)
      << text;
  // And a good path is written completely.
  const std::string good = (dir / "r.json").string();
  EXPECT_EQ(runProcess({HOIST_TWIND, "--lcm-url", "memq://", "--duration", "0.5", "--report", good}, log, 30s), 0)
      << readFile(log);
  const std::string json = readFile(good);
  EXPECT_NE(json.find("\"tool\": \"hoist-twind\""), std::string::npos) << json;
  EXPECT_EQ(json.back(), '\n');
}
