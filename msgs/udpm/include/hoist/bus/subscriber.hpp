// hoist/bus/subscriber.hpp -- the receive side of every program that listens
// to the hoist channels (hoist-twind, hoist-dash, hoist-mqtt, hoist-monitor,
// hoist-timing-test): ONE place that picks the receive path for an LCM URL
// and drains it.  Target hoist_lcm_udpm (msgs/CMakeLists.txt).
//
//   udpm:// (and LCM's default "")  our own UdpmReceiver (udpm_receiver.hpp):
//                                   nothing stored per channel name, exact
//                                   names without regular expressions;
//   any other provider              LCM's own receive path on the program's
//                                   lcm::LCM (exact names regex-escaped).
//
// The program keeps its lcm::LCM for publishing; on the udpm path LCM is
// never asked to receive, so it opens no receive socket.  Use:
//
//   lcm::LCM lcm(url);
//   hoist::bus::Subscriber rx(lcm);
//   if (!rx.open(url, why)) { ... why names the URL ... }
//   rx.add(channel, handler);                  // exact channel name
//   rx.addMatching(predicate, lcm_regex, h);   // a set of names (discovery)
//   ... poll/asio on rx.fd(), then rx.drain(max) -- or rx.poll(ms, max).
//
// A listener apart from the program's publisher takes no LCM instance:
// Subscriber rx; rx.open(listen_url, why) -- for another provider it opens
// its own.  Handlers run on the caller's thread inside drain()/poll(); they must not
// throw into LCM's C dispatch (catch inside, as every program here does).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "hoist/bus/udpm_receiver.hpp"

namespace hoist::bus {

class Subscriber final : public InputRouter {
 public:
  /// `lcm`: the program's LCM instance, used to receive only when the URL is
  /// not udpm:// (it must outlive the Subscriber).
  explicit Subscriber(lcm::LCM& lcm) : lcm_(&lcm) {}
  /// A listener of its own: open() creates a receive-only LCM instance for
  /// a URL that is not udpm:// (a listener apart from the program's publisher).
  Subscriber() = default;
  Subscriber(const Subscriber&) = delete;
  Subscriber& operator=(const Subscriber&) = delete;

  /// Picks and opens the receive path for `url` (the URL `lcm` was opened
  /// with).  False and `why` (naming the URL) when the udpm socket cannot be
  /// opened or LCM's provider has no descriptor (tcpq:// with no server).
  /// `default_rcvbuf` [bytes]: the udpm socket's receive buffer when the URL
  /// gives no recv_buf_size (UdpmReceiver::open).
  bool open(const std::string& url, std::string& why, int default_rcvbuf = 0);

  /// Messages on exactly `channel`.
  void add(const std::string& channel, RawHandler handler) override;
  /// Messages on every channel whose name satisfies `match`; `lcm_regex` is
  /// the same set as an LCM subscription (GLib regular expression, anchored)
  /// for the LCM path.  The handler's channel string is reused between calls.
  void addMatching(std::function<bool(std::string_view)> match, const std::string& lcm_regex, RawHandler handler);

  /// The descriptor that becomes readable when messages wait (for poll/asio).
  int fd() { return rx_ ? rx_->fd() : lcm_->getFileno(); }
  /// Dispatch at most `max` messages that are waiting now (never blocks);
  /// returns how many.  Bounded, so the caller's other work is never starved.
  int drain(int max);
  /// Wait up to `timeout_ms` for messages, then drain(max); returns how many
  /// were dispatched (0 on timeout or an interrupted wait).
  int poll(int timeout_ms, int max);

  /// Our own udpm receive path (its counters, kernel drops, buffer size), or
  /// nullptr on LCM's path.
  UdpmReceiver* udpm() const { return rx_.get(); }

 private:
  /// An LCM subscription's target: a stable address for lcm::LCM::subscribe.
  struct LcmHandler {
    RawHandler handler;
    void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) { handler(rbuf, channel); }
  };
  lcm::LCM* lcm_ = nullptr;            ///< LCM's receive path (when rx_ is not used)
  std::unique_ptr<lcm::LCM> own_lcm_;  ///< created by open() when no LCM instance was given
  std::unique_ptr<UdpmReceiver> rx_;
  std::vector<std::unique_ptr<LcmHandler>> lcm_handlers_;
};

}  // namespace hoist::bus
