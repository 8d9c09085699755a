// hoist/bus/udpm_receiver.hpp, the project's own udpm:// receive path (the
// LCM 1.3.1 workaround against channel-name spam, used by hoist-twind, hoist-dash,
// hoist-mqtt and hoist-monitor): URL parsing, exact and matching routes, and
// what it drops.  Real multicast on loopback, ports 7866 and 7877 (the datagrams are
// LCM's own, sent by ::lcm::LCM::publish, and hand-made ones).
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <thread>

#include "hoist/bus/udpm_receiver.hpp"
#include "lcm_fixtures.hpp"

using hoist::bus::UdpmReceiver;
using hoist::bus::UdpmUrl;
using namespace std::chrono_literals;

TEST(UdpmUrl, ParsesLcmUrlsAndTheDefault) {
  UdpmUrl u;
  std::string why;
  ASSERT_TRUE(hoist::bus::parseUdpmUrl("", u, why));  // LCM's default: udpm://239.255.76.67:7667?ttl=0
  EXPECT_EQ(u.group, "239.255.76.67");
  EXPECT_EQ(u.port, 7667);
  ASSERT_TRUE(hoist::bus::parseUdpmUrl("udpm://239.1.2.3:7001?ttl=0&recv_buf_size=65536", u, why)) << why;
  EXPECT_EQ(u.group, "239.1.2.3");
  EXPECT_EQ(u.port, 7001);
  EXPECT_EQ(u.recv_buf_size, 65536);
  EXPECT_FALSE(hoist::bus::parseUdpmUrl("memq://", u, why));
  EXPECT_FALSE(hoist::bus::parseUdpmUrl("udpm://10.0.0.1:7667", u, why));  // not multicast
  EXPECT_NE(why.find("not an IPv4 multicast group"), std::string::npos) << why;
  EXPECT_FALSE(hoist::bus::parseUdpmUrl("udpm://239.1.2.3:0", u, why));
  EXPECT_FALSE(hoist::bus::parseUdpmUrl("udpm://239.1.2.3:7001?recv_buf_size=-5", u, why));
}

