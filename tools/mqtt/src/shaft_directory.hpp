// shaft_directory.hpp -- the bridge's shaft directory: which LCM channel
// prefixes are bridged, under which shaft name, and discovery (a prefix is a
// candidate until its health, with one non-zero instance id, has kept
// coming; only then may it take a slot and its name).  Private to
// tools/mqtt; the map of the rooms is bridge.cpp.
//
// Writes only its own state (the table below).  What binding or forgetting
// a shaft means elsewhere (subscriptions, alarm states, Sparkplug births) is
// the Events listener's job.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bridge_common.hpp"
#include "hoist/mqtt/config.hpp"

namespace hoist::mqtt {

/// The MQTT topics of one shaft (JSON mode), fixed when the prefix is first seen.
struct ShaftTopics {
  std::string cage, health, alarm /* + <KIND> */, cmd, result, forecast, estimate;
};

/// One prefix's entry.  Other rooms see it const.
struct Shaft {
  std::string prefix, name;
  ShaftTopics t;
  bool configured = false, confirmed = false, bound = false;
  bool refused = false;  ///< confirmed-quality but no slot (table full) or its name is taken
  Clock::time_point bound_since{};
  Clock::time_point first_seen{}, last_seen{}, streak_start{}, last_refused_log{}, last_health{};
  std::int64_t streak_instance = 0;
  int streak = 0;                 ///< health messages of streak_instance, gaps <= discovery_timeout
  std::int64_t states_asked = 0;  ///< daemon instance asked for its alarm states
  std::int64_t instance_id = 0;   ///< the daemon instance the bound shaft is bound to (first heard, or its successor)
  Clock::time_point instance_last{};  ///< last health of that instance
  std::uint64_t impostor_in = 0;  ///< health messages of another instance while it lives (dropped)
  std::uint64_t health_in = 0;
};

class ShaftDirectory {
 public:
  /// What binding and forgetting mean for the other rooms (implemented by Bridge).
  class Events {
   public:
    virtual ~Events() = default;
    /// `s` is now published under its name (configured, or confirmed by discovery).
    virtual void bound(const Shaft& s) = 0;
    /// `s` is about to be erased (evicted candidate, or a silent shaft's slot reused).
    virtual void forgetting(const Shaft& s) = 0;
  };

  /// `cfg`, `log` and `events` are referenced, not copied: they must outlive
  /// the directory.  Nothing is bound until addConfigured().
  ShaftDirectory(const BridgeConfig& cfg, LogBudget& log, Events& events);
  ShaftDirectory(const ShaftDirectory&) = delete;
  ShaftDirectory& operator=(const ShaftDirectory&) = delete;

  /// Binds the configured prefixes ([bridge] channel_prefixes); once, after wiring.
  void addConfigured();

  /// The entry of `prefix`: a configured or known one (its last_seen
  /// updated), else with discovery a new candidate; nullptr if not bridged.
  const Shaft* resolve(const std::string& prefix);

  /// A health message of daemon instance `instance_id` on `s`.  A bound
  /// shaft stays bound to the instance it first heard: another instance id
  /// (0 included) under the same prefix while that one has been heard within
  /// discovery_timeout is an impostor (result `impostor`; its messages are
  /// the caller's to drop); after that silence it is the daemon's successor
  /// (a restart: `restarted`).
  struct HealthSeen {
    bool bound = false;      ///< the shaft is bound: its health is published
    bool restarted = false;  ///< a new daemon instance (alarm states from before it are void)
    bool impostor = false;   ///< another instance while the bound one lives: dropped, counted, logged
  };
  HealthSeen onHealth(const Shaft& s, std::int64_t instance_id);

  /// True once per daemon instance: ask it to re-announce its alarm states.
  bool askStates(const Shaft& s, std::int64_t instance);

  /// Ages candidates out, logs a full table once; call every loop.
  void tick(Clock::time_point now);

  const Shaft* boundByName(const std::string& name) const;
  const Shaft* byCommandTopic(const std::string& topic) const;
  const std::map<std::string, Shaft>& all() const { return shafts_; }
  /// Prefixes other than `s` that map to its name.
  std::vector<std::string> rivals(const Shaft& s) const;
  /// Health silent for longer than discovery_timeout.
  bool silent(const Shaft& s, Clock::time_point now) const;
  std::size_t slotsUsed() const;
  std::size_t boundCount() const { return bound_.size(); }
  bool tableFull() const;
  bool discovering() const { return discover_; }
  std::uint64_t refusedTotal() const { return refused_total_; }
  std::uint64_t evictedCandidates() const { return evicted_candidates_; }
  std::uint64_t agedOut() const { return aged_out_; }
  std::uint64_t impostors() const { return impostors_; }
  /// True if a message of daemon instance `instance_id` on `s` comes from the
  /// instance `s` is bound to (never for an unbound shaft or instance 0).
  static bool fromBoundInstance(const Shaft& s, std::int64_t instance_id) {
    return s.bound && s.instance_id != 0 && instance_id == s.instance_id;
  }

 private:
  Shaft* add(const std::string& prefix, bool configured);
  void bind(Shaft& s);
  void tryConfirm(Shaft& s, Clock::time_point now);
  void refuseLog(Shaft& s, Clock::time_point now, const std::string& why);
  void forget(const std::string& prefix);
  void sweep(Clock::time_point now);

  const BridgeConfig& cfg_;
  LogBudget& log_;
  Events& events_;
  std::map<std::string, Shaft> shafts_;           // by prefix: configured, confirmed and candidate prefixes
  std::map<std::string, std::string> cmd_topics_;  // command topic -> prefix bound to its shaft name
  std::map<std::string, std::string> bound_;       // shaft name -> the prefix published under it
  bool discover_ = false;
  std::uint64_t refused_total_ = 0, evicted_candidates_ = 0, aged_out_ = 0, impostors_ = 0;
  bool table_full_logged_ = false;
  Clock::time_point last_sweep_{};
};

}  // namespace hoist::mqtt
