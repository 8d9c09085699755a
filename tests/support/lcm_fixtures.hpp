// tests/support/lcm_fixtures.hpp -- LCM fixtures for the tests that talk to
// the programs over real UDP multicast on loopback: a Listener that records
// raw messages (optionally into an LCM log), the loopback-multicast check,
// the tests' URLs, and starting and stopping hoist-twind.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "process.hpp"

namespace hoist::test {

/// Records every message on the subscribed channels (raw bytes), optionally
/// into an LCM log file.
class Listener {
 public:
  struct Message {
    std::string channel;
    std::vector<std::uint8_t> data;
    std::int64_t recv_utime = 0;
  };

  explicit Listener(const std::string& url) : lcm_(url) {}
  bool good() { return lcm_.good(); }
  ::lcm::LCM& lcm() { return lcm_; }

  /// Every message is kept: LCM's per-subscription queue (30 messages by
  /// default, dropped beyond) is made unbounded -- at 10x real time the
  /// daemon publishes 2000 messages/s, and a test thread descheduled for
  /// 15 ms on a busy machine lost some.
  void subscribe(const std::string& regex) {
    ::lcm::Subscription* s = lcm_.subscribe(regex, &Listener::onMessage, this);
    if (s) s->setQueueCapacity(0);
  }
  void logTo(const std::string& path) { log_ = std::make_unique<::lcm::LogFile>(path, "w"); }
  void closeLog() { log_.reset(); }

  /// Handle messages until pred() is true or the timeout passes.
  bool waitFor(const std::function<bool()>& pred, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (!pred()) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
      if (left.count() <= 0) return false;
      lcm_.handleTimeout(static_cast<int>(std::min<long>(left.count(), 50)));
    }
    return true;
  }
  void pump(std::chrono::milliseconds d) {
    waitFor([] { return false; }, d);
  }

  std::size_t count(const std::string& channel) const {
    auto it = by_channel_.find(channel);
    return it == by_channel_.end() ? 0 : it->second.size();
  }
  const std::vector<Message>& messages(const std::string& channel) const {
    static const std::vector<Message> none;
    auto it = by_channel_.find(channel);
    return it == by_channel_.end() ? none : it->second;
  }
  template <class Msg>
  std::vector<Msg> decoded(const std::string& channel) const {
    std::vector<Msg> out;
    for (const auto& m : messages(channel)) {
      Msg x;
      if (x.decode(m.data.data(), 0, static_cast<int>(m.data.size())) == static_cast<int>(m.data.size()))
        out.push_back(std::move(x));
    }
    return out;
  }
  void clear() { by_channel_.clear(); }

 private:
  void onMessage(const ::lcm::ReceiveBuffer* rb, const std::string& channel) {
    Message m;
    m.channel = channel;
    const auto* p = static_cast<const std::uint8_t*>(rb->data);
    m.data.assign(p, p + rb->data_size);
    m.recv_utime = rb->recv_utime;
    if (log_) {
      ::lcm::LogEvent ev;
      ev.timestamp = rb->recv_utime;
      ev.channel = channel;
      ev.datalen = static_cast<int32_t>(rb->data_size);
      ev.data = rb->data;
      log_->writeEvent(&ev);
    }
    by_channel_[channel].push_back(std::move(m));
  }

  ::lcm::LCM lcm_;
  std::unique_ptr<::lcm::LogFile> log_;
  std::map<std::string, std::vector<Message>> by_channel_;
};

inline const char* kMulticastHelp =
    "UDP multicast on the loopback interface is not available, so LCM messages cannot be "
    "exchanged on this machine. Enable it (as root): `ip link set lo multicast on; ip route add "
    "224.0.0.0/4 dev lo` (scripts/setup.sh does this), then re-run the tests.";

