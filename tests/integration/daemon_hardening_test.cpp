// hoist-twind under bad input and faults, through real LCM (UDP multicast on
// loopback, ttl=0, one port per test in 7724..7735):
//   * a crafted garbage LCM log played into the daemon with lcm-logplayer:
//     every class counted under its reason, the daemon keeps publishing;
//   * raw garbage published with ::lcm::LCM::publish and a 10 kHz flood;
//   * the input stops and resumes: INPUT_STALE raised within ~3 input
//     periods and cleared when the input returns;
//   * the daemon SIGKILLed mid-trip and restarted: re-initialized from the
//     next encoder length, and says so;
//   * an injected model fault (non-finite state): MODEL_FAULT, recovery, no
//     NaN ever published;
//   * LCM publish failures: counted, logged rate-limited, not fatal.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/winder_t.hpp"
#include "lcm_fixtures.hpp"
#include "lcm_messages.hpp"

using namespace hoist::test;
namespace fs = std::filesystem;

namespace {

std::int64_t nowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::map<std::string, std::int64_t> reasons(const hoist::health_t& h) {
  std::map<std::string, std::int64_t> m;
  for (int i = 0; i < h.n_reasons; ++i) m[h.reject_reason[i]] = h.rejected[i];
  return m;
}

bool finiteCage(const hoist::cage_state_t& c) {
  bool ok = std::isfinite(c.t) && std::isfinite(c.l) && std::isfinite(c.v) && std::isfinite(c.a) &&
            std::isfinite(c.x_c) && std::isfinite(c.y_c) && std::isfinite(c.theta) &&
            std::isfinite(c.min_clearance) && std::isfinite(c.clearance_pos_y) &&
            std::isfinite(c.clearance_neg_y) && std::isfinite(c.clearance_guide);
  for (double v : c.lambdas) ok = ok && std::isfinite(v);
  return ok;
}

class DaemonHardening : public LcmProcessTest {
 protected:
  void start(int port, const std::string& name) {
    LcmProcessTest::start(port, name, {"HOIST_HEALTH", "HOIST_CAGE", "HOIST_ALARM"});
  }
  /// A config whose staleness does not depend on the input period (the
  /// rejection-count tests send bursts and must not see a stream resync).
  std::string steadyConfig() {
    const auto p = (dir_ / "steady.toml").string();
    std::ofstream(p) << "[service]\nstale_periods = 0\nstale_timeout = 2.0\n";
    return p;
  }
  std::unique_ptr<Process> startDaemon(std::vector<std::string> extra, const std::string& log_name) {
    std::vector<std::string> argv{HOIST_TWIND, "--lcm-url", url_, "--log-level", "info"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return startDaemonAndWait(*listener_, argv, (dir_ / log_name).string());
  }
  void stopDaemon(Process& p, const std::string& log_name) { stopDaemonCleanly(p, (dir_ / log_name).string()); }
  /// The latest health report satisfying pred (waits up to `timeout`).
  hoist::health_t waitHealth(const std::function<bool(const hoist::health_t&)>& pred, std::chrono::milliseconds timeout) {
    hoist::health_t h{};
    listener_->waitFor(
        [&] {
          auto hs = listener_->decoded<hoist::health_t>("HOIST_HEALTH");
          if (hs.empty()) return false;
          h = hs.back();
          return pred(h);
        },
        timeout);
    return h;
  }
  void expectNoNaNPublished() {
    const auto cages = listener_->decoded<hoist::cage_state_t>("HOIST_CAGE");
    for (const auto& c : cages) ASSERT_TRUE(finiteCage(c)) << "non-finite HOIST_CAGE at t = " << c.t;
    for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM"))
      ASSERT_TRUE(std::isfinite(a.value) && std::isfinite(a.threshold) && std::isfinite(a.t));
  }

};

TEST_F(DaemonHardening, GarbageLcmLogPlayedWithLogplayer) {
  start(7724, "logplayer");
  // Craft the log: 30 valid inputs (10 ms apart), a burst of every bad class,
  // 30 valid inputs.
  const auto log_path = (dir_ / "garbage.lcmlog").string();
  int n_decode = 0;
  {
    ::lcm::LogFile log(log_path, "w");
    ASSERT_TRUE(log.good());
    std::int64_t ts = 1'000'000, seq = 0, utime = 1'700'000'000'000'000;
    auto put = [&](const std::string& channel, const std::vector<std::uint8_t>& data) {
      ::lcm::LogEvent ev;
      ev.timestamp = ts;
      ev.channel = channel;
      ev.datalen = static_cast<int32_t>(data.size());
      ev.data = const_cast<std::uint8_t*>(data.data());
      log.writeEvent(&ev);
    };
    auto valid = [&](int n) {
      for (int i = 0; i < n; ++i) {
        put("HOIST_WINDER", encode(winder(seq++, utime, 0.0, 120.0)));
        utime += 10000;
        ts += 10000;
      }
    };
    valid(30);
    ts += 1000;
    std::mt19937 rng(5);
    std::vector<std::uint8_t> junk(777);
    for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
    put("HOIST_WINDER", junk), ++n_decode;                                   // garbage
    auto trunc = encode(winder(seq, utime, 0.0, 120.0));
    trunc.resize(30);
    put("HOIST_WINDER", trunc), ++n_decode;                                  // truncated
    hoist::alarm_t other{};
    other.kind = "CAGE_POS_Y";
    put("HOIST_WINDER", encode(other)), ++n_decode;                          // other message type
    auto big = encode(winder(seq, utime, 0.0, 120.0));
    big.resize(50000, 0xEE);
    put("HOIST_WINDER", big), ++n_decode;                                    // oversized
    auto bad = [&](auto mutate) {
      auto m = winder(seq, utime, 0.0, 120.0);
      mutate(m);
      put("HOIST_WINDER", encode(m));
    };
    bad([](auto& m) { m.v = NAN; });
    bad([](auto& m) { m.a = INFINITY; });
    bad([](auto& m) { m.length = -INFINITY; });
    bad([](auto& m) { m.length = 1000.0; });                                 // rope out of the shaft
    bad([&](auto& m) { m.utime = utime - 50000; });                          // time backwards
    bad([&](auto& m) { m.seq = seq - 1; });                                  // duplicate
    bad([&](auto& m) { m.seq = seq - 1; });                                  // duplicate again
    bad([&](auto& m) { m.v = 25.0; });                                       // over max_speed
    seq += 3;                                                                // skipped sequence numbers
    ts += 10000;
    valid(30);
  }
  auto d = startDaemon({"--config", steadyConfig(), "--clock", "wall"}, "twind.log");
  Process player({"/usr/bin/lcm-logplayer", "--lcm-url=" + url_, log_path}, (dir_ / "player.log").string());
  ASSERT_TRUE(player.started());
  listener_->waitFor([&] { return !player.running(); }, 20s);
  EXPECT_EQ(player.wait(1s), 0) << readFile((dir_ / "player.log").string());
  const std::size_t cages = listener_->count("HOIST_CAGE");
  const auto h = waitHealth([](const hoist::health_t& x) { return x.accepted >= 60 && x.rejected_total >= 12; }, 5s);
  auto r = reasons(h);
  EXPECT_EQ(h.accepted, 60);
  EXPECT_EQ(r["decode"], n_decode);
  EXPECT_EQ(r["non_finite"], 3);
  EXPECT_EQ(r["length_range"], 1);
  EXPECT_EQ(r["time_backwards"], 1);
  EXPECT_EQ(r["duplicate_seq"], 2);
  EXPECT_EQ(r["v_limit"], 1);
  EXPECT_EQ(h.rejected_total, n_decode + 8);
  EXPECT_EQ(h.seq_gaps, 3);
  // Still publishing afterwards, never a NaN.
  EXPECT_TRUE(listener_->waitFor([&] { return listener_->count("HOIST_CAGE") > cages + 20; }, 5s));
  expectNoNaNPublished();
  EXPECT_TRUE(d->running());
  stopDaemon(*d, "twind.log");
  const std::string log = readFile((dir_ / "twind.log").string());
  EXPECT_NE(log.find("rejected winder input (decode)"), std::string::npos) << log;
  EXPECT_NE(log.find("rejected winder input (non_finite)"), std::string::npos) << log;
}

TEST_F(DaemonHardening, RawGarbageAndA10kHzFlood) {
  start(7725, "flood");
  auto d = startDaemon({"--config", steadyConfig(), "--clock", "wall", "--rate", "100"}, "twind.log");
  ::lcm::LCM& lcm = listener_->lcm();
  std::mt19937 rng(99);
  std::vector<std::uint8_t> junk(60000);
  for (int i = 0; i < 100; ++i) {
    const std::size_t n = 1 + rng() % junk.size();
    for (std::size_t k = 0; k < n; ++k) junk[k] = static_cast<std::uint8_t>(rng());
    ASSERT_EQ(lcm.publish("HOIST_WINDER", junk.data(), static_cast<unsigned>(n)), 0);
    if (i % 10 == 9) listener_->pump(5ms);
  }
  listener_->pump(300ms);
  // 10 kHz for 1 s: paced in bursts of 10 per millisecond.
  const std::int64_t u0 = nowUs();
  const auto t0 = std::chrono::steady_clock::now();
  const int kFlood = 10000;
  for (int k = 0; k < kFlood; ++k) {
    const auto m = winder(k, u0 + 100 * k, 0.0, 150.0);
    const auto b = encode(m);
    lcm.publish("HOIST_WINDER", b.data(), static_cast<unsigned>(b.size()));
    if (k % 10 == 9) {
      // Receive while flooding (our own socket buffer is finite too).
      const auto due = t0 + std::chrono::microseconds(100 * (k + 1));
      while (std::chrono::steady_clock::now() < due) lcm.handleTimeout(0);
    }
  }
  const auto h = waitHealth([&](const hoist::health_t& x) { return x.accepted + x.seq_gaps >= kFlood - 1; }, 5s);
  auto r = reasons(h);
  // Garbage of up to 60 kB travels as many UDP fragments; on a loaded machine
  // the kernel may drop a few whole messages before the daemon sees them.
  // What arrives must be rejected as undecodable, and nothing else.
  EXPECT_LE(r["decode"], 100);
  EXPECT_GE(r["decode"], 90);
  EXPECT_EQ(h.rejected_total, r["decode"]) << "only the garbage may be rejected";
  // Every flood message accepted or (dropped by the kernel) counted as a gap.
  EXPECT_EQ(h.accepted + h.seq_gaps, kFlood);
  EXPECT_GT(h.accepted, kFlood / 2);
  // The daemon kept its schedule and its outputs.
  const std::size_t cages = listener_->count("HOIST_CAGE");
  EXPECT_TRUE(listener_->waitFor([&] { return listener_->count("HOIST_CAGE") > cages + 50; }, 5s));
  const auto hs = listener_->decoded<hoist::health_t>("HOIST_HEALTH");
  for (std::size_t i = 1; i < hs.size(); ++i) EXPECT_LT(hs[i].utime - hs[i - 1].utime, 2'500'000) << i;
  EXPECT_NEAR(listener_->decoded<hoist::cage_state_t>("HOIST_CAGE").back().l, 150.0, 1e-6);
  expectNoNaNPublished();
  stopDaemon(*d, "twind.log");
  // Rate-limited logging: at most log_rate_limit (5) decode lines per second.
  const std::string log = readFile((dir_ / "twind.log").string());
  int lines = 0;
  for (std::size_t p = 0; (p = log.find("rejected winder input (decode)", p)) != std::string::npos; ++p) ++lines;
  EXPECT_GE(lines, 1);
  EXPECT_LE(lines, 20) << log;
}

TEST_F(DaemonHardening, InputStopsAndResumes) {
  start(7726, "stale");
  auto d = startDaemon({"--clock", "wall", "--rate", "1000"}, "twind.log");
  ::lcm::LCM& lcm = listener_->lcm();
  std::int64_t seq = 0;
  std::int64_t last_sent_us = 0;
  auto stream = [&](int n) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; ++i) {
      last_sent_us = nowUs();
      const auto b = encode(winder(seq++, last_sent_us, 0.0, 200.0));
      lcm.publish("HOIST_WINDER", b.data(), static_cast<unsigned>(b.size()));
      const auto due = t0 + std::chrono::milliseconds(10 * (i + 1));
      listener_->waitFor([&] { return std::chrono::steady_clock::now() >= due; }, 20ms);
    }
  };
  auto events = [&](int event) {
    std::vector<hoist::alarm_t> out;
    for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM"))
      if (a.kind == "INPUT_STALE" && a.event_type == event) out.push_back(a);
    return out;
  };
  stream(100);
  const std::size_t raises = events(hoist::alarm_t::EVENT_RAISE).size();
  // Stop: INPUT_STALE within 3 input periods (30 ms) of the last input, plus
  // transport and scheduling slack.
  ASSERT_TRUE(listener_->waitFor([&] { return events(hoist::alarm_t::EVENT_RAISE).size() > raises; }, 2s));
  const auto raise = events(hoist::alarm_t::EVENT_RAISE).back();
  const double latency = static_cast<double>(raise.utime - last_sent_us) * 1e-6;
  EXPECT_LE(latency, 0.030 + 0.040) << "INPUT_STALE came " << latency << " s after the last input";
  EXPECT_GE(latency, 0.015);
  // The message states the timeout in force: ~3 periods of 10 ms.
  EXPECT_NE(raise.message.find("for more than 0.0"), std::string::npos) << raise.message;
  // Resume: cleared, the twin follows again.
  const std::size_t clears = events(hoist::alarm_t::EVENT_CLEAR).size();
  stream(50);
  EXPECT_TRUE(listener_->waitFor([&] { return events(hoist::alarm_t::EVENT_CLEAR).size() > clears; }, 2s));
  const auto h = waitHealth([](const hoist::health_t& x) { return x.accepted >= 150; }, 3s);
  EXPECT_EQ(h.accepted, 150);
  EXPECT_EQ(h.rejected_total, 0);
  stopDaemon(*d, "twind.log");
}

