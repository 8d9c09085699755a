// Health statistics: latency histogram quantiles, log rate limiting, the
// real-time log ring.
#include <spdlog/sinks/base_sink.h>

#include <atomic>
#include <mutex>
#include <string_view>
#include <thread>

#include "hoist/rt/rt_log.hpp"
#include <gtest/gtest.h>

#include <limits>

#include "hoist/service/core/health.hpp"

using namespace hoist::service;

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

// The daemon's log ring (hoist/rt/rt_log.hpp): when the writer cannot keep up
// (here its sink is blocked), log() does not wait: the line is dropped and
// counted, and every line is either written or counted as dropped.
namespace {
class BlockingSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  std::atomic<bool> open{false};
  std::atomic<int> lines{0};

 protected:
  void sink_it_(const spdlog::details::log_msg& m) override {
    while (!open.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (std::string_view(m.payload.data(), m.payload.size()).find("dropped (real-time log ring full)") ==
        std::string_view::npos)
      lines.fetch_add(1);
  }
  void flush_() override {}
};
}  // namespace

TEST(RtLogRing, FullRingDropsAndCountsNeverBlocks) {
  auto sink = std::make_shared<BlockingSink>();
  auto logger = std::make_shared<spdlog::logger>("t", sink);
  hoist::rt::RtLog log(logger, 8);
  // Were log() to wait for the writer, this loop would never end (the sink
  // stays blocked until after it): the test would time out.
  for (int i = 0; i < 1000; ++i) log.info("line {}", i);
  EXPECT_GE(log.dropped(), 1000 - 2 * 8);
  sink->open = true;
  log.stop();
  EXPECT_EQ(sink->lines.load() + log.dropped(), 1000);
}
