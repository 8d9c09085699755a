// hoist::bus::Subscriber (msgs/udpm/include/hoist/bus/subscriber.hpp): the one
// place that picks the receive path -- our UdpmReceiver for udpm:// URLs,
// LCM's own for other providers -- for hoist-twind and the tools.  Exact
// names on both paths (a prefix "mine.1/" must not receive "mineX1/"), the
// matching routes on both paths, and a provider without a connection named
// in the error.  Real multicast on loopback, port 8100; memq:// in-process.
#include <gtest/gtest.h>

#include <chrono>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "hoist/bus/subscriber.hpp"

using hoist::bus::Subscriber;

namespace {

struct Seen {
  std::vector<std::string> channels;
  hoist::bus::RawHandler handler() {
    return [this](const ::lcm::ReceiveBuffer* rb, const std::string& ch) {
      channels.push_back(ch + ":" + std::string(static_cast<const char*>(rb->data), rb->data_size));
    };
  }
};

void publish(::lcm::LCM& lcm, const std::string& channel, const std::string& text) {
  ASSERT_EQ(lcm.publish(channel, text.data(), static_cast<unsigned>(text.size())), 0);
}

// Poll until `n` messages have arrived or 5 s passed (loopback is fast; the
// bound only protects a loaded machine).
void receive(Subscriber& rx, Seen& seen, std::size_t n) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (seen.channels.size() < n && std::chrono::steady_clock::now() < end) rx.poll(50, 100);
}

void exactNamesAndMatching(const std::string& url, bool expect_udpm) {
  ::lcm::LCM lcm(url);
  ASSERT_TRUE(lcm.good()) << url;
  Subscriber rx(lcm);
  std::string why;
  ASSERT_TRUE(rx.open(url, why)) << why;
  EXPECT_EQ(rx.udpm() != nullptr, expect_udpm) << url;
  EXPECT_GE(rx.fd(), 0);
  Seen exact, matched;
  rx.add("mine.1/HOIST_CAGE", exact.handler());
  rx.addMatching([](std::string_view n) { return n.size() >= 6 && n.substr(n.size() - 6) == "_TRAIL"; },
                 ".*_TRAIL", matched.handler());
  publish(lcm, "mineX1/HOIST_CAGE", "regex-lookalike");  // must not reach the exact route
  publish(lcm, "mine.1/HOIST_CAGE", "a");
  publish(lcm, "OTHER", "nobody");
  publish(lcm, "X_TRAIL", "b");
  publish(lcm, "mine.1/HOIST_CAGE", "c");
  receive(rx, exact, 2);
  receive(rx, matched, 1);
  rx.poll(100, 100);  // anything late would show below
  EXPECT_EQ(exact.channels, (std::vector<std::string>{"mine.1/HOIST_CAGE:a", "mine.1/HOIST_CAGE:c"})) << url;
  EXPECT_EQ(matched.channels, (std::vector<std::string>{"X_TRAIL:b"})) << url;
  EXPECT_EQ(rx.drain(10), 0) << "nothing left";
}

}  // namespace

TEST(Subscriber, UdpmUrlTakesOurReceiverWithExactNames) {
  exactNamesAndMatching("udpm://239.255.76.67:8100?ttl=0", true);
}

TEST(Subscriber, OtherProvidersTakeLcmsPathWithExactNames) { exactNamesAndMatching("memq://", false); }

TEST(Subscriber, ListenerWithoutLcmInstanceOpensItsOwn) {
  // A listener apart from the publisher (hoist-timing-test's): no LCM given.
  ::lcm::LCM tx("udpm://239.255.76.67:8101?ttl=0");
  ASSERT_TRUE(tx.good());
  Subscriber rx;
  std::string why;
  ASSERT_TRUE(rx.open("udpm://239.255.76.67:8101?ttl=0", why)) << why;
  ASSERT_NE(rx.udpm(), nullptr);
  Seen seen;
  rx.add("CH", seen.handler());
  publish(tx, "CH", "x");
  receive(rx, seen, 1);
  EXPECT_EQ(seen.channels, (std::vector<std::string>{"CH:x"}));
}

TEST(Subscriber, ProviderWithoutConnectionIsNamed) {
  ::lcm::LCM lcm("tcpq://127.0.0.1:1");
  Subscriber rx(lcm);
  std::string why;
  EXPECT_FALSE(rx.open("tcpq://127.0.0.1:1", why));
  EXPECT_NE(why.find("tcpq://127.0.0.1:1"), std::string::npos) << why;
}
