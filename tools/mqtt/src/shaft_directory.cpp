// The bridge's shaft directory: see shaft_directory.hpp.
#include "shaft_directory.hpp"

#include <spdlog/spdlog.h>

#include "hoist/mqtt/command.hpp"

namespace hoist::mqtt {

ShaftDirectory::ShaftDirectory(const BridgeConfig& cfg, LogBudget& log, Events& events)
    : cfg_(cfg), log_(log), events_(events), discover_(cfg.channel_prefixes.empty()) {}

void ShaftDirectory::addConfigured() {
  for (const auto& p : cfg_.channel_prefixes) add(p, true);
}

Shaft* ShaftDirectory::add(const std::string& prefix, bool configured) {
  Shaft s;
  s.prefix = prefix;
  s.name = shaftName(prefix);
  const std::string base = "hoist/" + s.name + "/";
  s.t.cage = base + "cage";
  s.t.health = base + "health";
  s.t.alarm = base + "alarm/";
  s.t.cmd = base + "cmd/ack";
  s.t.result = base + "cmd/result";
  s.t.forecast = base + "forecast";
  s.t.estimate = base + "estimate";
  s.configured = configured;
  s.first_seen = s.last_seen = Clock::now();
  auto [it, fresh] = shafts_.emplace(prefix, std::move(s));
  if (configured) bind(it->second);
  return &it->second;
}

void ShaftDirectory::bind(Shaft& s) {
  if (auto old = bound_.find(s.name); old != bound_.end() && old->second != s.prefix) {
    auto o = shafts_.find(old->second);
    if (o != shafts_.end()) o->second.bound = false;
    spdlog::warn("shaft '{}': now bridged from LCM prefix '{}' (was '{}', whose health stopped)", s.name,
                 printable(s.prefix), printable(old->second));
  }
  s.bound = true;
  s.bound_since = Clock::now();
  s.refused = false;
  bound_[s.name] = s.prefix;
  cmd_topics_[s.t.cmd] = s.prefix;
  events_.bound(s);
}

bool ShaftDirectory::askStates(const Shaft& cs, std::int64_t instance) {
  auto it = shafts_.find(cs.prefix);
  if (it == shafts_.end() || instance == 0 || instance == it->second.states_asked) return false;
  it->second.states_asked = instance;
  return true;
}

std::size_t ShaftDirectory::slotsUsed() const {
  std::size_t n = 0;
  for (const auto& [p, s] : shafts_) n += (s.configured || s.confirmed) ? 1 : 0;
  return n;
}

bool ShaftDirectory::silent(const Shaft& s, Clock::time_point now) const {
  return seconds(now - (s.health_in ? s.last_health : s.last_seen)) > cfg_.discovery_timeout;
}

void ShaftDirectory::tryConfirm(Shaft& s, Clock::time_point now) {
  if (s.confirmed || s.configured) return;
  if (s.streak < 3 || seconds(now - s.streak_start) < 1.0) return;
  // Its name: free, or held by a prefix whose health has stopped.
  auto b = bound_.find(s.name);
  Shaft* holder = nullptr;
  if (b != bound_.end())
    if (auto h = shafts_.find(b->second); h != shafts_.end()) holder = &h->second;
  if (holder && (holder->configured || !silent(*holder, now))) {
    // The name stays with the daemon first heard: the impostor (or a
    // misconfigured daemon) costs its own prefix, never the real shaft.
    refuseLog(s, now, fmt::format("shaft name '{}' is already bridged from prefix '{}'{}: prefix '{}' (daemon "
                                  "instance {}) claims it too and is not bridged (an impostor, or a misconfigured "
                                  "daemon); both are reported in the bridge's health (discovery.conflicts), and "
                                  "hoist/{}/ stays with '{}'; list the plant's shafts with --channel-prefix",
                                  s.name, printable(holder->prefix), holder->configured ? " (configured)" : "",
                                  printable(s.prefix), s.streak_instance, s.name, printable(holder->prefix)));
    return;
  }
  // Another bridged shaft whose topic tree holds this one's or contains it
  // (N20: never publish inside another shaft's tree), or, with Sparkplug,
  // with the same device id: the one bound first keeps its place.
  for (const auto& [name, prefix] : bound_)
    if (name != s.name)
      if (const std::string clash = shaftNameClash(name, s.name, cfg_.sparkplug); !clash.empty()) {
        refuseLog(s, now, fmt::format("prefix '{}' is not bridged: the bridged prefix '{}' and it {}; list the "
                                      "plant's shafts with --channel-prefix",
                                      printable(s.prefix), printable(prefix), clash));
        return;
      }
  if (!holder && slotsUsed() >= static_cast<std::size_t>(cfg_.max_shafts)) {
    // Table full: a confirmed shaft whose health has stopped makes room.
    Shaft* victim = nullptr;
    for (auto& [p, o] : shafts_)
      if (o.confirmed && !o.configured && silent(o, now) && (!victim || o.last_health < victim->last_health))
        victim = &o;
    if (!victim) {
      refuseLog(s, now, fmt::format("the shaft table is full ({} shafts, [bridge] max_shafts): prefix '{}' is not "
                                    "bridged; list the plant's shafts with --channel-prefix",
                                    cfg_.max_shafts, printable(s.prefix)));
      return;
    }
    spdlog::warn("shaft '{}' (prefix '{}'): its health stopped; its slot goes to prefix '{}'", victim->name,
                 printable(victim->prefix), printable(s.prefix));
    forget(victim->prefix);
  }
  s.confirmed = true;
  bind(s);
}

void ShaftDirectory::refuseLog(Shaft& s, Clock::time_point now, const std::string& why) {
  if (!s.refused) ++refused_total_;
  const bool first = !s.refused;
  s.refused = true;
  if (first || now - s.last_refused_log > std::chrono::seconds(60)) {
    s.last_refused_log = now;
    std::int64_t suppressed = 0;
    if (log_.allow(LogBudget::kLcm, now, suppressed)) spdlog::warn("discovery: {}", why);
  }
}

void ShaftDirectory::forget(const std::string& prefix) {
  auto it = shafts_.find(prefix);
  if (it == shafts_.end()) return;
  events_.forgetting(it->second);
  if (it->second.bound) {
    bound_.erase(it->second.name);
    cmd_topics_.erase(it->second.t.cmd);
  }
  shafts_.erase(it);
}

void ShaftDirectory::sweep(Clock::time_point now) {
  if (!discover_ || now - last_sweep_ < std::chrono::milliseconds(250)) return;
  last_sweep_ = now;
  for (auto it = shafts_.begin(); it != shafts_.end();) {
    const Shaft& s = it->second;
    if (!s.configured && !s.confirmed && seconds(now - s.last_seen) > cfg_.discovery_timeout) {
      ++aged_out_;
      events_.forgetting(s);
      it = shafts_.erase(it);
    } else {
      ++it;
    }
  }
  if (table_full_logged_ && !tableFull()) {
    table_full_logged_ = false;
    spdlog::info("discovery: the shaft table has room again");
  }
}

void ShaftDirectory::tick(Clock::time_point now) {
  sweep(now);
  if (!table_full_logged_ && tableFull()) {
    table_full_logged_ = true;
    spdlog::warn("discovery: the shaft table is full ({} of [bridge] max_shafts = {}) and a prefix was refused; "
                 "see discovery.refused in the bridge's health",
                 slotsUsed(), cfg_.max_shafts);
  }
}

bool ShaftDirectory::tableFull() const {
  if (slotsUsed() < static_cast<std::size_t>(cfg_.max_shafts)) return false;
  for (const auto& [p, s] : shafts_)
    if (s.refused) return true;
  return false;
}

const Shaft* ShaftDirectory::resolve(const std::string& prefix) {
  if (auto it = shafts_.find(prefix); it != shafts_.end()) {
    it->second.last_seen = Clock::now();
    return &it->second;
  }
  if (!discover_) return nullptr;
  std::string why;
  if (!validChannelPrefix(prefix, &why)) return nullptr;
  std::size_t candidates = 0;
  Shaft* weakest = nullptr;
  for (auto& [p, s] : shafts_) {
    if (s.configured || s.confirmed) continue;
    ++candidates;
    if (!weakest || s.streak < weakest->streak || (s.streak == weakest->streak && s.last_seen < weakest->last_seen))
      weakest = &s;
  }
  if (candidates >= 4 * static_cast<std::size_t>(cfg_.max_shafts) && weakest) {
    ++evicted_candidates_;
    forget(weakest->prefix);
  }
  return add(prefix, false);
}

ShaftDirectory::HealthSeen ShaftDirectory::onHealth(const Shaft& cs, std::int64_t instance_id) {
  HealthSeen out;
  auto it = shafts_.find(cs.prefix);
  if (it == shafts_.end()) return out;
  Shaft& s = it->second;
  const auto now = Clock::now();
  if (s.bound && s.instance_id != 0 && instance_id != s.instance_id &&
      seconds(now - s.instance_last) <= cfg_.discovery_timeout) {
    // The shaft is bound to a daemon that still talks: a second instance under
    // its prefix costs itself (dropped), never the real shaft (issue 33).
    ++s.impostor_in;
    ++impostors_;
    out.impostor = true;
    std::int64_t suppressed = 0;
    if (log_.allow(LogBudget::kLcm, now, suppressed))
      spdlog::warn("shaft '{}': health of another daemon instance {} on {}HOIST_HEALTH while instance {} is alive: "
                   "an impostor, dropped ({} so far) [{} similar suppressed]",
                   s.name, instance_id, printable(s.prefix, 64), s.instance_id, s.impostor_in, suppressed);
    return out;
  }
  const bool continues =
      s.streak > 0 && instance_id == s.streak_instance && seconds(now - s.last_health) <= cfg_.discovery_timeout;
  if (instance_id == 0) {
    s.streak = 0;
  } else if (continues) {
    ++s.streak;
  } else {
    s.streak = 1;
    s.streak_instance = instance_id;
    s.streak_start = now;
  }
  ++s.health_in;
  s.last_health = now;
  if (!s.bound) {
    tryConfirm(s, now);
    if (s.bound) {  // bound to the instance that confirmed it: its alarm states (asked for now) pass
      s.instance_id = instance_id;
      s.instance_last = now;
    }
    return out;
  }
  out.bound = true;
  out.restarted = s.instance_id != 0 && instance_id != s.instance_id;
  s.instance_id = instance_id;
  s.instance_last = now;
  return out;
}

const Shaft* ShaftDirectory::boundByName(const std::string& name) const {
  auto b = bound_.find(name);
  return b == bound_.end() ? nullptr : &shafts_.at(b->second);
}

const Shaft* ShaftDirectory::byCommandTopic(const std::string& topic) const {
  auto it = cmd_topics_.find(topic);
  return it == cmd_topics_.end() ? nullptr : &shafts_.at(it->second);
}

std::vector<std::string> ShaftDirectory::rivals(const Shaft& s) const {
  std::vector<std::string> out;
  for (const auto& [p, o] : shafts_)
    if (&o != &s && o.name == s.name) out.push_back(p);
  return out;
}

}  // namespace hoist::mqtt
