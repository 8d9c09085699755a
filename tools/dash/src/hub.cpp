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
#include "hoist/msg/codec.hpp"

namespace hoist::dash {

namespace {

// Suffix of the LCM channel of each hoist type (INTERFACES.md).
const std::vector<std::pair<std::string, std::string>>& typeSuffixes() {
  using namespace hoist::bus;
  static const std::vector<std::pair<std::string, std::string>> v{
      {"hoist.winder_t", std::string(kChannelWinder)},
      {"hoist.cage_state_t", std::string(kChannelCage)},
      {"hoist.guide_shape_t", std::string(kChannelGuideShape)},
      {"hoist.alarm_t", std::string(kChannelAlarm)},
      {"hoist.alarm_ack_t", std::string(kChannelAlarmAck)},
      {"hoist.health_t", std::string(kChannelHealth)},
      // INTERFACES.md "Additions": the forecast's channels, once their types exist.
      {"hoist.forecast_t", "HOIST_FORECAST"},
      {"hoist.trip_plan_t", "HOIST_TRIP_PLAN"},
      // The load estimator's output ([estimator] enabled), at the cage rate.
      {"hoist.estimate_t", std::string(kChannelEstimate)}};
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

bool isUint32(const Json& j) {
  return j.is_number_unsigned() || (j.is_number_integer() && j.get<std::int64_t>() >= 0 &&
                                     j.get<std::int64_t>() <= 0xffffffffLL);
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
  if (kind.empty() || kind.size() > 64) return "kind must have 1..64 characters";
  for (char ch : kind)
    if (!((ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '*'))
      return "kind may contain only A-Z, 0-9, '_' and '*'";
  if (level < 0 || level > 2) return "level must be 0 (both), 1 (WARNING) or 2 (CRITICAL)";
  if (action != alarm_ack_t::ACTION_ACK && action != alarm_ack_t::ACTION_SHELVE &&
      action != alarm_ack_t::ACTION_UNSHELVE)
    return "action must be 1 (ACK), 2 (SHELVE) or 3 (UNSHELVE)";
  if (action == alarm_ack_t::ACTION_SHELVE && !(std::isfinite(shelve_duration) && shelve_duration > 0.0 &&
                                                 shelve_duration <= 1e6))
    return "shelve_duration must be in (0, 1e6] s";
  if (user.empty() || user.size() > 64) return "user must have 1..64 characters (enter your name)";
  for (unsigned char ch : user)
    if (ch < 0x20 || ch == 0x7f) return "user may not contain control characters";
  return "";
}

// ---- MinMaxDecimator -----------------------------------------------------------

void MinMaxDecimator::foldMin(Json& acc, const Json& v) {
  if (acc.is_object() && v.is_object()) {
    for (auto it = acc.begin(); it != acc.end(); ++it) {
      const auto f = v.find(it.key());
      if (f != v.end()) foldMin(it.value(), *f);
    }
  } else if (acc.is_array() && v.is_array() && acc.size() == v.size()) {
    for (std::size_t i = 0; i < acc.size(); ++i) foldMin(acc[i], v[i]);
  } else if (acc.is_number() && v.is_number()) {
    if (v.get<double>() < acc.get<double>()) acc = v;
  } else if (acc.is_boolean() && v.is_boolean()) {
    acc = acc.get<bool>() && v.get<bool>();
  }
}

void MinMaxDecimator::foldMax(Json& acc, const Json& v) {
  if (acc.is_object() && v.is_object()) {
    for (auto it = acc.begin(); it != acc.end(); ++it) {
      const auto f = v.find(it.key());
      if (f != v.end()) foldMax(it.value(), *f);
    }
  } else if (acc.is_array() && v.is_array() && acc.size() == v.size()) {
    for (std::size_t i = 0; i < acc.size(); ++i) foldMax(acc[i], v[i]);
  } else if (acc.is_number() && v.is_number()) {
    if (v.get<double>() > acc.get<double>()) acc = v;
  } else if (acc.is_boolean() && v.is_boolean()) {
    acc = acc.get<bool>() || v.get<bool>();
  }
}

void MinMaxDecimator::add(const Json& sample) {
  if (count_ == 0) {
    // Only numbers and booleans are folded; strings are dropped from min/max.
    Json keep = Json::object();
    if (sample.is_object())
      for (auto it = sample.begin(); it != sample.end(); ++it)
        if (it->is_number() || it->is_boolean() || it->is_array()) keep[it.key()] = *it;
    min_ = max_ = keep;
    first_ = Json{{"t", sample.value("t", 0.0)}, {"utime", sample.value("utime", std::int64_t{0})}};
  } else {
    foldMin(min_, sample);
    foldMax(max_, sample);
  }
  last_ = sample;
  ++count_;
}

Json MinMaxDecimator::take() {
  Json out{{"count", count_}, {"first", first_}, {"last", last_}, {"min", min_}, {"max", max_}};
  count_ = 0;
  first_ = last_ = min_ = max_ = Json();
  return out;
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
    if (suffix == "HOIST_ALARM" && !pending.empty()) {
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
    if (suffix == bus::kChannelEstimate) addDecimated(kEstimateDecimatedSuffix, "hoist_dash.estimate_decimated", "HOIST_ESTIMATE");
    if (suffix == "HOIST_CAGE") {
      addDecimated(kDecimatedSuffix, "hoist_dash.cage_decimated", "HOIST_CAGE");
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
  if (opt_.discover && suffix == "HOIST_HEALTH") onDiscoveryHealth(prefix, j);
  if (suffix == "HOIST_HEALTH" && channelFor(channel) != nullptr) {
    if (!noteInstance(prefix, j)) return;
    maybeRequestAlarmStates(prefix, j);
  }
  if (suffix != "HOIST_HEALTH" && channelFor(channel) != nullptr && !fromFollowedInstance(prefix, suffix, j)) return;
  if (suffix == "HOIST_ALARM" && (channelFor(channel) != nullptr || opt_.discover)) annotateAlarm(prefix, j);
  Channel* ch = channelFor(channel);
  if (ch == nullptr) {
    if (ch == nullptr) {
      // An alarm of a shaft not announced yet (its first HOIST_HEALTH is up
      // to a second away): keep it for the alarm list, bounded.
      if (opt_.discover && suffix == "HOIST_ALARM" &&
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
  if (suffix == "HOIST_HEALTH" || suffix == "HOIST_GUIDE_SHAPE" || suffix == "HOIST_FORECAST" ||
      suffix == "HOIST_TRIP_PLAN")
    ch->latest = payload;  // sent on subscribe (the trip plan: the speed axis's vmax)
  if (suffix == "HOIST_ALARM") {
    const std::string key = j.value("kind", std::string()) + "/" + std::to_string(j.value("level", 0));
    if (ch->table.size() < 64 || ch->table.count(key)) ch->table[key] = payload;
    else count("alarm_table_full");
  }
  if (suffix == "HOIST_CAGE") decimators_[prefix].add(j);
  if (suffix == bus::kChannelEstimate) estimate_decimators_[prefix].add(j);
  broadcast(*ch, payload);
}

const std::vector<std::string>& Hub::historyFields() {
  static const std::vector<std::string> f{"y_c",       "theta",     "lambdas.0",     "lambdas.1",
                                          "lambdas.2", "lambdas.3", "lambdas.4",     "min_clearance",
                                          "v",         "l",         "rope_slack_threshold", "rope_overload_threshold"};
  return f;
}

namespace {
double fieldOf(const Json& m, const std::string& f) {
  const Json* v = nullptr;
  if (f.rfind("lambdas.", 0) == 0) {
    const auto k = static_cast<std::size_t>(f[8] - '0');
    const auto it = m.find("lambdas");
    if (it != m.end() && it->is_array() && k < it->size()) v = &(*it)[k];
  } else if (const auto it = m.find(f); it != m.end()) {
    v = &*it;
  }
  return v != nullptr && v->is_number() ? v->get<double>() : std::nan("");
}
}  // namespace

void Hub::addHistory(const std::string& prefix, const Json& d) {
  if (!d.is_object() || !d.contains("last") || !d["last"].is_object()) return;
  const std::int64_t t0 = d.value("first", Json::object()).value("utime", std::int64_t{0});
  const std::int64_t t1 = d["last"].value("utime", std::int64_t{0});
  if (t1 <= 0) return;
  auto& h = history_[prefix];
  if (!h.empty() && t1 < h.back().last_utime) h.clear();  // a restarted daemon: time went back
  const Json& mn = d.value("count", 0) > 1 ? d["min"] : d["last"];
  const Json& mx = d.value("count", 0) > 1 ? d["max"] : d["last"];
  const auto& fields = historyFields();
  const auto bucket_us = static_cast<std::int64_t>(opt_.history_bucket_s * 1e6);
  if (h.empty() || t1 - h.back().first_utime >= bucket_us) {
    HistBucket b;
    b.first_utime = t0 > 0 ? t0 : t1;
    b.last_utime = t1;
    b.min.resize(fields.size());
    b.max.resize(fields.size());
    for (std::size_t i = 0; i < fields.size(); ++i) {
      b.min[i] = fieldOf(mn, fields[i]);
      b.max[i] = fieldOf(mx, fields[i]);
    }
    h.push_back(std::move(b));
  } else {
    HistBucket& b = h.back();
    b.last_utime = t1;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const double lo = fieldOf(mn, fields[i]), hi = fieldOf(mx, fields[i]);
      if (std::isnan(b.min[i]) || lo < b.min[i]) b.min[i] = lo;
      if (std::isnan(b.max[i]) || hi > b.max[i]) b.max[i] = hi;
    }
  }
  const auto keep_us = static_cast<std::int64_t>(opt_.history_s * 1e6);
  const std::size_t cap = static_cast<std::size_t>(opt_.history_s / std::max(1e-3, opt_.history_bucket_s)) + 16;
  while (!h.empty() && (h.front().last_utime < t1 - keep_us || h.size() > cap)) h.pop_front();
}

std::string Hub::historyOf(const std::string& prefix) const {
  Json out{{"fields", historyFields()}, {"first_utime", Json::array()}, {"last_utime", Json::array()},
           {"min", Json::array()}, {"max", Json::array()}};
  const auto it = history_.find(prefix);
  if (it != history_.end()) {
    auto row = [](const std::vector<double>& v) {
      Json r = Json::array();
      // 6 significant digits (a trend's resolution): half the JSON.
      char buf[32];
      for (double x : v) {
        if (!std::isfinite(x)) {
          r.push_back(nullptr);
          continue;
        }
        std::snprintf(buf, sizeof buf, "%.6g", x);
        r.push_back(std::strtod(buf, nullptr));
      }
      return r;
    };
    for (const auto& b : it->second) {
      out["first_utime"].push_back(b.first_utime);
      out["last_utime"].push_back(b.last_utime);
      out["min"].push_back(row(b.min));
      out["max"].push_back(row(b.max));
    }
  }
  return out.dump();
}

std::string Hub::shaftName(const std::string& prefix) {
  std::string s = prefix;
  if (!s.empty() && (s.back() == '/' || s.back() == '_' || s.back() == '-' || s.back() == '.')) s.pop_back();
  return s.empty() ? std::string("default") : s;
}

void Hub::noteHealth(Evidence& e, std::int64_t instance, std::uint64_t now) const {
  const double gap = e.last_ns == 0 ? 0.0 : static_cast<double>(now - std::min(now, e.last_ns)) * 1e-9;
  if (e.count == 0 || instance != e.instance || gap > opt_.health_gap_s) {
    e.count = 1;  // a new run of evidence
    e.instance = instance;
    if (e.first_ns == 0) e.first_ns = now;
  } else {
    ++e.count;
  }
  e.last_ns = now;
  if (e.instance != 0 && e.count >= opt_.confirm_count) e.confirmed = true;
}

void Hub::onDiscoveryHealth(const std::string& prefix, const Json& health) {
  const std::uint64_t now = clock_();
  const std::int64_t instance = health.value("instance_id", std::int64_t{0});
  if (const auto it = disc_.find(prefix); it != disc_.end()) {
    noteHealth(it->second, instance, now);
    return;
  }
  if (std::find(prefix_list_.begin(), prefix_list_.end(), prefix) != prefix_list_.end()) return;  // fixed
  Evidence& e = refused_[prefix];
  noteHealth(e, instance, now);
  maintainDiscovery();  // free the slots of silent candidates first
  if (prefix_list_.size() >= opt_.max_prefixes) {
    // Real daemons first: the weakest slot (an unconfirmed candidate with less
    // evidence, or a confirmed prefix silent for confirmed_idle_s) gives way
    // to a prefix with more evidence of a daemon behind it.
    std::string weakest;
    const Evidence* w = nullptr;
    for (const auto& [p, d] : disc_) {
      const bool idle = static_cast<double>(now - std::min(now, d.last_ns)) * 1e-9 > opt_.confirmed_idle_s;
      if (d.confirmed && !idle) continue;
      if (w == nullptr || (d.confirmed ? 1 : 0) < (w->confirmed ? 1 : 0) || d.count < w->count ||
          (d.count == w->count && d.last_ns < w->last_ns)) {
        w = &d;
        weakest = p;
      }
    }
    const bool idle_w = w != nullptr && static_cast<double>(now - std::min(now, w->last_ns)) * 1e-9 > opt_.confirmed_idle_s;
    const bool stronger = w != nullptr && e.instance != 0 && (idle_w || (!w->confirmed && e.count > w->count));
    if (!stronger) {
      count("prefix_refused_table_full");
      count("prefix_limit_reached");  // the older counter name
      ++refused_total_;
      last_refusal_ns_ = now;
      last_refused_ = msg::terminalSafe(prefix, 64);
      if (refused_.size() > 256) {  // bounded: forget the stalest
        auto stalest = refused_.begin();
        for (auto it = refused_.begin(); it != refused_.end(); ++it)
          if (it->second.last_ns < stalest->second.last_ns) stalest = it;
        if (stalest->first != prefix) refused_.erase(stalest);
      }
      setStatus("discovery-full", 2,
                "shaft table full (" + std::to_string(opt_.max_prefixes) + " prefixes): HOIST_HEALTH from prefix '" +
                    last_refused_ + "' refused (" + std::to_string(refused_total_) +
                    " refused so far); list the plant's shafts with --channel-prefix");
      return;
    }
    if (logAllowed())
      spdlog::warn("shaft discovery: prefix '{}' ({}) gives way to '{}' (daemon instance {}, {} health messages)",
                 msg::terminalSafe(weakest, 64), w->confirmed ? "silent" : "unconfirmed", msg::terminalSafe(prefix, 64),
                 e.instance, e.count);
    count("prefix_replaced");
    removePrefix(weakest);
  }
  const Evidence got = e;
  refused_.erase(prefix);
  addPrefix(prefix);
  if (std::find(prefix_list_.begin(), prefix_list_.end(), prefix) != prefix_list_.end()) disc_[prefix] = got;
  checkNameClashes();
}

void Hub::maintainDiscovery() {
  if (!opt_.discover) return;
  const std::uint64_t now = clock_();
  std::vector<std::string> gone;
  for (const auto& [p, d] : disc_)
    if (!d.confirmed && static_cast<double>(now - std::min(now, d.last_ns)) * 1e-9 > opt_.candidate_ttl_s)
      gone.push_back(p);
  for (const auto& p : gone) {
    count("prefix_aged_out");
    removePrefix(p);
  }
  if (!gone.empty()) checkNameClashes();
  // Alarms of a prefix whose health never came (a real daemon's follows within
  // a second): forgotten after 30 s, so forged ones cannot hold the room.
  for (auto it = pending_since_.begin(); it != pending_since_.end();) {
    if (static_cast<double>(now - std::min(now, it->second)) * 1e-9 > 30.0) {
      pending_alarms_.erase(it->first);
      it = pending_since_.erase(it);
    } else {
      ++it;
    }
  }
  for (auto it = refused_.begin(); it != refused_.end();)
    it = static_cast<double>(now - std::min(now, it->second.last_ns)) * 1e-9 > 10.0 ? refused_.erase(it) : std::next(it);
  // Statuses whose text changed while throttled: the latest, now.
  for (auto it = status_dirty_.begin(); it != status_dirty_.end();) {
    const auto st = statuses_.find(*it);
    if (st != statuses_.end() && now - std::min(now, status_sent_ns_[*it]) >= 1'000'000'000ULL) {
      status_sent_ns_[*it] = now;
      const auto frame = std::make_shared<const std::string>(st->second.dump());
      for (Client* c : clients_) c->sendText(frame);
      it = status_dirty_.erase(it);
    } else if (st == statuses_.end()) {
      it = status_dirty_.erase(it);
    } else {
      ++it;
    }
  }
  // The table-full status lasts while refusals keep coming (10 s).
  if (statuses_.count("discovery-full") && static_cast<double>(now - std::min(now, last_refusal_ns_)) * 1e-9 > 10.0)
    clearStatus("discovery-full");
}

void Hub::checkNameClashes() {
  std::map<std::string, std::vector<std::string>> by_name;
  for (const auto& p : prefix_list_) by_name[shaftName(p)].push_back(p);
  std::set<std::string> live;
  for (const auto& [name, ps] : by_name) {
    if (ps.size() < 2) continue;
    const std::string id = "discovery-clash:" + name;
    live.insert(id);
    std::string list;
    for (const auto& p : ps) list += (list.empty() ? "'" : ", '") + msg::terminalSafe(p, 64) + "'";
    const std::string text = "prefixes " + list + " all give the shaft name '" + msg::terminalSafe(name, 64) +
                             "': one of them may be forged; check which daemon is real and list the plant's shafts "
                             "with --channel-prefix";
    if (!statuses_.count(id) || statuses_[id]["message"] != text) {
      count("prefix_name_clash");
      if (logAllowed()) spdlog::warn("shaft discovery: {}", text);
      setStatus(id, 2, text);
    }
  }
  std::vector<std::string> old;
  for (const auto& [id, st] : statuses_)
    if (id.rfind("discovery-clash:", 0) == 0 && !live.count(id)) old.push_back(id);
  for (const auto& id : old) clearStatus(id);
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
    if (target == nullptr || target->suffix != "HOIST_ALARM_ACK") {
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
