// shaft_data.hpp -- the bridge's data path: what the shafts' daemons said
// (latest cage state and estimate, every alarm kind's state by level, input
// counters) and its publication, as JSON topics or, in Sparkplug mode, as
// the devices' metrics (DDATA by exception).  Private to tools/mqtt; the map
// of the rooms is bridge.cpp.
//
// Writes only its own state (one Feed per LCM prefix) and sends through the
// MQTT link; in Sparkplug mode it also fills the session's device metrics.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "bridge_common.hpp"
#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/mqtt/config.hpp"
#include "mqtt_link.hpp"
#include "shaft_directory.hpp"

namespace hoist::mqtt {

class SparkplugSession;

/// One alarm kind's state: the latest event of each level.
struct AlarmState {
  std::optional<hoist::alarm_t> by_level[3];  // index = level (1 WARNING, 2 CRITICAL)
  hoist::alarm_t last;                        // latest event of either level
};

class ShaftData {
 public:
  static constexpr int kMaxKindsPerShaft = 32;
  /// Alarm kinds are used in topic names: upper-case letters, digits and '_', 1..32.
  static bool validKind(const std::string& k);

  /// What one prefix said.
  struct Feed {
    hoist::cage_state_t cage{};
    bool cage_new = false;
    hoist::estimate_t estimate{};  // like the cage: the latest estimate at [bridge] cage_rate
    bool estimate_new = false;
    bool alarms_settled = false;  // Sparkplug: alarm kinds never heard of are known inactive
    std::map<std::string, AlarmState> alarms;  // by kind
    std::uint64_t cage_in = 0, cage_out = 0, alarms_in = 0, forecasts_in = 0, estimates_in = 0, estimates_out = 0;
  };

  /// `cfg`, `link` and `log` are referenced and must outlive this object.
  ShaftData(const BridgeConfig& cfg, MqttLink& link, LogBudget& log);
  ShaftData(const ShaftData&) = delete;
  ShaftData& operator=(const ShaftData&) = delete;

  /// Sparkplug mode: the session whose device metrics carry the data (set
  /// once while wiring; it must outlive this object).  nullptr: JSON topics.
  void useSparkplug(SparkplugSession* sp) { sp_ = sp; }

  // ---- from LCM (the shaft as the directory resolved it) ----
  /// True if a message of daemon instance `instance` on `s`'s `channel` may
  /// pass: from the instance the shaft is bound to (ShaftDirectory).  Alarm
  /// events (`strict`) need that instance known; data before the first health
  /// passes.  Others are counted by channel and logged (rate-limited).
  bool admit(const Shaft& s, std::int64_t instance, const char* channel, bool strict);
  void onCage(const Shaft& s, const hoist::cage_state_t& m);
  void onEstimate(const Shaft& s, const hoist::estimate_t& m);
  void onForecast(const Shaft& s, const hoist::forecast_t& m);
  void onAlarm(const Shaft& s, const hoist::alarm_t& m);
  /// A bound shaft's health; `restarted`: a new daemon instance (alarm
  /// states from before its start are cleared first).
  void onHealth(const Shaft& s, const hoist::health_t& m, bool restarted);

  // ---- from the directory ----
  /// `s` was bound: its alarm states are published (JSON) or set (Sparkplug).
  void bound(const Shaft& s);
  void forget(const std::string& prefix) { feeds_.erase(prefix); }

  // ---- timers ----
  /// The latest cage state and estimate of every bound shaft, if new.
  void publishCages(const ShaftDirectory& dir);
  /// Every bound shaft's alarm states, after a (re)connection (JSON mode);
  /// a state waiting in the journal is not sent twice unless `journal_lost`.
  void republishAlarms(const ShaftDirectory& dir, bool journal_lost);
  /// Sparkplug: kinds never heard of are inactive once [bridge] alarm_sync_time has passed.
  void settleAlarms(const ShaftDirectory& dir, Clock::time_point now);

  // ---- const views ----
  const Feed* find(const std::string& prefix) const;
  /// An acknowledge matches an active, unacknowledged alarm known of `prefix`.
  bool ackMatches(const std::string& prefix, const hoist::alarm_ack_t& ack) const;
  int activeAlarms(const std::string& prefix) const;
  std::uint64_t alarmRejected() const { return alarm_rejected_; }
  /// Messages dropped by admit(), by channel suffix.
  const std::map<std::string, std::uint64_t>& foreignInstance() const { return foreign_; }

 private:
  Feed& feed(const Shaft& s) { return feeds_[s.prefix]; }
  void daemonRestarted(const Shaft& s, Feed& f, const hoist::health_t& h);
  void publishAlarmState(const Shaft& s, const std::string& kind, const AlarmState& a);
  nlohmann::json alarmStateJson(const Shaft& s, const std::string& kind, const AlarmState& a) const;
  void setAlarmMetrics(const Shaft& s, const std::string& kind, const AlarmState& a);

  const BridgeConfig& cfg_;
  MqttLink& link_;
  LogBudget& log_;
  SparkplugSession* sp_ = nullptr;
  std::map<std::string, Feed> feeds_;  // by prefix
  std::uint64_t alarm_rejected_ = 0;
  std::map<std::string, std::uint64_t> foreign_;  // admit()'s drops by channel suffix
};

}  // namespace hoist::mqtt
