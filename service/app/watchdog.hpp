// The systemd watchdog of hoist-twind (sd_notify WATCHDOG=1): a supervisor
// thread that pings systemd only while the loop makes progress.
//
// Who calls: Daemon (daemon.hpp) starts it in start(), while the stop
// signals are still blocked (so the thread never receives them), and stops it
// in finish() and its destructor.  The loop only bumps the progress counter
// it is given (one relaxed atomic add per tick: no lock, no allocation, no
// system call); the thread reads it every interval and withholds the ping
// when it did not move, so a hung loop lets systemd restart the service after
// WatchdogSec.
//
// Lifetimes: the progress counter and the logger must outlive the watchdog
// (Daemon owns all three and declares the counter first).  stop() joins the
// thread; the destructor calls it.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <spdlog/spdlog.h>
#include <thread>

namespace hoist::service::inline app {

class Watchdog {
 public:
  /// `progress`: the loop's tick counter; `log`: start/stall/resume lines.
  Watchdog(const std::atomic<std::uint64_t>& progress, std::shared_ptr<spdlog::logger> log)
      : progress_(progress), out_(std::move(log)) {}
  ~Watchdog() { stop(); }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  /// Starts the thread if systemd asked for a watchdog (WATCHDOG_USEC, set
  /// from WatchdogSec=); pings at half the timeout.  A no-op otherwise.
  void start();
  /// Stops and joins the thread (a no-op when it is not running).
  void stop();

 private:
  void main(std::chrono::microseconds interval);

  const std::atomic<std::uint64_t>& progress_;
  std::shared_ptr<spdlog::logger> out_;
  std::thread thread_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool quit_ = false;
};

}  // namespace hoist::service::app
