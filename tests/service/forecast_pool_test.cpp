// The forecast workers give way to the real-time loop.  A thread created by
// the loop thread after it took SCHED_FIFO inherits that priority, and two
// SCHED_FIFO threads of one priority on one CPU do not preempt each other: a
// worker computing a forecast for milliseconds held the loop off its
// deadline (bench/multishaft.sh with forecasts on: misses whose time was in
// "timer" with little loop CPU).  hoist::rt::yieldToRealtimeLoop makes the
// calling thread SCHED_OTHER at a raised nice value; every ForecastPool worker
// calls it first.
//   * the function sets the calling thread's policy and nice value, and no
//     other thread's;
//   * the premise (where this process may take SCHED_FIFO, e.g. as root):
//     a thread created by a SCHED_FIFO thread is SCHED_FIFO too;
//   * a pool started from such a thread reports every worker yielded.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <pthread.h>
#include <sched.h>
#include <string>
#include <sys/resource.h>
#include <thread>
#include <unistd.h>

#include "forecast_pool.hpp"
#include "hoist/rt/realtime.hpp"

using namespace hoist;
using namespace hoist::service;

namespace {

int niceOfThisThread() {
  errno = 0;
  return ::getpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()));
}

/// Try to make the calling thread SCHED_FIFO `prio`; false where refused.
bool tryFifo(int prio) {
  sched_param sp{};
  sp.sched_priority = prio;
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0;
}

}  // namespace

TEST(YieldToRealtimeLoop, SetsThisThreadsPolicyAndNiceOnly) {
  const int main_nice = niceOfThisThread();
  const int main_policy = sched_getscheduler(0);
  int policy = -1, nice = -1;
  bool ok = false, was_fifo = false;
  std::string why;
  std::thread t([&] {
    was_fifo = tryFifo(3) && sched_getscheduler(0) == SCHED_FIFO;
    ok = hoist::rt::yieldToRealtimeLoop(ForecastPool::kWorkerNice, &why);
    policy = sched_getscheduler(0);
    nice = niceOfThisThread();
  });
  t.join();
  EXPECT_TRUE(ok) << why;
  EXPECT_EQ(policy, SCHED_OTHER) << (was_fifo ? "from SCHED_FIFO" : "from SCHED_OTHER");
  EXPECT_EQ(nice, ForecastPool::kWorkerNice);
  EXPECT_EQ(niceOfThisThread(), main_nice) << "another thread's nice value changed";
  EXPECT_EQ(sched_getscheduler(0), main_policy);
  std::printf("SCHED_FIFO %s here\n", was_fifo ? "granted" : "refused (the premise below is then not checked)");
}

TEST(ForecastPool, WorkersStartedByAFifoLoopGiveWayFirst) {
  std::atomic<bool> fifo{false}, child_fifo{false};
  int yielded = -1, workers = 0;
  std::thread loop([&] {
    fifo = tryFifo(5);
    if (fifo) {
      // The premise: a thread created now inherits SCHED_FIFO.
      std::thread child([&] { child_fifo = sched_getscheduler(0) == SCHED_FIFO; });
      child.join();
    }
    TwinConfig c;
    c.shaft.n = 6;
    c.service.rate = 100.0;
    auto model = std::make_shared<const ShaftModel>(c.shaft);
    ForecastJob job(model, c);
    ForecastPool pool(2);
    pool.add(&job);
    pool.start();
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (pool.workersYielded() < pool.workers() && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    yielded = pool.workersYielded();
    workers = pool.workers();
    pool.stop();
  });
  loop.join();
  if (fifo) EXPECT_TRUE(child_fifo) << "a thread created by a SCHED_FIFO thread inherits it";
  EXPECT_EQ(workers, 2);
  EXPECT_EQ(yielded, workers) << "every worker gave way to the loop";
}
