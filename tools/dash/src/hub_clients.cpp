// The hub's client side of the Foxglove WebSocket protocol v1 (Hub's
// members; docs/dashboard.md "Foxglove WebSocket protocol"): a client's text
// ops (subscribe, unsubscribe, advertise, unadvertise) and binary frames
// (client publish), with their errors answered as status messages.  Called
// by the server (server.hpp) on the hub's thread for a Client it owns; the
// rest of the hub is hub.cpp.

#include "hoist/bus/channels.hpp"
#include "hub.hpp"

namespace hoist::dash {

namespace {

bool isUint32(const Json& j) {
  return j.is_number_unsigned() || (j.is_number_integer() && j.get<std::int64_t>() >= 0 &&
                                     j.get<std::int64_t>() <= 0xffffffffLL);
}

}  // namespace

void Hub::status(Client& c, int level, const std::string& msg) {
  c.sendText(std::make_shared<const std::string>(Json{{"op", "status"}, {"level", level}, {"message", msg}}.dump()));
}

void Hub::onClientText(Client& c, std::string_view text) {
  Json j = Json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("op") || !j["op"].is_string()) {
    count("ws_rejected_bad_json");
    status(c, 2, "rejected: a text frame must be a JSON object with a string field \"op\"");
    return;
  }
  const std::string op = j["op"].get<std::string>();
  if (op == "subscribe") handleSubscribe(c, j);
  else if (op == "unsubscribe") handleUnsubscribe(c, j);
  else if (op == "advertise") handleClientAdvertise(c, j);
  else if (op == "unadvertise") handleClientUnadvertise(c, j);
  else if (op == "getParameters" || op == "setParameters" || op == "subscribeParameterUpdates" ||
           op == "unsubscribeParameterUpdates" || op == "subscribeConnectionGraph" ||
           op == "unsubscribeConnectionGraph" || op == "fetchAsset") {
    count("ws_rejected_unsupported_op");
    status(c, 2, "rejected: op \"" + op + "\" is not supported by hoist-dash (capability not announced)");
  } else {
    count("ws_rejected_unknown_op");
    status(c, 2, "rejected: unknown op \"" + op.substr(0, 64) + "\"");
  }
}

void Hub::handleSubscribe(Client& c, const Json& j) {
  const auto subs = j.find("subscriptions");
  if (subs == j.end() || !subs->is_array()) {
    count("ws_rejected_bad_request");
    status(c, 2, "rejected subscribe: \"subscriptions\" must be an array");
    return;
  }
  for (const auto& s : *subs) {
    if (!s.is_object() || !s.contains("id") || !s.contains("channelId") || !isUint32(s["id"]) ||
        !isUint32(s["channelId"])) {
      count("ws_rejected_bad_request");
      status(c, 2, "rejected subscribe: each subscription needs uint32 \"id\" and \"channelId\"");
      continue;
    }
    const auto id = s["id"].get<std::uint32_t>();
    const auto chan = s["channelId"].get<std::uint32_t>();
    const auto ch = by_id_.find(chan);
    if (ch == by_id_.end()) {
      count("ws_rejected_bad_request");
      status(c, 2, "rejected subscribe: unknown channel id " + std::to_string(chan));
      continue;
    }
    if (c.subs_.count(id) || c.by_chan_.count(chan)) {
      count("ws_rejected_bad_request");
      status(c, 2, "rejected subscribe: subscription id " + std::to_string(id) +
                       " or channel " + std::to_string(chan) + " already in use");
      continue;
    }
    if (c.subs_.size() >= 1024) {
      count("ws_rejected_bad_request");
      status(c, 2, "rejected subscribe: too many subscriptions");
      continue;
    }
    c.subs_[id] = chan;
    c.by_chan_[chan] = id;
    count("ws_subscriptions");
    // Low-rate state is sent at once: the latest health/shape, the alarm table.
    if (ch->second->latest) sendTo(c, id, *ch->second->latest);
    if (ch->second->suffix == kHistorySuffix) sendTo(c, id, historyOf(ch->second->prefix));
    for (const auto& [key, p] : ch->second->table) sendTo(c, id, *p);
  }
}

void Hub::handleUnsubscribe(Client& c, const Json& j) {
  const auto ids = j.find("subscriptionIds");
  if (ids == j.end() || !ids->is_array()) {
    count("ws_rejected_bad_request");
    status(c, 2, "rejected unsubscribe: \"subscriptionIds\" must be an array");
    return;
  }
  for (const auto& v : *ids) {
    if (!isUint32(v) || !c.subs_.count(v.get<std::uint32_t>())) {
      count("ws_rejected_bad_request");
      status(c, 1, "unsubscribe: no such subscription " + v.dump().substr(0, 32));
      continue;
    }
    const auto id = v.get<std::uint32_t>();
    c.by_chan_.erase(c.subs_[id]);
    c.subs_.erase(id);
  }
}

void Hub::handleClientAdvertise(Client& c, const Json& j) {
  if (opt_.read_only) {
    count("commands_rejected_read_only");
    status(c, 2, "rejected: hoist-dash runs --read-only; operator commands are disabled");
    return;
  }
  const auto chans = j.find("channels");
  if (chans == j.end() || !chans->is_array()) {
    count("ws_rejected_bad_request");
    status(c, 2, "rejected advertise: \"channels\" must be an array");
    return;
  }
  for (const auto& ch : *chans) {
    if (!ch.is_object() || !ch.contains("id") || !isUint32(ch["id"]) || !ch.contains("topic") ||
        !ch["topic"].is_string() || ch.value("encoding", std::string()) != "json") {
      count("ws_rejected_bad_request");
      status(c, 2, "rejected advertise: each channel needs uint32 \"id\", \"topic\" and encoding \"json\"");
      continue;
    }
    const std::string topic = ch["topic"].get<std::string>();
    const Channel* target = channelFor(topic);
    if (target == nullptr || target->suffix != bus::kChannelAlarmAck) {
      count("commands_rejected_topic");
      status(c, 2, "rejected advertise: clients may publish only on <prefix>HOIST_ALARM_ACK of a known shaft, not \"" +
                       topic.substr(0, 128) + "\"");
      continue;
    }
    if (c.published_.size() >= 64) {
      count("ws_rejected_bad_request");
      status(c, 2, "rejected advertise: too many client channels");
      continue;
    }
    c.published_[ch["id"].get<std::uint32_t>()] = topic;
  }
}

void Hub::handleClientUnadvertise(Client& c, const Json& j) {
  const auto ids = j.find("channelIds");
  if (ids == j.end() || !ids->is_array()) {
    count("ws_rejected_bad_request");
    status(c, 2, "rejected unadvertise: \"channelIds\" must be an array");
    return;
  }
  for (const auto& v : *ids)
    if (isUint32(v)) c.published_.erase(v.get<std::uint32_t>());
}

void Hub::onClientBinary(Client& c, std::string_view bytes) {
  if (bytes.empty() || static_cast<std::uint8_t>(bytes[0]) != 0x01) {
    count("ws_rejected_unknown_binary_op");
    status(c, 2, "rejected: unknown binary opcode (hoist-dash accepts only 0x01 client message data)");
    return;
  }
  if (bytes.size() < 5) {
    count("ws_rejected_bad_request");
    status(c, 2, "rejected: client message data shorter than its 5-byte header");
    return;
  }
  std::uint32_t chan = 0;
  for (int i = 0; i < 4; ++i) chan |= std::uint32_t(static_cast<std::uint8_t>(bytes[1 + i])) << (8 * i);
  handleClientMessage(c, chan, bytes.substr(5));
}

}  // namespace hoist::dash
