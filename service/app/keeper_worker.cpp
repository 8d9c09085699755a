// The thread that serves the shafts' preload keepers: see keeper_worker.hpp.
#include "keeper_worker.hpp"

#include <cctype>
#include <chrono>

#include "hoist/rt/realtime.hpp"
#include "shaft_twin.hpp"

namespace hoist::service::inline app {

std::string stateFileName(const std::string& base, const std::string& label) {
  std::string f = base;
  if (label.empty()) return f;
  f += '.';
  for (const char c : label)
    f += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  return f;
}

KeeperWorker::KeeperWorker(const std::vector<ShaftTwin*>& shafts, const std::string& state_dir,
                           std::shared_ptr<spdlog::logger> log)
    : shafts_(shafts) {
  for (ShaftTwin* s : shafts_)
    s->keepPreload(state_dir.empty() ? std::string() : state_dir + "/" + stateFileName("preload", s->label()), log);
}

void KeeperWorker::start() {
  if (thread_.joinable()) return;
  quit_.store(false);
  thread_ = std::thread([this] { main(); });
}

void KeeperWorker::stop() {
  if (!thread_.joinable()) return;
  quit_.store(true, std::memory_order_release);
  thread_.join();
}

void KeeperWorker::main() {
  hoist::rt::yieldToRealtimeLoop(kNice);
  for (;;) {
    const bool quitting = quit_.load(std::memory_order_acquire);
    for (ShaftTwin* s : shafts_) s->servePreload();
    if (quitting) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

}  // namespace hoist::service::app
