// Health statistics: latency histogram quantiles, log rate limiting.
#include <gtest/gtest.h>

#include <limits>

#include "hoist/service/health.hpp"

using namespace hoist::svc;

TEST(LatencyHistogram, QuantilesWithinABin) {
  LatencyHistogram h;
  EXPECT_EQ(h.quantile(0.5), 0.0);
  for (int i = 1; i <= 1000; ++i) h.add(static_cast<double>(i));  // 1 .. 1000 us
  EXPECT_EQ(h.count(), 1000);
  EXPECT_DOUBLE_EQ(h.max(), 1000.0);
  EXPECT_NEAR(h.quantile(0.5), 500.0, 500.0 * 0.07);
  EXPECT_NEAR(h.quantile(0.99), 990.0, 990.0 * 0.07);
  EXPECT_LE(h.quantile(1.0), 1000.0);
  h.reset();
  EXPECT_EQ(h.count(), 0);
  EXPECT_EQ(h.max(), 0.0);
}

TEST(LatencyHistogram, ExtremesAreSafe) {
  LatencyHistogram h;
  h.add(-5.0);
  h.add(0.0);
  h.add(1e12);
  h.add(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(h.count(), 4);
  EXPECT_GE(h.quantile(1.0), 1e9);
}

TEST(LogRateLimiter, AllowsNPerSecondAndCountsTheRest) {
  LogRateLimiter<2> rl(3);
  std::int64_t suppressed = -1;
  int allowed = 0;
  for (int i = 0; i < 10; ++i) allowed += rl.allow(0, 0.01 * i, suppressed);
  EXPECT_EQ(allowed, 3);
  EXPECT_EQ(rl.pending(0), 7);
  EXPECT_TRUE(rl.allow(1, 0.5, suppressed));  // keys are independent
  EXPECT_EQ(suppressed, 0);
  EXPECT_TRUE(rl.allow(0, 1.2, suppressed));  // new window
  EXPECT_EQ(suppressed, 7);
  EXPECT_EQ(rl.pending(0), 0);
}