TEST_F(DaemonHardening, KilledAndRestartedMidTrip) {
  start(7727, "restart");
  auto d = startDaemon({"--clock", "wall"}, "twind1.log");
  ::lcm::LCM& lcm = listener_->lcm();
  std::int64_t seq = 0;
  double l = 100.0;
  const double v = 2.0;
  auto stream = [&](int n) {
    for (int i = 0; i < n; ++i) {
      const auto b = encode(winder(seq++, nowUs(), v, l));
      lcm.publish("HOIST_WINDER", b.data(), static_cast<unsigned>(b.size()));
      l += v * 0.01;
      listener_->pump(10ms);
    }
  };
  stream(100);
  auto lastCage = [&] { return listener_->decoded<hoist::cage_state_t>("HOIST_CAGE").back(); };
  EXPECT_NEAR(lastCage().l, l, 0.2);
  d->signal(SIGKILL);
  EXPECT_EQ(d->wait(5s), 128 + SIGKILL);
  stream(50);  // the trip goes on while the twin is down
  listener_->clear();
  auto d2 = startDaemon({"--clock", "wall"}, "twind2.log");
  stream(100);
  const auto c = lastCage();
  EXPECT_NEAR(c.l, l, 0.2) << "the restarted twin must follow the encoder, not start at l0";
  EXPECT_FALSE(c.degraded);
  expectNoNaNPublished();
  stopDaemon(*d2, "twind2.log");
  const std::string log = readFile((dir_ / "twind2.log").string());
  EXPECT_NE(log.find("model re-initialized at l ="), std::string::npos) << log;
}

