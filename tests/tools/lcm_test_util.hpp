// Helpers for the LCM integration tests: child processes with timeouts, an
// LCM listener that records raw messages, and the loopback-multicast check.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace hoist::test {

using namespace std::chrono_literals;

/// A child process; killed (SIGKILL) if still running when destroyed.
class Process {
 public:
  Process(std::vector<std::string> argv, const std::string& log_path) : argv_(std::move(argv)) {
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
    posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    std::vector<char*> args;
    for (auto& a : argv_) args.push_back(a.data());
    args.push_back(nullptr);
    if (posix_spawn(&pid_, args[0], &fa, nullptr, args.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&fa);
  }
  ~Process() {
    if (running()) {
      ::kill(pid_, SIGKILL);
      int st;
      ::waitpid(pid_, &st, 0);
    }
  }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  bool started() const { return pid_ > 0; }
  bool running() {
    if (pid_ <= 0 || done_) return false;
    int st;
    const pid_t r = ::waitpid(pid_, &st, WNOHANG);
    if (r == pid_) {
      done_ = true;
      status_ = st;
      return false;
    }
    return true;
  }
  void signal(int sig) {
    if (running()) ::kill(pid_, sig);
  }
  /// Exit status (0..255, 128+signal if killed), or -1 on timeout.
  int wait(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (running()) {
      if (std::chrono::steady_clock::now() > end) return -1;
      std::this_thread::sleep_for(5ms);
    }
    if (pid_ <= 0) return -1;
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : 128 + WTERMSIG(status_);
  }

 private:
  std::vector<std::string> argv_;
  pid_t pid_ = -1;
  bool done_ = false;
  int status_ = 0;
};

/// Run to completion (with timeout); returns the exit status or -1.
inline int runProcess(std::vector<std::string> argv, const std::string& log_path,
                      std::chrono::milliseconds timeout) {
  Process p(std::move(argv), log_path);
  if (!p.started()) return -1;
  return p.wait(timeout);
}

inline std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

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
  lcm::LCM& lcm() { return lcm_; }

  void subscribe(const std::string& regex) { lcm_.subscribe(regex, &Listener::onMessage, this); }
  void logTo(const std::string& path) { log_ = std::make_unique<lcm::LogFile>(path, "w"); }
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
  void onMessage(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    Message m;
    m.channel = channel;
    const auto* p = static_cast<const std::uint8_t*>(rb->data);
    m.data.assign(p, p + rb->data_size);
    m.recv_utime = rb->recv_utime;
    if (log_) {
      lcm::LogEvent ev;
      ev.timestamp = rb->recv_utime;
      ev.channel = channel;
      ev.datalen = static_cast<int32_t>(rb->data_size);
      ev.data = rb->data;
      log_->writeEvent(&ev);
    }
    by_channel_[channel].push_back(std::move(m));
  }

  lcm::LCM lcm_;
  std::unique_ptr<lcm::LogFile> log_;
  std::map<std::string, std::vector<Message>> by_channel_;
};

inline const char* kMulticastHelp =
    "UDP multicast on the loopback interface is not available, so LCM messages cannot be "
    "exchanged on this machine. Enable it (as root): `ip link set lo multicast on; ip route add "
    "224.0.0.0/4 dev lo` (scripts/setup.sh does this), then re-run the tests.";

/// True if a message published on `url` comes back within one second.
inline bool loopbackMulticastWorks(const std::string& url, std::string& why) {
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    why = "cannot open LCM at " + url;
    return false;
  }
  bool got = false;
  struct H {
    bool* got;
    void on(const lcm::ReceiveBuffer*, const std::string&) { *got = true; }
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

/// A fresh directory for one test's files.
inline std::filesystem::path testDir(const std::string& name) {
  const auto dir = std::filesystem::path(HOIST_TEST_WORK_DIR) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
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
  auto p = std::make_unique<Process>(argv, log);
  EXPECT_TRUE(p->started());
  const std::size_t before = listener.count(health_channel);
  EXPECT_TRUE(listener.waitFor([&] { return listener.count(health_channel) > before; }, 10s))
      << "hoist-twind did not come up; its log:\n" << readFile(log);
  listener.pump(200ms);
  return p;
}

/// SIGTERM, then a clean exit (status 0) within 10 s.
inline void stopDaemonCleanly(Process& p, const std::string& log) {
  p.signal(SIGTERM);
  EXPECT_EQ(p.wait(10s), 0) << readFile(log);
}

}  // namespace hoist::test
