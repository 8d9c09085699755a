// KeeperWorker: the one thread that serves every shaft's PreloadKeeper
// (preload_keeper.hpp): it builds and keeps the preloads operators adopt,
// and releases the models the loop replaced, off the real-time loop.  It
// wakes every 100 ms (an adoption is a rare, human-paced event) at
// SCHED_OTHER nice 10, below the loop.  Also the state files' names.
//
// Lifetimes: the Daemon owns it after its shafts (declared later), so it is
// stopped (joined) before the keepers it serves are destroyed; stop() is
// idempotent and serves once more (a replaced model is released).
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <spdlog/logger.h>

namespace hoist::service::inline app {

class ShaftTwin;

/// A shaft's state file in the state directory: `base` ("accel_offset",
/// "preload"), or "<base>.<label>" with several shafts (the label's
/// characters other than letters, digits, '-' and '_' as '_').
std::string stateFileName(const std::string& base, const std::string& label);

class KeeperWorker {
 public:
  /// Gives every shaft its PreloadKeeper (ShaftTwin::keepPreload), its state
  /// file under `state_dir` ("" = not kept across restarts).
  KeeperWorker(const std::vector<ShaftTwin*>& shafts, const std::string& state_dir,
               std::shared_ptr<spdlog::logger> log);
  ~KeeperWorker() { stop(); }
  KeeperWorker(const KeeperWorker&) = delete;
  KeeperWorker& operator=(const KeeperWorker&) = delete;

  void start();
  void stop();
  static constexpr int kNice = 10;

 private:
  void main();
  std::vector<ShaftTwin*> shafts_;
  std::atomic<bool> quit_{false};
  std::thread thread_;
};

}  // namespace hoist::service::app