TEST_F(DaemonHardening, InjectedModelFaultRecoversWithoutNaN) {
  start(7728, "fault");
  auto d = startDaemon({"--clock", "wall", "--test-inject-fault-at", "1.5"}, "twind.log");
  ::lcm::LCM& lcm = listener_->lcm();
  std::int64_t seq = 0;
  for (int i = 0; i < 350; ++i) {
    const auto b = encode(winder(seq++, nowUs(), 0.0, 120.0));
    lcm.publish("HOIST_WINDER", b.data(), static_cast<unsigned>(b.size()));
    listener_->pump(10ms);
  }
  auto faultRaised = [&] {
    for (const auto& a : listener_->decoded<hoist::alarm_t>("HOIST_ALARM"))
      if (a.kind == "MODEL_FAULT" && a.event_type == hoist::alarm_t::EVENT_RAISE && a.level == hoist::alarm_t::LEVEL_CRITICAL)
        return true;
    return false;
  };
  EXPECT_TRUE(listener_->waitFor(faultRaised, 3s));
  const auto h = waitHealth([](const hoist::health_t& x) { return x.model_faults >= 1; }, 3s);
  EXPECT_EQ(h.model_faults, 1);
  EXPECT_EQ(h.nonfinite_blocked, 0);
  const auto cages = listener_->decoded<hoist::cage_state_t>("HOIST_CAGE");
  ASSERT_FALSE(cages.empty());
  // Outputs: following (not degraded), degraded after the fault for
  // fault_hold (1 s), following again (before the input stops at the end).
  int phase = 0;
  for (const auto& c : cages) {
    if (phase == 0 && !c.degraded) phase = 1;
    else if (phase == 1 && c.degraded) phase = 2;
    else if (phase == 2 && !c.degraded) {
      phase = 3;
      EXPECT_NEAR(c.l, 120.0, 1e-6);
    }
  }
  EXPECT_EQ(phase, 3) << "expected following -> degraded (fault) -> following";
  expectNoNaNPublished();
  stopDaemon(*d, "twind.log");
  EXPECT_NE(readFile((dir_ / "twind.log").string()).find("MODEL_FAULT"), std::string::npos);
}

