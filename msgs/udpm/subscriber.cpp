// The receive side of the hoist programs: see hoist/bus/subscriber.hpp.
#include "hoist/bus/subscriber.hpp"

#include <poll.h>

#include "hoist/bus/lcm_util.hpp"

namespace hoist::bus {

bool Subscriber::open(const std::string& url, std::string& why, int default_rcvbuf) {
  why.clear();
  rx_ = openUdpmReceiver(url, why, default_rcvbuf);
  if (rx_) return true;
  if (!why.empty()) return false;  // udpm://, but the socket could not be opened (why names the URL)
  // Another provider: LCM receives.  One that could not connect (tcpq://
  // with no server) has no descriptor: say which URL, not "Bad file descriptor".
  if (!lcm_) {
    own_lcm_ = std::make_unique<lcm::LCM>(url);
    lcm_ = own_lcm_.get();
  }
  if (!lcm_->good()) {
    why = "cannot open LCM at " + describeLcmUrl(url);
    return false;
  }
  if (lcm_->getFileno() < 0) {
    why = "cannot receive from LCM at " + describeLcmUrl(url) +
          ": the provider has no connection (is its server running?)";
    return false;
  }
  return true;
}

void Subscriber::add(const std::string& channel, RawHandler handler) {
  if (rx_) {
    rx_->add(channel, std::move(handler));
    return;
  }
  // lcm::subscribe takes a regular expression: subscribe to the literal
  // name (a prefix "mine.1/" must not match "mineX1/").
  lcm_handlers_.push_back(std::make_unique<LcmHandler>(LcmHandler{std::move(handler)}));
  lcm_->subscribe(regexEscape(channel), &LcmHandler::onMessage, lcm_handlers_.back().get());
}

void Subscriber::addMatching(std::function<bool(std::string_view)> match, const std::string& lcm_regex,
                             RawHandler handler) {
  if (rx_) {
    rx_->addMatching(std::move(match), std::move(handler));
    return;
  }
  lcm_handlers_.push_back(std::make_unique<LcmHandler>(LcmHandler{std::move(handler)}));
  lcm_->subscribe(lcm_regex, &LcmHandler::onMessage, lcm_handlers_.back().get());
}

int Subscriber::drain(int max) {
  if (rx_) return rx_->drain(max);
  int n = 0;
  while (n < max && lcm_->handleTimeout(0) > 0) ++n;
  return n;
}

int Subscriber::poll(int timeout_ms, int max) {
  pollfd p{fd(), POLLIN, 0};
  if (::poll(&p, 1, timeout_ms) <= 0 || !(p.revents & POLLIN)) return 0;
  return drain(max);
}

}  // namespace hoist::bus
