// The bridge's command gate: see command_gate.hpp.
#include "command_gate.hpp"

#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>

#include "hoist/bus/channels.hpp"
#include "hoist/mqtt/sparkplug.hpp"

namespace hoist::mqtt {

CommandGate::CommandGate(const BridgeConfig& cfg, bool sparkplug, const ShaftDirectory& dir, const ShaftData& data,
                         LcmSide& lcm, MqttLink& link, LogBudget& log)
    : cfg_(cfg), sparkplug_(sparkplug), dir_(dir), data_(data), lcm_(lcm), link_(link), log_(log) {}

std::string CommandGate::cmdTopic(const Shaft& s) const {
  return sparkplug_ ? sparkplug::deviceTopic(cfg_.sp_group_id, "DCMD", cfg_.sp_edge_node_id, sparkplug::deviceId(s.name))
                    : s.t.cmd;
}

std::uint64_t CommandGate::commands(const std::string& prefix) const {
  auto it = shafts_.find(prefix);
  return it == shafts_.end() ? 0 : it->second.commands;
}

hoist::rt::TokenBucket* CommandGate::bucket(std::map<std::string, hoist::rt::TokenBucket>& table,
                                             const std::string& key, double rate, double burst, double now) {
  auto it = table.find(key);
  if (it != table.end()) return &it->second;
  if (table.size() >= kMaxUsersPerShaft)
    for (auto u = table.begin(); u != table.end();)  // forget idle users
      u = u->second.full(now) ? table.erase(u) : std::next(u);
  if (table.size() >= kMaxUsersPerShaft) return nullptr;
  return &table.emplace(key, hoist::rt::TokenBucket(rate, burst)).first->second;
}

/// Rate limit ([bridge] command_rate, command_burst).  A per-identity topic:
/// the identity's own bucket.  The legacy topic: per payload user, and 4x
/// that for all of its users together (so many user names gain nothing).
bool CommandGate::rateAllows(const Shaft& s, const std::string& user, const std::string& identity,
                             Clock::time_point now) {
  const double rate = cfg_.command_rate, burst = cfg_.command_burst;
  const double t = log_.sinceStart(now);
  ShaftBudget& b = shafts_.try_emplace(s.prefix, rate, burst).first->second;
  if (!identity.empty()) {
    hoist::rt::TokenBucket* own = bucket(b.identities, identity, rate, burst, t);
    return own && own->take(t);
  }
  hoist::rt::TokenBucket* mine = bucket(b.users, user, rate, burst, t);
  if (!mine) return false;
  hoist::rt::TokenBucket probe = *mine;
  if (!probe.take(t)) {
    *mine = probe;
    return false;
  }
  if (!b.total.take(t)) return false;
  *mine = probe;
  return true;
}

/// The command's answer on hoist/<shaft>/cmd/result (QoS 1, not retained).
void CommandGate::answer(const Shaft& s, const char* result, const char* reason, const std::string& detail,
                         const hoist::alarm_ack_t* ack, const std::string& identity) {
  if (sparkplug_) return;  // Sparkplug has no answer topic: counted (bridge health, NDATA Bridge/Commands ...)
  // Results are budgeted per identity too: 20/s (bursts of 50) each, the
  // legacy topic's together, so a flood is not echoed and costs nobody else.
  const double t = log_.sinceStart(Clock::now());
  hoist::rt::TokenBucket* budget = &result_budget_;
  if (!identity.empty())
    budget = bucket(shafts_.try_emplace(s.prefix, cfg_.command_rate, cfg_.command_burst).first->second.results,
                    identity, 20.0, 50.0, t);
  if (!budget || !budget->take(t)) return void(++n_.results_dropped);
  nlohmann::json j = nlohmann::json::object();
  j["utime"] = hoist::bus::wallUtime();
  j["shaft"] = s.name;
  j["result"] = result;
  j["reason"] = reason;
  j["detail"] = detail;
  if (ack) {
    j["command"] = {{"kind", ack->kind.empty() ? std::string("*") : printable(ack->kind, 32)},
                    {"level", int(ack->level)},
                    {"action", int(ack->action)},
                    {"user", printable(ack->user)},
                    {"utime", ack->utime}};
    if (ack->action == hoist::alarm_ack_t::ACTION_SHELVE) j["command"]["shelve_duration"] = ack->shelve_duration;
    if (ack->action == hoist::alarm_ack_t::ACTION_CALIBRATE) {
      j["command"]["known_fa"] = ack->known_fa;
      j["command"]["known_b"] = ack->known_b;
      j["command"]["calibrate_duration"] = ack->calibrate_duration;
    }
  }
  ++n_.results_published;
  link_.publish({s.t.result, j.dump(), 1, false, MsgClass::Health});
}

void CommandGate::refuse(const Shaft* s, CommandReject why, const std::string& detail, const std::string& topic,
                         int payloadlen, bool may_log, const hoist::alarm_ack_t* ack, const std::string& identity) {
  ++n_.rejected;
  ++n_.by_reason[static_cast<int>(why)];
  if (!s) {
    if (may_log) spdlog::warn("rejected command on {}: {}: {}", topic, toString(why), detail);
    return;
  }
  if (may_log)
    spdlog::warn("rejected command on {} ({} bytes): {}: {}", identity.empty() ? cmdTopic(*s) : printable(topic, 200),
                 payloadlen, toString(why), detail);
  answer(*s, "refused", toString(why), detail, ack, identity);
}

void CommandGate::onMessage(const struct mosquitto_message* m) {
  const std::string topic = m->topic;
  std::string identity;
  const Shaft* sp = dir_.byCommandTopic(topic);
  if (!sp) {  // hoist/<shaft>/cmd/ack/<user>
    const auto slash = topic.rfind('/');
    if (slash == std::string::npos) return;
    sp = dir_.byCommandTopic(topic.substr(0, slash));
    identity = topic.substr(slash + 1);
  }
  if (!sp || !cfg_.commands) return;
  const Shaft& s = *sp;
  if (m->payloadlen == 0) return;  // an empty payload deletes a retained message: nothing to do
  ++n_.received;
  const auto now = Clock::now();
  std::int64_t suppressed = 0;
  const bool may_log = log_.allow(LogBudget::kCmd, now, suppressed);
  if (may_log && suppressed) spdlog::warn("{} command log lines suppressed", suppressed);
  if (m->retain) {
    // A retained command would be executed again on every (re)subscription:
    // never executed; the bridge deletes it from the broker (empty retained message).
    refuse(&s, CommandReject::Retained,
           "retained messages are never executed (publish commands with retain=false); deleting it", m->topic,
           m->payloadlen, may_log, nullptr, identity);
    link_.sendRaw(m->topic, nullptr, 0, 1, true);
    return;
  }
  CommandResult r = parseAckCommand(m->payload, m->payloadlen > 0 ? static_cast<std::size_t>(m->payloadlen) : 0,
                                    static_cast<std::size_t>(cfg_.max_command_bytes), hoist::bus::wallUtime(),
                                    cfg_.max_command_age);
  if (r.reject != CommandReject::None)
    return refuse(&s, r.reject, r.detail, m->topic, m->payloadlen, may_log, nullptr, identity);
  if (!identity.empty()) {
    // The broker vouched for the topic's user: it is the operator's name
    // (a payload naming someone else is refused; one naming nobody gets it).
    if (const std::string why = checkUser(identity); !why.empty())
      return refuse(&s, CommandReject::BadUser, "the topic's user: " + why, m->topic, m->payloadlen, may_log, nullptr,
                    identity);
    if (r.ack.user != identity && r.ack.user != kDefaultCommandUser)
      return refuse(&s, CommandReject::BadUser,
                    fmt::format("the payload's user '{}' is not the topic's '{}'", printable(r.ack.user),
                                printable(identity)),
                    m->topic, m->payloadlen, may_log, &r.ack, identity);
    r.ack.user = identity;
  }
  execute(s, r, m->payloadlen, may_log, now, identity);
}

void CommandGate::execute(const Shaft& s, const CommandResult& r, int payloadlen, bool may_log,
                          Clock::time_point now, const std::string& identity) {
  const hoist::alarm_ack_t* cmd = &r.ack;
  const std::string topic = identity.empty() ? cmdTopic(s) : s.t.cmd + "/" + identity;
  // A rival prefix claiming the same name (discovery) is not bridged and
  // costs nothing here: the command goes to the daemon the name is bound to.
  if (!rateAllows(s, r.ack.user, identity, now))
    return refuse(&s, CommandReject::RateLimited,
                  fmt::format("user '{}' over {} commands/s (burst {}) on shaft '{}'{}", printable(r.ack.user),
                              cfg_.command_rate, cfg_.command_burst, s.name,
                              identity.empty() ? " (the shared topic: its users together at most 4x that)" : ""),
                  topic, payloadlen, may_log, cmd, identity);
  // An acknowledge for no alarm: answered (the daemon would do nothing).
  // Until the daemon has re-announced its active alarms since the shaft was
  // bridged, the bridge's view may be incomplete: forwarded then.
  const bool view_complete = seconds(now - s.bound_since) >= cfg_.alarm_sync_time;
  std::string note;
  if (r.ack.action == hoist::alarm_ack_t::ACTION_ACK && !data_.ackMatches(s.prefix, r.ack)) {
    if (view_complete) {
      ++n_.rejected;
      ++n_.by_reason[static_cast<int>(CommandReject::NoMatchingAlarm)];
      const std::string why = fmt::format("no unacknowledged alarm {} (level {}) on shaft '{}'",
                                          r.ack.kind.empty() || r.ack.kind == "*" ? std::string("of any kind")
                                                                                  : printable(r.ack.kind, 32),
                                          int(r.ack.level), s.name);
      spdlog::info("acknowledge on {} from '{}' matches no alarm: {}", topic, printable(r.ack.user), why);
      return answer(s, "refused", toString(CommandReject::NoMatchingAlarm), why, cmd, identity);
    }
    note = "no matching alarm known yet (the bridge has not yet heard the daemon re-announce its alarms); "
           "forwarded, the daemon decides";
  }
  const std::string channel = hoist::bus::channel(s.prefix, hoist::bus::kChannelAlarmAck);
  if (!lcm_.publishAck(channel, r.ack)) {
    ++n_.lcm_failures;
    if (may_log) spdlog::error("command on {}: LCM publish on {} failed", topic, channel);
    return answer(s, "refused", "lcm_publish_failed", "LCM publish on " + channel + " failed", cmd, identity);
  }
  ++n_.forwarded;
  ++shafts_.try_emplace(s.prefix, cfg_.command_rate, cfg_.command_burst).first->second.commands;
  answer(s, "accepted", "forwarded", note.empty() ? "forwarded to " + channel : note, cmd, identity);
  if (may_log)
    spdlog::info("command on {} from '{}': action {} kind '{}' level {}{} -> {}", topic, printable(r.ack.user),
                 int(r.ack.action), r.ack.kind.empty() ? "*" : printable(r.ack.kind, 32), int(r.ack.level),
                 r.ack.action == hoist::alarm_ack_t::ACTION_SHELVE ? fmt::format(" for {} s", r.ack.shelve_duration)
                 : r.ack.action == hoist::alarm_ack_t::ACTION_CALIBRATE
                     ? fmt::format(" (calibrate: Fa {} N at b {} m for {} s)", r.ack.known_fa, r.ack.known_b,
                                   r.ack.calibrate_duration)
                     : std::string(),
                 channel);
}

}  // namespace hoist::mqtt