TEST_F(DaemonHardening, PublishFailuresAreCountedAndNotFatal) {
  start(7729, "pubfail");
  auto d = startDaemon({"--clock", "wall", "--rate", "200", "--test-fail-publish-every", "3"}, "twind.log");
  // Cage output starts with the first input: stream 3 s at 100 Hz.
  for (int i = 0; i < 300; ++i) {
    const auto b = encode(winder(i, nowUs(), 0.0, 120.0));
    listener_->lcm().publish("HOIST_WINDER", b.data(), static_cast<unsigned>(b.size()));
    listener_->pump(10ms);
  }
  const auto h = waitHealth([](const hoist::health_t& x) { return x.publish_failures > 100; }, 3s);
  EXPECT_GT(h.publish_failures, 100);
  EXPECT_TRUE(d->running());
  EXPECT_GT(listener_->count("HOIST_CAGE"), 300u);  // two thirds still go out
  stopDaemon(*d, "twind.log");
  const std::string log = readFile((dir_ / "twind.log").string());
  int lines = 0;
  for (std::size_t p = 0; (p = log.find("LCM publish failed", p)) != std::string::npos; ++p) ++lines;
  EXPECT_GE(lines, 1);
  EXPECT_LE(lines, 5 * 6) << "rate-limited to 5 lines per second";
  EXPECT_NE(log.find("similar suppressed"), std::string::npos);
}

}  // namespace

