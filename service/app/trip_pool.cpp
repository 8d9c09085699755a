// The trip rooms' worker threads: see trip_pool.hpp.
#include "trip_pool.hpp"

#include <algorithm>
#include <stdexcept>

#include "hoist/rt/realtime.hpp"

namespace hoist::service::inline app {

TripPool::TripPool(int workers) : max_workers_(workers) {
  if (workers < 1) throw std::invalid_argument("TripPool: workers must be >= 1");
}

TripPool::~TripPool() { stop(); }

void TripPool::start() {
  if (!threads_.empty() || rooms_.empty()) return;
  quit_.store(false);
  const std::size_t n = std::min(rooms_.size(), static_cast<std::size_t>(max_workers_));
  for (std::size_t k = 0; k < n; ++k) threads_.emplace_back([this, k, n] { workerMain(k, n); });
}

void TripPool::stop() {
  if (threads_.empty()) return;
  quit_.store(true, std::memory_order_release);
  for (auto& t : threads_) t.join();
  threads_.clear();
}

void TripPool::workerMain(std::size_t k, std::size_t n) {
  hoist::rt::yieldToRealtimeLoop(kWorkerNice);
  std::vector<TripWork*> mine;
  for (std::size_t i = k; i < rooms_.size(); i += n) mine.push_back(rooms_[i]);
  std::size_t opened = 0;
  for (;;) {
    const bool quitting = quit_.load(std::memory_order_acquire);
    if (quitting) break;
    if (opened < mine.size()) mine[opened++]->workerOpen();  // one per pass: the opened ones record meanwhile
    for (std::size_t i = 0; i < opened; ++i) mine[i]->workerDrain();
    if (opened == mine.size()) std::this_thread::sleep_for(kDrainPeriod);
  }
  // The loop has stopped pushing: every room opened, drained once more, closed.
  while (opened < mine.size()) mine[opened++]->workerOpen();
  for (TripWork* r : mine) r->workerDrain();
  for (TripWork* r : mine) r->workerClose();
}

}  // namespace hoist::service::app