TEST(UdpmReceiverTest, ExactAndMatchingRoutesOthersCountedNothingStored) {
  const std::string url = hoist::test::urlFor(7866);
  std::string why;
  if (!hoist::test::loopbackMulticastWorks(url, why)) FAIL() << why << ".\n" << hoist::test::kMulticastHelp;
  UdpmUrl u;
  ASSERT_TRUE(hoist::bus::parseUdpmUrl(url, u, why));
  UdpmReceiver rx;
  ASSERT_TRUE(rx.open(u, why)) << why;
  int exact = 0, matched = 0;
  std::string last_matched;
  std::size_t last_size = 0;
  rx.add("mine.1/HOIST_WINDER", [&](const ::lcm::ReceiveBuffer* rb, const std::string& ch) {
    ++exact;
    last_size = rb->data_size;
    EXPECT_EQ(ch, "mine.1/HOIST_WINDER");
  });
  rx.addMatching([](std::string_view n) { return n.size() >= 11 && n.substr(n.size() - 11) == "HOIST_ALARM"; },
                 [&](const ::lcm::ReceiveBuffer*, const std::string& ch) {
                   ++matched;
                   last_matched = ch;
                 });
  // Drain as we go: a burst of 1000 datagrams would overflow the socket's
  // default receive buffer (and be lost in the kernel, not here).
  auto pump = [&] {
    const auto until = std::chrono::steady_clock::now() + 50ms;
    while (std::chrono::steady_clock::now() < until)
      if (rx.drain(256) == 0) std::this_thread::sleep_for(1ms);
  };
  ::lcm::LCM pub(url);
  ASSERT_TRUE(pub.good());
  const char payload[5] = {1, 2, 3, 4, 5};
  pub.publish("mine.1/HOIST_WINDER", payload, 5);   // exact
  pub.publish("mineX1/HOIST_WINDER", payload, 5);   // a regex would match; an exact name does not
  pub.publish("north/HOIST_ALARM", payload, 5);     // matching route
  pub.publish("HOIST_ALARM_ACK", payload, 5);       // neither
  pump();
  for (int i = 0; i < 1000; ++i) {
    pub.publish("SPAM_" + std::to_string(i), payload, 5);
    if (i % 50 == 49) pump();
  }
  // Hand-made datagrams: a fragment ("LC03"), no NUL within 64 bytes, too short.
  const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(s, 0);
  unsigned char ttl = 0;
  ::setsockopt(s, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(u.port));
  inet_pton(AF_INET, u.group.c_str(), &to.sin_addr);
  auto send = [&](const std::string& d) {
    ::sendto(s, d.data(), d.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  };
  send(std::string("LC03") + std::string(20, 'x'));
  send(std::string("LC02\0\0\0\1", 8) + std::string(100, 'A'));
  send("LC0");
  ::close(s);
  const auto end = std::chrono::steady_clock::now() + 3s;
  while (rx.received() < 1007 && std::chrono::steady_clock::now() < end) {
    if (rx.drain(256) == 0) std::this_thread::sleep_for(5ms);
  }
  EXPECT_EQ(rx.received(), 1007);
  EXPECT_EQ(exact, 1);
  EXPECT_EQ(last_size, 5u);
  EXPECT_EQ(matched, 1);
  EXPECT_EQ(last_matched, "north/HOIST_ALARM");
  EXPECT_EQ(rx.ignored(), 1002);   // mineX1, HOIST_ALARM_ACK, 1000 spam names
  EXPECT_EQ(rx.malformed(), 3);
}

TEST(UdpmReceiverTest, KernelSuffixFilterQueuesOnlyTheWatchedChannels) {
  // hoist-twind's watch of its own HOIST_HEALTH on lcm_url_out: the kernel
  // must drop every other channel (its cage and shape outputs) before they
  // reach the socket, and keep "<prefix>HOIST_HEALTH" for the prefix lengths
  // given (here 0 and 6: "" and "north/").
  const std::string url = hoist::test::urlFor(7877);
  std::string why;
  if (!hoist::test::loopbackMulticastWorks(url, why)) FAIL() << why << ".\n" << hoist::test::kMulticastHelp;
  UdpmUrl u;
  ASSERT_TRUE(hoist::bus::parseUdpmUrl(url, u, why));
  UdpmReceiver rx;
  ASSERT_TRUE(rx.open(u, why)) << why;
  std::vector<std::string> got;
  rx.addMatching([](std::string_view) { return true; },
                 [&](const ::lcm::ReceiveBuffer*, const std::string& ch) { got.push_back(ch); });
  ASSERT_TRUE(rx.acceptOnlySuffix("HOIST_HEALTH", {0, 6}, why)) << why;
  ::lcm::LCM pub(url);
  ASSERT_TRUE(pub.good());
  const char payload[24] = {};
  for (const char* ch : {"HOIST_CAGE", "HOIST_HEALTH", "north/HOIST_CAGE", "north/HOIST_HEALTH", "south/HOIST_HEALTH",
                         "xyz/HOIST_HEALTH", "HOIST_HEALTHX", "north/HOIST_HEALTH_", "HOIST_HEALT"})
    pub.publish(ch, payload, sizeof payload);
  const auto until = std::chrono::steady_clock::now() + 300ms;
  while (std::chrono::steady_clock::now() < until)
    if (rx.drain(256) == 0) std::this_thread::sleep_for(1ms);
  // "south/" has 6 bytes too: the kernel keeps it (same length); the exact
  // routes of the daemon then tell it apart.  Everything else never arrives.
  EXPECT_EQ(got, (std::vector<std::string>{"HOIST_HEALTH", "north/HOIST_HEALTH", "south/HOIST_HEALTH"}));
  EXPECT_EQ(rx.received(), 3);
  EXPECT_EQ(rx.ignored(), 0);
  EXPECT_EQ(rx.malformed(), 0);
}