namespace {

TEST_F(DaemonHardening, AlarmCommandFloodIsRateLimitedAndSanitized) {
  start(7730, "ackflood");
  auto d = startDaemon({"--clock", "wall"}, "twind.log");
  hoist::alarm_ack_t ack{};
  ack.kind = "CAGE_POS_Y";
  ack.level = 7;  // invalid
  ack.action = hoist::alarm_ack_t::ACTION_ACK;
  ack.user = "\x1b[31mevil\x1b[0m" + std::string(10000, 'x');
  for (int i = 0; i < 2000; ++i) {
    listener_->lcm().publish("HOIST_ALARM_ACK", &ack);
    if (i % 100 == 99) listener_->pump(10ms);
  }
  std::vector<std::uint8_t> junk(3000, 0xFF);
  for (int i = 0; i < 500; ++i) listener_->lcm().publish("HOIST_ALARM_ACK", junk.data(), static_cast<unsigned>(junk.size()));
  listener_->pump(500ms);
  EXPECT_TRUE(d->running());
  stopDaemon(*d, "twind.log");
  const std::string log = readFile((dir_ / "twind.log").string());
  int lines = 0;
  for (std::size_t p = 0; (p = log.find("ignored", p)) != std::string::npos; ++p) ++lines;
  EXPECT_GE(lines, 1);
  EXPECT_LE(lines, 30) << "alarm-command log lines must be rate-limited";
  EXPECT_EQ(log.find('\x1b'), std::string::npos) << "control characters from the network reached the log";
  EXPECT_LT(log.size(), 20000u);
}

}  // namespace
