// The hub's shaft discovery (Hub's members; docs/dashboard.md "Shaft
// discovery"): health from an unknown prefix is evidence, a prefix is
// confirmed after opt_.confirm_count reports of one instance, the table is
// bounded and maintained (maintainDiscovery, from flushDecimated), and two
// prefixes that give one shaft name raise a status.  Called on the hub's
// thread; the rest of the hub is hub.cpp.
#include <algorithm>

#include <spdlog/spdlog.h>

#include "hoist/msg/codec.hpp"
#include "hub.hpp"

namespace hoist::dash {

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

}  // namespace hoist::dash
