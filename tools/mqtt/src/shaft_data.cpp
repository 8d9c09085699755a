// The bridge's data path: see shaft_data.hpp.
#include "shaft_data.hpp"

#include <spdlog/spdlog.h>

#include "hoist/mqtt/command.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/msg/codec.hpp"
#include "sparkplug_session.hpp"

namespace hoist::mqtt {

namespace {

using json = nlohmann::json;

/// The names of alarm_t's levels and events (generated from alarm_t.lcm).
namespace alarm_names = hoist::msg::enums::alarm_t;

/// The kind's summary: level = the highest active, unshelved level.
struct Summary {
  int level = 0;
  bool unacked = false, shelved = false;
};
Summary summarize(const AlarmState& a) {
  Summary out;
  for (int lv = 1; lv <= 2; ++lv) {
    const auto& e = a.by_level[lv];
    if (!e) continue;
    if (e->active && !e->shelved) out.level = lv;
    out.unacked = out.unacked || (e->active && !e->acked && !e->shelved);
    out.shelved = out.shelved || e->shelved;
  }
  return out;
}

}  // namespace

bool ShaftData::validKind(const std::string& k) {
  if (k.empty() || k.size() > 32) return false;
  for (char c : k)
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return false;
  return true;
}

ShaftData::ShaftData(const BridgeConfig& cfg, MqttLink& link, LogBudget& log) : cfg_(cfg), link_(link), log_(log) {}

const ShaftData::Feed* ShaftData::find(const std::string& prefix) const {
  auto it = feeds_.find(prefix);
  return it == feeds_.end() ? nullptr : &it->second;
}

void ShaftData::onCage(const Shaft& s, const hoist::cage_state_t& m) {
  Feed& f = feed(s);
  f.cage = m;
  f.cage_new = s.bound;
  ++f.cage_in;
}

void ShaftData::onEstimate(const Shaft& s, const hoist::estimate_t& m) {
  // The load estimate, at the cage rate; sent like the cage state (the
  // latest one at [bridge] cage_rate, QoS 0, not retained).
  Feed& f = feed(s);
  f.estimate = m;
  f.estimate_new = s.bound;
  ++f.estimates_in;
}

void ShaftData::onForecast(const Shaft& s, const hoist::forecast_t& m) {
  // The look-ahead forecast, as JSON (nested scenarios), at the daemon's
  // rate (~1 Hz); queued like health (low rate).
  ++feed(s).forecasts_in;
  if (s.bound && sp_) {
    sp_->metrics(s.name).onForecast(m);
    sp_->sendData(s.name, sparkplug::Source::Forecast, MsgClass::Health);
  } else if (s.bound) {
    link_.publish({s.t.forecast, hoist::msg::toJson(m).dump(), 0, false, MsgClass::Health});
  }
}

void ShaftData::onHealth(const Shaft& s, const hoist::health_t& m, bool restarted) {
  Feed& f = feed(s);
  if (restarted) daemonRestarted(s, f, m);
  if (sp_) {
    sp_->metrics(s.name).onHealth(m);
    return sp_->sendData(s.name, sparkplug::Source::Health, MsgClass::Health);
  }
  link_.publish({s.t.health, hoist::msg::toJson(m).dump(), 0, false, MsgClass::Health});
}

bool ShaftData::admit(const Shaft& s, std::int64_t instance, const char* channel, bool strict) {
  if (ShaftDirectory::fromBoundInstance(s, instance)) return true;
  if (!strict && s.instance_id == 0) return true;  // no health yet: the daemon is the only one heard
  const std::uint64_t n = ++foreign_[channel];
  std::int64_t suppressed = 0;
  if (log_.allow(LogBudget::kLcm, Clock::now(), suppressed))
    spdlog::warn("shaft '{}': dropped {} of daemon instance {} on {}{}: the shaft follows instance {} ({} dropped "
                 "on it so far) [{} similar suppressed]",
                 printable(s.name, 64), channel, instance, printable(s.prefix, 64), channel,
                 s.instance_id == 0 ? std::string("(none heard yet)") : std::to_string(s.instance_id), n, suppressed);
  return false;
}

void ShaftData::onAlarm(const Shaft& s, const hoist::alarm_t& m) {
  // Only the daemon whose health this shaft follows changes what SCADA sees
  // (issue 33: one forged CLEAR turned the retained alarm inactive).
  if (!admit(s, m.instance_id, hoist::bus::kChannelAlarm.data(), true)) return;
  if (!validKind(m.kind) || m.level < 1 || m.level > 2) {
    ++alarm_rejected_;
    std::int64_t suppressed = 0;
    if (log_.allow(LogBudget::kLcm, Clock::now(), suppressed))
      spdlog::warn("ignored alarm on shaft '{}' with kind '{}' level {} (kind must be [A-Z0-9_]{{1,32}}, level 1 or 2)",
                   s.name, printable(m.kind, 32), int(m.level));
    return;
  }
  Feed& f = feed(s);
  auto it = f.alarms.find(m.kind);
  if (it == f.alarms.end()) {
    if (static_cast<int>(f.alarms.size()) >= kMaxKindsPerShaft) return void(++alarm_rejected_);
    it = f.alarms.emplace(m.kind, AlarmState{}).first;
  }
  it->second.by_level[m.level] = m;
  it->second.last = m;
  ++f.alarms_in;
  if (s.bound) publishAlarmState(s, it->first, it->second);
}

/// A new daemon process: alarm states from before its start are void (the
/// new daemon announces what is active from its own start).
void ShaftData::daemonRestarted(const Shaft& s, Feed& f, const hoist::health_t& h) {
  const std::int64_t start = h.utime - static_cast<std::int64_t>(h.uptime * 1e6);
  spdlog::info("shaft '{}': new daemon instance; alarm states from before its start are cleared", s.name);
  for (auto& [kind, a] : f.alarms) {
    bool changed = false;
    for (auto& lv : a.by_level)
      if (lv && lv->utime < start && (lv->active || lv->shelved)) {
        lv->active = lv->acked = lv->shelved = lv->latched = false;
        lv->event_type = hoist::alarm_t::EVENT_CLEAR;
        lv->message = "cleared by hoist-mqtt: the daemon restarted";
        changed = true;
      }
    if (changed) publishAlarmState(s, kind, a);
  }
}

void ShaftData::bound(const Shaft& s) {
  Feed& f = feed(s);
  if (sp_) {
    sp_->metrics(s.name);  // the device exists from now on (alias block, DBIRTH)
    for (const auto& [kind, a] : f.alarms) setAlarmMetrics(s, kind, a);
    return;
  }
  for (const auto& [kind, a] : f.alarms) publishAlarmState(s, kind, a);
}

json ShaftData::alarmStateJson(const Shaft& s, const std::string& kind, const AlarmState& a) const {
  const Summary sum = summarize(a);
  json j = json::object();
  j["shaft"] = s.name;
  j["kind"] = kind;
  j["active"] = sum.level > 0;
  j["level"] = std::string(alarm_names::levelName(sum.level));
  j["unacked"] = sum.unacked;
  j["shelved"] = sum.shelved;
  j["utime"] = a.last.utime;
  j["last_event"] = std::string(alarm_names::eventName(a.last.event_type));
  j["warning"] = a.by_level[1] ? hoist::msg::toJson(*a.by_level[1]) : json(nullptr);
  j["critical"] = a.by_level[2] ? hoist::msg::toJson(*a.by_level[2]) : json(nullptr);
  return j;
}

void ShaftData::publishAlarmState(const Shaft& s, const std::string& kind, const AlarmState& a) {
  if (sp_) {
    setAlarmMetrics(s, kind, a);
    return sp_->sendData(s.name, sparkplug::Source::Alarm, MsgClass::Alarm);
  }
  link_.publish({s.t.alarm + kind, alarmStateJson(s, kind, a).dump(), 1, true, MsgClass::Alarm});
}

/// The kind's state as the JSON mode's alarm topic gives it: acked = active
/// and nothing unacknowledged.
void ShaftData::setAlarmMetrics(const Shaft& s, const std::string& kind, const AlarmState& a) {
  const Summary sum = summarize(a);
  sp_->metrics(s.name).setAlarm(kind, sum.level, sum.level > 0, sum.level > 0 && !sum.unacked, sum.shelved,
                                a.last.utime);
}

void ShaftData::publishCages(const ShaftDirectory& dir) {
  for (const auto& [p, s] : dir.all()) {
    auto it = feeds_.find(p);
    if (it == feeds_.end() || !it->second.cage_new || !s.bound) continue;
    Feed& f = it->second;
    f.cage_new = false;
    ++f.cage_out;
    if (sp_) {
      sp_->metrics(s.name).onCage(f.cage);
      sp_->sendData(s.name, sparkplug::Source::Cage, MsgClass::Cage);
      continue;
    }
    link_.publish({s.t.cage, hoist::msg::toJson(f.cage).dump(), 0, false, MsgClass::Cage});
  }
  for (const auto& [p, s] : dir.all()) {
    auto it = feeds_.find(p);
    if (it == feeds_.end() || !it->second.estimate_new || !s.bound) continue;
    Feed& f = it->second;
    f.estimate_new = false;
    ++f.estimates_out;
    if (sp_) {
      sp_->metrics(s.name).onEstimate(f.estimate);
      sp_->sendData(s.name, sparkplug::Source::Estimate, MsgClass::Cage);
      continue;
    }
    link_.publish({s.t.estimate, hoist::msg::toJson(f.estimate).dump(), 0, false, MsgClass::Cage});
  }
}

void ShaftData::republishAlarms(const ShaftDirectory& dir, bool journal_lost) {
  for (const auto& [p, s] : dir.all()) {
    auto it = feeds_.find(p);
    if (!s.bound || it == feeds_.end()) continue;
    for (const auto& [kind, a] : it->second.alarms)
      if (journal_lost || !link_.journaledAlarm(s.t.alarm + kind)) publishAlarmState(s, kind, a);
  }
}

void ShaftData::settleAlarms(const ShaftDirectory& dir, Clock::time_point now) {
  for (const auto& [p, s] : dir.all()) {
    if (!s.bound || seconds(now - s.bound_since) < cfg_.alarm_sync_time) continue;
    Feed& f = feed(s);
    if (f.alarms_settled) continue;
    f.alarms_settled = true;
    sp_->metrics(s.name).alarmsSettled(hoist::bus::wallUtime());
    sp_->sendData(s.name, sparkplug::Source::Alarm, MsgClass::Alarm);
  }
}

bool ShaftData::ackMatches(const std::string& prefix, const hoist::alarm_ack_t& ack) const {
  const Feed* f = find(prefix);
  if (!f) return false;
  const bool any_kind = ack.kind.empty() || ack.kind == "*";
  for (const auto& [kind, a] : f->alarms) {
    if (!any_kind && kind != ack.kind) continue;
    for (int lv = 1; lv <= 2; ++lv)
      // Active or returned to normal (RTN UNACK): not yet acknowledged.
      if ((ack.level == 0 || ack.level == lv) && a.by_level[lv] && !a.by_level[lv]->acked)
        return true;
  }
  return false;
}

int ShaftData::activeAlarms(const std::string& prefix) const {
  const Feed* f = find(prefix);
  int active = 0;
  if (f)
    for (const auto& [k, a] : f->alarms)
      for (const auto& lv : a.by_level) active += lv && lv->active ? 1 : 0;
  return active;
}

}  // namespace hoist::mqtt
