// The trip rooms' pool (service/app/trip_pool.hpp): every room is opened
// once, first, then drained, and closed once, last, after a final drain;
// all of one room's calls come from one thread; a few threads serve many
// rooms, their opening spread over passes while the opened ones drain; an
// idle pool sleeps; stop() is idempotent and a pool without rooms starts
// nothing.  The live trip rooms on it: trip_history_daemon_test.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "trip_pool.hpp"

using hoist::service::TripPool;
using hoist::service::TripWork;
using namespace std::chrono_literals;

namespace {

/// A room that records who called what, in which order.
class FakeRoom : public TripWork {
 public:
  void workerOpen() override { note('o'); }
  void workerDrain() override {
    note('d');
    drains.fetch_add(1);
  }
  void workerClose() override { note('c'); }

  std::string calls() const {
    std::lock_guard<std::mutex> l(mu_);
    return calls_;
  }
  std::set<std::thread::id> threads() const {
    std::lock_guard<std::mutex> l(mu_);
    return threads_;
  }
  std::atomic<long> drains{0};

 private:
  void note(char c) {
    std::lock_guard<std::mutex> l(mu_);
    calls_ += c;
    threads_.insert(std::this_thread::get_id());
  }
  mutable std::mutex mu_;
  std::string calls_;
  std::set<std::thread::id> threads_;
};

/// calls = "o" "d"* "c": opened first and once, closed last and once, drained at least once before.
bool wellFormed(const std::string& c) {
  return c.size() >= 3 && c.front() == 'o' && c.back() == 'c' && c.find_first_of("oc", 1) == c.size() - 1 &&
         c[c.size() - 2] == 'd';
}

/// `n` rooms, each added to `pool`.
std::vector<std::unique_ptr<FakeRoom>> addRooms(TripPool& pool, int n) {
  std::vector<std::unique_ptr<FakeRoom>> rooms;
  for (int i = 0; i < n; ++i) {
    rooms.push_back(std::make_unique<FakeRoom>());
    pool.add(rooms.back().get());
  }
  return rooms;
}

}  // namespace

TEST(TripPool, FewThreadsServeManyRoomsEachFromOneThreadOpenFirstCloseLast) {
  TripPool pool(3);
  const auto rooms = addRooms(pool, 50);
  EXPECT_EQ(pool.workers(), 0);
  pool.start();
  EXPECT_EQ(pool.workers(), 3);
  // Every room opened and drained within a few seconds (one open per pass per worker).
  const auto until = std::chrono::steady_clock::now() + 10s;
  auto allDrained = [&] {
    for (auto& r : rooms)
      if (r->drains.load() < 2) return false;
    return true;
  };
  while (!allDrained() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(5ms);
  ASSERT_TRUE(allDrained());
  // Idle: drained every kDrainPeriod, not in a busy loop (a loaded machine
  // only makes the passes rarer), and on and on.
  const long before = rooms[0]->drains.load();
  std::this_thread::sleep_for(200ms);
  EXPECT_LE(rooms[0]->drains.load() - before, 12);  // 10 at 20 ms
  const auto again = std::chrono::steady_clock::now() + 10s;
  while (rooms[0]->drains.load() < before + 3 && std::chrono::steady_clock::now() < again)
    std::this_thread::sleep_for(5ms);
  EXPECT_GE(rooms[0]->drains.load(), before + 3);
  pool.stop();
  pool.stop();  // idempotent
  std::set<std::thread::id> all;
  for (auto& r : rooms) {
    EXPECT_TRUE(wellFormed(r->calls())) << r->calls();
    EXPECT_EQ(r->threads().size(), 1u);  // one thread for the room's life
    all.insert(*r->threads().begin());
  }
  EXPECT_EQ(all.size(), 3u);  // 3 threads for 50 rooms
}

TEST(TripPool, AStopBeforeEveryRoomWasOpenedStillOpensDrainsAndClosesEachOnce) {
  TripPool pool(1);
  const auto rooms = addRooms(pool, 200);
  pool.start();
  pool.stop();  // at once: most rooms not yet opened by the passes
  for (auto& r : rooms) EXPECT_TRUE(wellFormed(r->calls())) << r->calls();
}

TEST(TripPool, NoRoomsNoThreadsAndFewerRoomsThanWorkers) {
  TripPool empty(4);
  empty.start();
  EXPECT_EQ(empty.workers(), 0);
  empty.stop();
  FakeRoom a, b;
  TripPool two(8);
  two.add(&a);
  two.add(&b);
  two.start();
  EXPECT_EQ(two.workers(), 2);
  two.stop();
  EXPECT_TRUE(wellFormed(a.calls()));
  EXPECT_TRUE(wellFormed(b.calls()));
  EXPECT_THROW(TripPool(0), std::invalid_argument);
}
