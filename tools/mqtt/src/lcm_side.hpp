// lcm_side.hpp -- the bridge's LCM side: the program's lcm::LCM (publishing
// alarm commands), its receive path (hoist::bus::Subscriber) and the route
// table: one entry per channel suffix, each decoded by ONE templated decode
// (hoist::msg::checkedDecode, before anything is allocated from the
// payload) and handed to its handler with the shaft the prefix resolves to.
// Private to tools/mqtt; the map of the rooms is bridge.cpp.
//
// Writes only its own counters (messages, ignored channels, decode errors by
// type and reason).  No exception leaves a handler (counted as "exception").
#pragma once

#include <cstdint>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "bridge_common.hpp"
#include "hoist/alarm_ack_t.hpp"
#include "hoist/bus/subscriber.hpp"
#include "hoist/msg/codec.hpp"
#include "shaft_directory.hpp"

namespace hoist::mqtt {

class LcmSide {
 public:
  /// Opens LCM at `url` (already resolved: hoist::bus::resolveLcmUrl).
  /// Throws std::runtime_error naming the URL if it cannot.  `log` is
  /// referenced and must outlive this object.
  LcmSide(const std::string& url, LogBudget& log);
  LcmSide(const LcmSide&) = delete;
  LcmSide& operator=(const LcmSide&) = delete;

  /// Where a channel's prefix leads (the shaft directory): nullptr = not
  /// bridged (counted as an ignored channel, not decoded).
  using Resolve = std::function<const Shaft*(const std::string& prefix)>;

  /// Messages of type Msg on every channel `<prefix><suffix>`; routes are
  /// tried in the order they were added.  Call before listen().
  template <class Msg>
  void route(std::string_view suffix, std::function<void(const Shaft&, const Msg&)> on) {
    routes_.push_back({std::string(suffix), [this, on = std::move(on)](const Shaft& s, const lcm::ReceiveBuffer* rb,
                                                                        const std::string& channel) {
                         Msg m;
                         const auto st = hoist::msg::checkedDecode(rb->data, rb->data_size, m);
                         if (st != hoist::msg::DecodeStatus::ok) return decodeError(Msg::getTypeName(), st, channel);
                         on(s, m);
                       }});
  }

  /// Opens the receive path and subscribes to every routed suffix (one
  /// subscription for all shafts).  Throws std::runtime_error naming the URL.
  void listen(Resolve resolve);

  int fd() { return rx_.fd(); }
  /// Dispatches at most `max` waiting messages (never blocks).
  void drain(int max) { rx_.drain(max); }

  /// Publishes an alarm command on `channel`; false if LCM refused it.
  bool publishAck(const std::string& channel, const hoist::alarm_ack_t& m) { return lcm_.publish(channel, &m) == 0; }

  const std::string& url() const { return url_; }
  std::uint64_t messages() const { return messages_; }
  std::uint64_t ignoredChannels() const { return ignored_; }
  const std::map<std::string, std::uint64_t>& decodeErrors() const { return decode_errors_; }
  std::uint64_t decodeErrorsTotal() const;

 private:
  struct Route {
    std::string suffix;
    std::function<void(const Shaft&, const lcm::ReceiveBuffer*, const std::string&)> run;
  };
  void onMessage(const lcm::ReceiveBuffer* rb, const std::string& channel);
  void decodeError(const char* type, hoist::msg::DecodeStatus st, const std::string& channel);

  std::string url_;
  lcm::LCM lcm_;
  hoist::bus::Subscriber rx_{lcm_};  ///< ours for udpm:// (nothing stored per channel name), LCM's otherwise
  LogBudget& log_;
  std::vector<Route> routes_;
  Resolve resolve_;
  std::uint64_t messages_ = 0, ignored_ = 0;
  std::map<std::string, std::uint64_t> decode_errors_;  // "cage_state_t/truncated" -> n
};

}  // namespace hoist::mqtt
