// The systemd watchdog of hoist-twind: see watchdog.hpp.
#include "watchdog.hpp"

#include <algorithm>
#include <systemd/sd-daemon.h>

namespace hoist::service::inline app {

void Watchdog::start() {
  // WATCHDOG_USEC (set by systemd from WatchdogSec=) enables it; ping at half
  // the timeout, as sd_watchdog_enabled(3) recommends.
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) <= 0 || usec == 0) return;
  const auto interval = std::chrono::microseconds(std::max<std::uint64_t>(usec / 2, 1000));
  out_->info("systemd watchdog: {} ms timeout; pinging every {} ms while the loop makes progress", usec / 1000,
             interval.count() / 1000);
  quit_ = false;
  thread_ = std::thread([this, interval] { main(interval); });
}

void Watchdog::stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lk(mu_);
    quit_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void Watchdog::main(std::chrono::microseconds interval) {
  std::uint64_t last = progress_.load(std::memory_order_relaxed);
  bool stalled = false;
  std::unique_lock lk(mu_);
  while (!cv_.wait_for(lk, interval, [this] { return quit_; })) {
    const std::uint64_t now = progress_.load(std::memory_order_relaxed);
    if (now != last) {
      sd_notify(0, "WATCHDOG=1");
      if (stalled) out_->warn("systemd watchdog: the loop makes progress again; pings resumed");
      stalled = false;
      last = now;
    } else if (!stalled) {
      stalled = true;
      out_->error("systemd watchdog: no tick for {} ms; withholding the ping (systemd restarts the service "
                  "if this lasts WatchdogSec)",
                  interval.count() / 1000);
    }
  }
}

}  // namespace hoist::service::app
