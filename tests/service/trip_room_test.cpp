// The trip room's ring (service/app/trip_room.hpp): single producer, single
// consumer, fixed capacity -- order kept across wrap-around, a full ring
// refuses (the loop counts a drop, never waits), and two threads see every
// tick once, in order.  The live trip recording is trip_history_daemon_test.
#include <gtest/gtest.h>

#include <thread>

#include "trip_room.hpp"

using hoist::service::TripRing;
using hoist::service::TripTick;

namespace {
TripTick tickAt(int k) {
  TripTick t;
  t.m.t = k;
  t.wall_us = k;
  return t;
}
}  // namespace

TEST(TripRing, KeepsOrderAcrossWrapAroundAndRefusesWhenFull) {
  TripRing r(4);  // holds capacity - 1 = 3 ticks
  TripTick out;
  EXPECT_FALSE(r.pop(out));
  int next_in = 0, next_out = 0;
  for (int round = 0; round < 5; ++round) {
    while (r.push(tickAt(next_in))) ++next_in;
    EXPECT_EQ(next_in - next_out, 3) << "a full ring holds capacity - 1 ticks";
    EXPECT_FALSE(r.push(tickAt(-1)));  // full: refused, nothing overwritten
    ASSERT_TRUE(r.pop(out));
    EXPECT_EQ(out.wall_us, next_out++);
    ASSERT_TRUE(r.pop(out));
    EXPECT_EQ(out.wall_us, next_out++);
  }
  while (r.pop(out)) EXPECT_EQ(out.wall_us, next_out++);
  EXPECT_EQ(next_out, next_in);
}

TEST(TripRing, TwoThreadsSeeEveryTickOnceInOrder) {
  TripRing r(64);
  constexpr int kTicks = 200000;
  std::thread producer([&] {
    for (int k = 0; k < kTicks; ++k)
      while (!r.push(tickAt(k))) std::this_thread::yield();
  });
  int expected = 0;
  TripTick out;
  while (expected < kTicks) {
    if (!r.pop(out)) {
      std::this_thread::yield();
      continue;
    }
    ASSERT_EQ(out.wall_us, expected);
    ASSERT_EQ(out.m.t, static_cast<double>(expected));
    ++expected;
  }
  producer.join();
  EXPECT_FALSE(r.pop(out));
}
