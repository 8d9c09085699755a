// Foxglove WebSocket protocol v1 over the hoist LCM channels (see hub.hpp).
#include "hub.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <optional>

#include <spdlog/spdlog.h>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/contract/alarm_command.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/msg/names.hpp"

namespace hoist::dash {

namespace {

// The hoist types hoist-dash relays, and their channel suffixes from the
// `// @channel` of msgs/*.lcm (hoist/msg/names.hpp, generated: no name is
// spelled here).  The sensors' raw inputs (cage_imu_t, rope_load_t) are not
// relayed: the page shows the load estimate made from them.
const std::vector<std::pair<std::string, std::string>>& typeSuffixes() {
  static const std::vector<std::pair<std::string, std::string>> v = [] {
    constexpr std::string_view kRelayed[] = {"hoist.winder_t", "hoist.cage_state_t", "hoist.guide_shape_t",
                                             "hoist.alarm_t",  "hoist.alarm_ack_t",  "hoist.health_t",
                                             "hoist.forecast_t", "hoist.trip_plan_t", "hoist.estimate_t"};
    std::vector<std::pair<std::string, std::string>> out;
    for (const msg::ChannelInfo& c : msg::kChannels)
      if (std::find(std::begin(kRelayed), std::end(kRelayed), c.type) != std::end(kRelayed))
        out.emplace_back(std::string(c.type), std::string(c.channel));
    return out;
  }();
  return v;
}

bool endsWith(const std::string& s, const std::string& suf) {
  return s.size() >= suf.size() && s.compare(s.size() - suf.size(), suf.size(), suf) == 0;
}

template <class S>
std::string schemaText(const S& s) {
  if constexpr (std::is_same_v<std::decay_t<S>, Json>) return s.dump();
  else return std::string(s);
}

std::string frameHeader(std::uint8_t op, std::uint32_t id, std::uint64_t ns) {
  std::string h(13, '\0');
  h[0] = static_cast<char>(op);
  for (int i = 0; i < 4; ++i) h[1 + i] = static_cast<char>((id >> (8 * i)) & 0xff);
  for (int i = 0; i < 8; ++i) h[5 + i] = static_cast<char>((ns >> (8 * i)) & 0xff);
  return h;
}

}  // namespace

std::string channelSuffixOfType(const std::string& type_name) {
  for (const auto& [t, s] : typeSuffixes())
    if (t == type_name) return s;
  return "";
}

std::string hoistSuffixOf(const std::string& channel) {
  std::string best;
  for (const auto& [t, s] : typeSuffixes())
    if (endsWith(channel, s) && s.size() > best.size()) best = s;
  return best;
}

std::string validateAckFields(const std::string& kind, int level, int action, double shelve_duration,
                              const std::string& user) {
  // The page's policy: a kind named ("*" for all), the three alarm actions
  // of an operator at the list, a shelve of at most 1e6 s ...
  if (kind.empty()) return "kind must name an alarm kind, or '*' for all";
  if (action != alarm_ack_t::ACTION_ACK && action != alarm_ack_t::ACTION_SHELVE &&
      action != alarm_ack_t::ACTION_UNSHELVE)
    return "action must be 1 (ACK), 2 (SHELVE) or 3 (UNSHELVE)";
  if (action == alarm_ack_t::ACTION_SHELVE && !(shelve_duration <= 1e6)) return "shelve_duration must be in (0, 1e6] s";
  // ... on top of the daemon's own rule (hoist::contract, as hoist-mqtt), so
  // the page never forwards a command the daemon would refuse.
  contract::AlarmCommand cmd;
  switch (contract::validateAlarmCommand(kind, level, action, shelve_duration, cmd)) {
    case contract::CommandError::None: break;
    case contract::CommandError::UnknownKind:
      return "kind must name an alarm kind, or '*' for all (\"" + contract::printable(kind) + "\" is none)";
    case contract::CommandError::BadLevel: return "level must be 0 (both), 1 (WARNING) or 2 (CRITICAL)";
    case contract::CommandError::BadShelveDuration: return "shelve_duration must be in (0, 1e6] s";
    case contract::CommandError::BadAction:
    case contract::CommandError::BadCalibration:
    case contract::CommandError::BadPreload: return "action must be 1 (ACK), 2 (SHELVE) or 3 (UNSHELVE)";
  }
  return validateCommandUser(user);
}

std::string validateCommandUser(const std::string& user) {
  // The contract's one rule (hoist-mqtt applies the same).
  const char* why = contract::operatorNameProblem(user);
  if (!why) return "";
  return user.empty() || user.size() > contract::kMaxOperatorName ? std::string(why) + " (enter your name)" : why;
}

// ---- Hub ------------------------------------------------------------------------

Hub::Hub(Options opt, Publisher publish, Clock clock)
    : opt_(std::move(opt)), publish_(std::move(publish)), clock_(std::move(clock)) {
  session_id_ = std::to_string(clock_());
  for (const auto& p : opt_.prefixes) addPrefix(p);
}

std::uint64_t Hub::counter(const std::string& what) const {
  const auto it = counters_.find(what);
  return it == counters_.end() ? 0 : it->second;
}

Json Hub::stats() const {
  Json c = Json::object();
  for (const auto& [k, v] : counters_) c[k] = v;
  Json disc{{"enabled", opt_.discover}, {"slots", prefix_list_.size()}, {"max", opt_.max_prefixes},
            {"table_full", prefix_list_.size() >= opt_.max_prefixes}, {"refused_total", refused_total_},
            {"last_refused", last_refused_}, {"candidates", Json::array()}, {"confirmed", Json::array()},
            {"status", Json::array()}};
  for (const auto& [p, e] : disc_) disc[e.confirmed ? "confirmed" : "candidates"].push_back(p);
  for (const auto& [id, st] : statuses_) disc["status"].push_back(st);
  return Json{{"clients", clients_.size()}, {"prefixes", prefix_list_}, {"read_only", opt_.read_only},
              {"channels", channels_.size()}, {"counters", c}, {"discovery", disc}};
}

void Hub::addPrefix(const std::string& prefix) {
  if (std::find(prefix_list_.begin(), prefix_list_.end(), prefix) != prefix_list_.end()) return;
  if (prefix_list_.size() >= opt_.max_prefixes) {
    count("prefix_limit_reached");
    return;
  }
  prefix_list_.push_back(prefix);
  std::vector<const Channel*> added;
  auto pending = pending_alarms_.extract(prefix);
  pending_since_.erase(prefix);
  for (const auto& t : msg::allTypes()) {
    const std::string suffix = channelSuffixOfType(t.name);
    if (suffix.empty()) continue;
    Channel ch;
    ch.id = next_id_++;
    ch.topic = prefix + suffix;
    ch.prefix = prefix;
    ch.suffix = suffix;
    ch.schema_name = t.name;
    ch.schema = schemaText(t.schema);
    auto& stored = channels_[ch.topic] = std::move(ch);
    by_id_[stored.id] = &stored;
    if (suffix == bus::kChannelAlarm && !pending.empty()) {
      // Kept from before the shaft was confirmed: only the confirmed daemon
      // instance's alarm events (issue 33).
      const auto d = disc_.find(prefix);
      for (auto& [key, a] : pending.mapped()) {
        const Json j = Json::parse(*a, nullptr, false);
        if (d == disc_.end() || (j.is_object() && j.value("instance_id", std::int64_t{0}) == d->second.instance))
          stored.table[key] = a;
        else
          count("HOIST_ALARM_foreign_instance");
      }
    }
    added.push_back(&stored);
    // The decimated channels (cage state, load estimate): min/max of every
    // numeric field per interval, at the display rate.
    auto addDecimated = [&](const char* dsuffix, const std::string& name, const std::string& what) {
      Json last_schema = Json::parse(stored.schema, nullptr, false);
      Channel d;
      d.id = next_id_++;
      d.topic = prefix + dsuffix;
      d.prefix = prefix;
      d.suffix = dsuffix;
      d.schema_name = name;
      d.schema = Json{{"type", "object"},
                      {"title", name},
                      {"description",
                       what + " decimated by hoist-dash to the display rate: per interval the message count, "
                       "the first message's t and utime, the last message whole, and the smallest and largest "
                       "value of every numeric field (booleans: AND in min, OR in max)"},
                      {"properties",
                       {{"count", {{"type", "integer"}}},
                        {"first", {{"type", "object"}}},
                        {"last", last_schema},
                        {"min", {{"type", "object"}}},
                        {"max", {{"type", "object"}}}}}}
                     .dump();
      auto& sd = channels_[d.topic] = std::move(d);
      by_id_[sd.id] = &sd;
      added.push_back(&sd);
    };
    if (suffix == bus::kChannelEstimate) addDecimated(kEstimateDecimatedSuffix, "hoist_dash.estimate_decimated", std::string(bus::kChannelEstimate));
    if (suffix == bus::kChannelCage) {
      addDecimated(kDecimatedSuffix, "hoist_dash.cage_decimated", std::string(bus::kChannelCage));
      // The trend history: sent whole on subscribe, then nothing (the
      // decimated channel carries the rest).
      Channel hc;
      hc.id = next_id_++;
      hc.topic = prefix + kHistorySuffix;
      hc.prefix = prefix;
      hc.suffix = kHistorySuffix;
      hc.schema_name = "hoist_dash.cage_history";
      hc.schema = Json{{"type", "object"},
                       {"title", "hoist_dash.cage_history"},
                       {"description",
                        "The recent HOIST_CAGE history kept by hoist-dash (up to its history window), sent once on "
                        "subscribe: per bucket the first and last utime and the smallest and largest value of each "
                        "field in `fields` (rows of `min` and `max` in that order; null = not a number)"},
                       {"properties",
                        {{"fields", {{"type", "array"}, {"items", {{"type", "string"}}}}},
                         {"first_utime", {{"type", "array"}, {"items", {{"type", "integer"}}}}},
                         {"last_utime", {{"type", "array"}, {"items", {{"type", "integer"}}}}},
                         {"min", {{"type", "array"}}},
                         {"max", {{"type", "array"}}}}}}
                      .dump();
      auto& sh = channels_[hc.topic] = std::move(hc);
      by_id_[sh.id] = &sh;
      added.push_back(&sh);
    }
  }
  const auto adv = std::make_shared<const std::string>(advertiseOf(added).dump());
  for (Client* c : clients_) c->sendText(adv);
}

Hub::Channel* Hub::channelFor(const std::string& topic) {
  const auto it = channels_.find(topic);
  return it == channels_.end() ? nullptr : &it->second;
}

Json Hub::advertiseOf(const std::vector<const Channel*>& chans) const {
  Json arr = Json::array();
  for (const Channel* ch : chans)
    arr.push_back({{"id", ch->id},
                   {"topic", ch->topic},
                   {"encoding", "json"},
                   {"schemaName", ch->schema_name},
                   {"schema", ch->schema},
                   {"schemaEncoding", "jsonschema"}});
  return Json{{"op", "advertise"}, {"channels", arr}};
}

void Hub::addClient(Client& c) {
  clients_.insert(&c);
  count("ws_clients_accepted");
  Json caps = Json::array();
  Json info{{"op", "serverInfo"}, {"name", "hoist-dash"}, {"sessionId", session_id_}};
  if (!opt_.read_only) {
    caps.push_back("clientPublish");
    info["supportedEncodings"] = Json::array({"json"});
  }
  info["capabilities"] = caps;
  info["metadata"] = Json{{"read_only", opt_.read_only ? "true" : "false"},
                          {"shafts", opt_.shaft_meta.dump()},
                          {"decimated_suffix", kDecimatedSuffix}};
  c.sendText(std::make_shared<const std::string>(info.dump()));
  std::vector<const Channel*> all;
  for (const auto& [topic, ch] : channels_) all.push_back(&ch);
  std::sort(all.begin(), all.end(), [](const Channel* a, const Channel* b) { return a->id < b->id; });
  c.sendText(std::make_shared<const std::string>(advertiseOf(all).dump()));
  for (const auto& [id, st] : statuses_) c.sendText(std::make_shared<const std::string>(st.dump()));
}

void Hub::removeClient(Client& c) { clients_.erase(&c); }

void Hub::sendTo(Client& c, std::uint32_t sub_id, const std::string& payload) {
  auto frame = std::make_shared<std::string>(frameHeader(0x01, sub_id, clock_()));
  frame->append(payload);
  c.sendData(std::move(frame));
}

void Hub::broadcast(Channel& ch, const std::shared_ptr<const std::string>& payload) {
  for (Client* c : clients_) {
    const auto it = c->by_chan_.find(ch.id);
    if (it != c->by_chan_.end()) sendTo(*c, it->second, *payload);
  }
}

void Hub::onLcm(const std::string& channel, const void* data, std::size_t size) {
  count("lcm_messages");
  if (size > opt_.max_lcm_bytes) {
    count("lcm_rejected_oversized");
    return;
  }
  const std::string suffix = hoistSuffixOf(channel);
  if (suffix.empty()) {
    count("lcm_ignored_channel");
    return;
  }
  const msg::TypeInfo* type = msg::findByFingerprint(data, size);
  if (type == nullptr) {
    count("lcm_rejected_unknown_type");
    return;
  }
  if (channelSuffixOfType(type->name) != suffix) {
    count("lcm_rejected_wrong_type");
    return;
  }
  Json j;
  msg::DecodeStatus st{};
  bool ok = false;
  try {
    ok = type->bytesToJson(data, size, j, st);
  } catch (...) {
    ok = false;
  }
  if (!ok) {
    count(std::string("lcm_rejected_decode_") + msg::toString(st));
    return;
  }
  const std::string prefix = channel.substr(0, channel.size() - suffix.size());
  if (opt_.discover && suffix == bus::kChannelHealth) onDiscoveryHealth(prefix, j);
  if (suffix == bus::kChannelHealth && channelFor(channel) != nullptr) {
    if (!noteInstance(prefix, j)) return;
    maybeRequestAlarmStates(prefix, j);
  }
  if (suffix != bus::kChannelHealth && channelFor(channel) != nullptr && !fromFollowedInstance(prefix, suffix, j)) return;
  if (suffix == bus::kChannelAlarm && (channelFor(channel) != nullptr || opt_.discover)) annotateAlarm(prefix, j);
  Channel* ch = channelFor(channel);
  if (ch == nullptr) {
    if (ch == nullptr) {
      // An alarm of a shaft not announced yet (its first HOIST_HEALTH is up
      // to a second away): keep it for the alarm list, bounded.
      if (opt_.discover && suffix == bus::kChannelAlarm &&
          (pending_alarms_.count(prefix) || pending_alarms_.size() < opt_.max_prefixes)) {
        pending_since_.emplace(prefix, clock_());
        auto& t = pending_alarms_[prefix];
        const std::string key = j.value("kind", std::string()) + "/" + std::to_string(j.value("level", 0));
        if (t.size() < 64 || t.count(key)) t[key] = std::make_shared<const std::string>(j.dump());
      }
      count("lcm_ignored_prefix");
      return;
    }
  }
  count("lcm_decoded");
  const auto payload = std::make_shared<const std::string>(j.dump());
  if (suffix == bus::kChannelHealth || suffix == bus::kChannelGuideShape || suffix == bus::kChannelForecast ||
      suffix == bus::kChannelTripPlan)
    ch->latest = payload;  // sent on subscribe (the trip plan: the speed axis's vmax)
  if (suffix == bus::kChannelAlarm) {
    const std::string key = j.value("kind", std::string()) + "/" + std::to_string(j.value("level", 0));
    if (ch->table.size() < 64 || ch->table.count(key)) ch->table[key] = payload;
    else count("alarm_table_full");
  }
  if (suffix == bus::kChannelCage) decimators_[prefix].add(j);
  if (suffix == bus::kChannelEstimate) estimate_decimators_[prefix].add(j);
  broadcast(*ch, payload);
}

bool Hub::logAllowed() {
  const std::uint64_t now = clock_();
  if (now - std::min(now, log_window_ns_) > 10'000'000'000ULL) {
    log_window_ns_ = now;
    log_lines_ = 0;
  }
  return ++log_lines_ <= 10;
}

void Hub::setStatus(const std::string& id, int level, const std::string& text) {
  Json st{{"op", "status"}, {"level", level}, {"message", text}, {"id", id}};
  const bool same = statuses_.count(id) && statuses_[id] == st;
  if (!statuses_.count(id) && spdlog::should_log(spdlog::level::warn) && id == "discovery-full")
    spdlog::warn("shaft discovery: {}", text);
  const bool fresh = !statuses_.count(id);
  statuses_[id] = st;
  if (same) return;
  // A flood of refusals updates the text, but clients get it at most once a
  // second (control frames are not droppable: a flood must not fill queues).
  const std::uint64_t now = clock_();
  auto& sent = status_sent_ns_[id];
  if (!fresh && now - std::min(now, sent) < 1'000'000'000ULL) {
    status_dirty_.insert(id);
    return;
  }
  sent = now;
  status_dirty_.erase(id);
  const auto frame = std::make_shared<const std::string>(st.dump());
  for (Client* c : clients_) c->sendText(frame);
}

void Hub::clearStatus(const std::string& id) {
  if (statuses_.erase(id) == 0) return;
  status_sent_ns_.erase(id);
  status_dirty_.erase(id);
  if (id == "discovery-full") spdlog::info("shaft discovery: the table has room again");
  const auto frame = std::make_shared<const std::string>(Json{{"op", "removeStatus"}, {"statusIds", {id}}}.dump());
  for (Client* c : clients_) c->sendText(frame);
}

void Hub::removePrefix(const std::string& prefix) {
  const auto pit = std::find(prefix_list_.begin(), prefix_list_.end(), prefix);
  if (pit == prefix_list_.end()) return;
  prefix_list_.erase(pit);
  disc_.erase(prefix);
  states_asked_.erase(prefix);
  instance_.erase(prefix);
  instance_last_ns_.erase(prefix);
  decimators_.erase(prefix);
  estimate_decimators_.erase(prefix);
  history_.erase(prefix);
  for (auto it = alarm_ids_.begin(); it != alarm_ids_.end();)
    it = it->first.compare(0, prefix.size() + 1, prefix + "\n") == 0 ? alarm_ids_.erase(it) : std::next(it);
  Json ids = Json::array();
  for (auto it = channels_.begin(); it != channels_.end();) {
    if (it->second.prefix != prefix) {
      ++it;
      continue;
    }
    const std::uint32_t id = it->second.id;
    ids.push_back(id);
    for (Client* c : clients_) {
      if (const auto s = c->by_chan_.find(id); s != c->by_chan_.end()) {
        c->subs_.erase(s->second);
        c->by_chan_.erase(s);
      }
      for (auto p = c->published_.begin(); p != c->published_.end();)
        p = p->second == it->first ? c->published_.erase(p) : std::next(p);
    }
    by_id_.erase(id);
    it = channels_.erase(it);
  }
  const auto frame = std::make_shared<const std::string>(Json{{"op", "unadvertise"}, {"channelIds", ids}}.dump());
  for (Client* c : clients_) c->sendText(frame);
}

void Hub::flushDecimated() {
  if (opt_.discover) {
    const std::uint64_t now = clock_();
    if (now - std::min(now, last_maintain_ns_) >= 500'000'000ULL) {
      last_maintain_ns_ = now;
      maintainDiscovery();
    }
  }
  for (auto& [prefix, dec] : decimators_) {
    if (dec.empty()) continue;
    const Json d = dec.take();
    addHistory(prefix, d);
    const auto payload = std::make_shared<const std::string>(d.dump());
    if (Channel* ch = channelFor(prefix + kDecimatedSuffix)) broadcast(*ch, payload);
  }
  for (auto& [prefix, dec] : estimate_decimators_) {
    if (dec.empty()) continue;
    const auto payload = std::make_shared<const std::string>(dec.take().dump());
    if (Channel* ch = channelFor(prefix + kEstimateDecimatedSuffix)) broadcast(*ch, payload);
  }
}

}  // namespace hoist::dash