/// True if a message published on `url` comes back within one second.
inline bool loopbackMulticastWorks(const std::string& url, std::string& why) {
  ::lcm::LCM lcm(url);
  if (!lcm.good()) {
    why = "cannot open LCM at " + url;
    return false;
  }
  bool got = false;
  struct H {
    bool* got;
    void on(const ::lcm::ReceiveBuffer*, const std::string&) { *got = true; }
  } h{&got};
  lcm.subscribe("HOIST_TEST_PROBE", &H::on, &h);
  const char probe[4] = {'p', 'i', 'n', 'g'};
  const auto end = std::chrono::steady_clock::now() + 1s;
  while (!got && std::chrono::steady_clock::now() < end) {
    if (lcm.publish("HOIST_TEST_PROBE", probe, sizeof probe) != 0) {
      why = "LCM publish failed on " + url;
      return false;
    }
    lcm.handleTimeout(100);
  }
  if (!got) why = "a probe message published on " + url + " did not come back within 1 s";
  return got;
}

/// The tests' LCM URL on `port`: UDP multicast on loopback, host-local.
inline std::string urlFor(int port) { return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0"; }

/// Starts the daemon command line `argv` (output to `log`) and waits up to
/// 10 s for its next message on `health_channel` (hoist-twind publishes one
/// at once when it is up).  LCM 1.3.1's UDP receiver may still drop the first
/// datagrams right after it comes up (seen as a missing first few inputs), so
/// the listener then keeps receiving for 200 ms to let it settle.
inline std::unique_ptr<Process> startDaemonAndWait(Listener& listener, const std::vector<std::string>& argv,
                                                   const std::string& log,
                                                   const std::string& health_channel = "HOIST_HEALTH") {
  // Up = a health report of this process: one published after it started.
  // A report of a daemon stopped just before may still be on its way to the
  // listener (a loaded machine): counting reports would take that one, and
  // what the test publishes next would go out before this daemon listens.
  // health_t's first field is utime (after LCM's 8-byte fingerprint).
  const auto started_utime = std::chrono::duration_cast<std::chrono::microseconds>(
                                 std::chrono::system_clock::now().time_since_epoch()).count();
  auto p = std::make_unique<Process>(argv, log);
  EXPECT_TRUE(p->started());
  const auto reportedSinceStart = [&] {
    for (const Listener::Message& m : listener.messages(health_channel)) {
      if (m.data.size() < 16) continue;
      std::uint64_t u = 0;
      for (std::size_t i = 8; i < 16; ++i) u = (u << 8) | m.data[i];
      if (static_cast<std::int64_t>(u) >= started_utime) return true;
    }
    return false;
  };
  EXPECT_TRUE(listener.waitFor(reportedSinceStart, 10s)) << "hoist-twind did not come up; its log:\n" << readFile(log);
  listener.pump(200ms);
  return p;
}

/// SIGTERM, then a clean exit (status 0) within 10 s.
inline void stopDaemonCleanly(Process& p, const std::string& log) {
  p.signal(SIGTERM);
  EXPECT_EQ(p.wait(10s), 0) << readFile(log);
}

#ifdef HOIST_TEST_WORK_DIR
/// Base fixture of the process-level tests: the LCM URL of one port, a fresh
/// directory for the test's files, and a Listener on that URL.
class LcmProcessTest : public ::testing::Test {
 protected:
  /// Fails the test (with instructions) when loopback multicast is off.
  void start(int port, const std::string& name, const std::vector<std::string>& channels = {}) {
    url_ = urlFor(port);
    dir_ = testDir(name);
    std::string why;
    if (!loopbackMulticastWorks(url_, why)) FAIL() << why << ".\n" << kMulticastHelp;
    // The listener's socket buffer as the daemon's (2 MiB): a burst while
    // the test thread waits for a CPU stays in the kernel.
    listener_ = std::make_unique<Listener>(url_ + "&recv_buf_size=2097152");
    ASSERT_TRUE(listener_->good()) << kMulticastHelp;
    for (const auto& c : channels) listener_->subscribe(c);
  }

  std::string url_;
  std::filesystem::path dir_;
  std::unique_ptr<Listener> listener_;
};
#endif

}  // namespace hoist::test
