// hoist-twind's own udpm receive path (msgs/udpm/include/hoist/bus/udpm_receiver.hpp),
// for many shafts per process: the receive buffer it asks for is granted, and the kernel's drop count
// (SO_RXQ_OVFL) accounts for every datagram that did not fit.  Real UDP
// multicast on loopback, a port per test (8143-8145: CTest runs them side by
// side, and the drop count would count another test's datagrams).  And its
// own publisher (hoist/bus/udpm_sender.hpp).
#include <gtest/gtest.h>

#include <fstream>
#include <lcm/lcm-cpp.hpp>

#include "hoist/bus/udpm_receiver.hpp"
#include "hoist/bus/udpm_sender.hpp"

using namespace hoist::bus;

namespace {

const char* kUrl = "udpm://239.255.76.67:8143?ttl=0";        // DefaultReceiveBufferIsGranted
const char* kUrlDrops = "udpm://239.255.76.67:8144?ttl=0";   // KernelDropsAccountForEveryDatagramThatDidNotFit
const char* kUrlSender = "udpm://239.255.76.67:8145?ttl=0";  // LcmReceivesWhatItSendsAndQueues

long rmemMax() {
  std::ifstream f("/proc/sys/net/core/rmem_max");
  long v = 0;
  f >> v;
  return v;
}

bool multicastWorks() {
  ::lcm::LCM l(kUrl);
  return l.good();
}

}  // namespace

TEST(UdpmReceiver, DefaultReceiveBufferIsGranted) {
  UdpmUrl url;
  std::string why;
  ASSERT_TRUE(parseUdpmUrl(kUrl, url, why)) << why;
  UdpmReceiver rx;
  const int want = 4 << 20;
  ASSERT_TRUE(rx.open(url, why, want)) << why;
  // The kernel doubles the request (bookkeeping overhead); without the
  // privilege for SO_RCVBUFFORCE it caps the request at rmem_max.
  const long expect = std::min<long>(want, rmemMax());
  EXPECT_GE(rx.rcvbuf(), expect) << "rmem_max " << rmemMax();
  // recv_buf_size in the URL wins over the default.
  UdpmUrl small;
  ASSERT_TRUE(parseUdpmUrl(std::string(kUrl) + "&recv_buf_size=65536", small, why)) << why;
  EXPECT_EQ(small.recv_buf_size, 65536);
  UdpmReceiver rx2;
  ASSERT_TRUE(rx2.open(small, why, want)) << why;
  EXPECT_LT(rx2.rcvbuf(), 4 << 20);
  EXPECT_GE(rx2.rcvbuf(), 65536);
}

TEST(UdpmReceiver, KernelDropsAccountForEveryDatagramThatDidNotFit) {
  if (!multicastWorks())
    GTEST_FAIL() << "UDP multicast on loopback is off: run scripts/setup.sh or, as root, "
                    "ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo";
  UdpmUrl url;
  std::string why;
  // A tiny buffer (the kernel's minimum): a burst overflows it.
  ASSERT_TRUE(parseUdpmUrl(std::string(kUrlDrops) + "&recv_buf_size=4096", url, why)) << why;
  UdpmReceiver rx;
  ASSERT_TRUE(rx.open(url, why)) << why;
  int got = 0;
  rx.add("DROPTEST", [&](const ::lcm::ReceiveBuffer* rb, const std::string&) {
    EXPECT_EQ(rb->data_size, 200u);
    ++got;
  });
  ::lcm::LCM tx(kUrlDrops);
  ASSERT_TRUE(tx.good());
  std::vector<std::uint8_t> payload(200, 0x5a);
  constexpr int kSent = 300;
  for (int i = 0; i < kSent; ++i) ASSERT_EQ(tx.publish("DROPTEST", payload.data(), payload.size()), 0);
  // Nothing was read while they were sent: most did not fit.
  while (rx.drain(64) > 0) {
  }
  EXPECT_GT(got, 0);
  // The datagrams read were queued before the drops: they carry none.
  EXPECT_EQ(rx.kernelDrops(), 0);
  // The next datagram carries the count (SO_RXQ_OVFL) ...
  ASSERT_EQ(tx.publish("DROPTEST", payload.data(), payload.size()), 0);
  for (int i = 0; i < 1000 && rx.drain(64) == 0; ++i) {
  }
  const std::int64_t dropped = rx.kernelDrops();
  EXPECT_GT(dropped, 0) << "the tiny buffer cannot have held " << kSent << " datagrams";
  EXPECT_EQ(got - 1 + dropped, kSent) << "received " << got - 1 << ", dropped " << dropped;
  // ... and the kernel says the same when asked.
  EXPECT_EQ(rx.refreshKernelDrops(), dropped);
  EXPECT_EQ(rx.ignored(), 0);
  EXPECT_EQ(rx.malformed(), 0);
}

TEST(UdpmSender, LcmReceivesWhatItSendsAndQueues) {
  // The daemon's own publisher (udpm_sender.hpp) speaks LCM's wire format:
  // an ::lcm::LCM subscriber gets every message, immediate and batched, in order.
  if (!multicastWorks()) GTEST_FAIL() << "UDP multicast on loopback is off";
  UdpmUrl url;
  std::string why;
  ASSERT_TRUE(parseUdpmUrl(kUrlSender, url, why)) << why;
  EXPECT_EQ(url.ttl, 0);
  UdpmSender tx;
  ASSERT_TRUE(tx.open(url, why)) << why;
  ::lcm::LCM rx(std::string(kUrlSender) + "&recv_buf_size=4000000");
  ASSERT_TRUE(rx.good());
  std::vector<int> seen;
  struct Sub {
    std::vector<int>* seen;
    void on(const ::lcm::ReceiveBuffer* rb, const std::string& ch) {
      ASSERT_EQ(ch, "SENDTEST");
      ASSERT_EQ(rb->data_size, 3000u);
      seen->push_back(static_cast<const std::uint8_t*>(rb->data)[0]);
    }
  } sub{&seen};
  rx.subscribe("SENDTEST", &Sub::on, &sub)->setQueueCapacity(1000);  // LCM's default: 30
  std::vector<std::vector<std::uint8_t>> bufs;
  for (int i = 0; i < 100; ++i) bufs.emplace_back(3000, static_cast<std::uint8_t>(i));
  std::int64_t failures = 0;
  ASSERT_TRUE(tx.send("SENDTEST", bufs[0].data(), bufs[0].size()));
  for (int i = 1; i < 100; ++i) ASSERT_TRUE(tx.queue("SENDTEST", bufs[i].data(), bufs[i].size(), &failures));
  EXPECT_EQ(tx.queued(), 99 - UdpmSender::kSlots);  // a full queue is flushed before the next message
  EXPECT_EQ(tx.flush(), 0);
  EXPECT_EQ(tx.queued(), 0);
  EXPECT_EQ(failures, 0);
  EXPECT_EQ(tx.sent(), 100);
  EXPECT_LE(tx.systemCalls(), 1 + 2 + 2);  // one send, two sendmmsg (maybe one more after a partial send)
  for (int k = 0; k < 200 && seen.size() < 100; ++k) rx.handleTimeout(20);
  ASSERT_EQ(seen.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(seen[i], i);
  // Refused: too long a channel name, too large a payload.
  EXPECT_FALSE(tx.queue(std::string(64, 'x'), bufs[0].data(), 10, &failures));
  std::vector<std::uint8_t> big(UdpmSender::kMaxPayload + 1);
  EXPECT_FALSE(tx.send("SENDTEST", big.data(), big.size()));
}
