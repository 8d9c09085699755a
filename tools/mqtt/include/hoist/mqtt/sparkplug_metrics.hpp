// hoist/mqtt/sparkplug_metrics.hpp -- hoist-mqtt's Sparkplug B metrics:
// the table of a shaft's (device's) metrics, their aliases, current values
// and report by exception with a deadband; the edge node's own metrics; the
// Sparkplug topics.  No protobuf here (hoist/mqtt/sparkplug.hpp encodes).
//
// Each shaft is a Sparkplug device.  Its metrics (deviceMetrics(), in DBIRTH
// order; units as the property "engUnit"):
//   Cage/...      from <prefix>HOIST_CAGE     (cage_state_t), at [bridge] cage_rate
//   Health/...    from <prefix>HOIST_HEALTH   (health_t), as they come
//   Alarms/<KIND>/{Level,Active,Acked,Shelved} from <prefix>HOIST_ALARM (the kind's
//                 state, as the JSON mode's hoist/<shaft>/alarm/<KIND>), as they come
//   Alarms/<KIND>/{Ack,Shelve,Unshelve}  writable by DCMD (the only writable ones)
//   Forecast/...  from <prefix>HOIST_FORECAST (the summary over its scenarios)
//   Estimate/...  from <prefix>HOIST_ESTIMATE (null until the first estimate)
//   Condition/... from the history database's trip records ([history] url,
//                 hoist/mqtt/trip_feed.hpp): Last Trip, Preload Scale and its
//                 Sigma (the trend's combined estimate; null before an
//                 informative trip), Last Trip Informative, Trips In Trend,
//                 Guide Preload Low (0 none, 1 WARNING, 2 CRITICAL); null
//                 until the first trip record
// A metric with no value yet is born with is_null.  DDATA carries the metrics
// of one source whose value changed by more than their deadband
// ([sparkplug] deadband, [sparkplug.deadbands]; 0 = any change) since it was
// last sent, by alias only.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/health_t.hpp"

namespace hoist::mqtt::sparkplug {

/// Sparkplug B DataType (the specification's numbers).
enum class DataType : std::uint32_t {
  Int8 = 1, Int16 = 2, Int32 = 3, Int64 = 4, UInt8 = 5, UInt16 = 6, UInt32 = 7, UInt64 = 8,
  Float = 9, Double = 10, Boolean = 11, String = 12, DateTime = 13, Text = 14,
};
bool isNumeric(DataType t);
const char* typeName(DataType t);  ///< "Int64", "Double", ...

enum class Source : std::uint8_t { Node, Cage, Health, Alarm, Forecast, Estimate, Command, Condition };

struct MetricDef {
  std::string name;
  DataType type;
  std::string units;  ///< "" = none
  Source source;
  bool writable = false;
};

/// Every device metric, in DBIRTH order (the same for every shaft).
const std::vector<MetricDef>& deviceMetrics();
const MetricDef* findDeviceMetric(std::string_view name);
std::vector<std::string> deviceMetricNames();

/// The Condition/... metrics' values (hoist::mqtt::ConditionMetrics as the
/// trip feed reads them; no dependency on the history library here).
struct ConditionValues {
  bool valid = false;
  double preload_scale = 1.0, preload_sigma = -1.0;
  bool last_informative = false;
  std::int64_t trips_in_trend = 0, last_trip = 0;
  int guide_preload_low = 0;
};

/// A metric value.  Integers of every width in `i`, Float/Double in `d`.
struct Value {
  bool is_null = true;
  bool b = false;
  std::int64_t i = 0;
  double d = 0.0;
  std::string s;
};

/// A metric as sent or received.
struct Metric {
  std::string name;            ///< "" = not sent (DATA by alias)
  bool has_alias = false;
  std::uint64_t alias = 0;
  bool has_type = false;
  DataType type = DataType::Double;
  std::uint64_t timestamp_ms = 0;  ///< 0 = not sent
  std::string units;           ///< sent as the property "engUnit" (births)
  bool is_historical = false;
  Value value;
};

struct Payload {
  std::uint64_t timestamp_ms = 0;
  bool has_seq = false;
  std::uint64_t seq = 0;
  std::vector<Metric> metrics;
};

/// The node's own metrics (NBIRTH order): bdSeq, Node Control/Rebirth
/// (writable), Properties/Version, Bridge/Commands Received, ... Forwarded,
/// ... Refused, Bridge/Decode Errors.  Aliases 1..n.
struct NodeCounters {
  std::int64_t commands_received = 0, commands_forwarded = 0, commands_refused = 0, decode_errors = 0;
};
const std::vector<MetricDef>& nodeMetrics();
inline constexpr std::uint64_t kRebirthAlias = 2;
/// NBIRTH (seq 0 is set when sent).
Payload nodeBirth(std::int64_t bd_seq, const std::string& version, const NodeCounters& c, std::uint64_t now_ms);
/// NDEATH: only bdSeq, no seq.
Payload nodeDeath(std::int64_t bd_seq, std::uint64_t now_ms);
/// NDATA with the counters that changed since `last` (none: no metrics).
Payload nodeData(const NodeCounters& c, const NodeCounters& last, std::uint64_t now_ms);

/// One shaft's metrics: aliases first_alias .. first_alias + n - 1.
class DeviceMetrics {
 public:
  DeviceMetrics(std::uint64_t first_alias, double default_deadband, const std::map<std::string, double>& deadbands);

  void onCage(const hoist::cage_state_t& m);
  void onHealth(const hoist::health_t& m);
  void onForecast(const hoist::forecast_t& m);
  void onEstimate(const hoist::estimate_t& m);
  /// A new trip record of this shaft (the trip feed); utime = its arrival.
  void onCondition(const ConditionValues& c, std::int64_t utime);
  /// The state of alarm `kind` (an alarm_t kind name; other kinds are ignored:
  /// false).  level 0..2 = the highest active, unshelved level.
  bool setAlarm(const std::string& kind, int level, bool active, bool acked, bool shelved, std::int64_t utime);

  /// The alarm metrics still null (no event of that kind since the shaft was
  /// bridged) become inactive: called once the daemon has had the time to
  /// re-announce its active alarms ([bridge] alarm_sync_time).
  void alarmsSettled(std::int64_t utime);

  /// DBIRTH: every metric with name, alias, datatype, units and current value;
  /// what it carries becomes the last reported value.
  Payload birth(std::uint64_t now_ms);
  /// DDATA: the metrics of `src` that moved past their deadband since last
  /// reported, by alias (empty metrics: nothing to send).
  Payload changes(Source src, std::uint64_t now_ms);

  /// The metric of an alias or a name (nullptr if none), and its index.
  const MetricDef* byAlias(std::uint64_t alias, std::size_t* index = nullptr) const;
  const MetricDef* byName(std::string_view name, std::size_t* index = nullptr) const;
  std::uint64_t aliasOf(std::size_t index) const { return first_alias_ + index; }
  const Value& current(std::size_t index) const { return current_[index]; }
  std::size_t size() const { return current_.size(); }

 private:
  void set(std::size_t index, const Value& v, std::int64_t utime);
  void setD(const char* name, double v, std::int64_t utime);
  void setI(const char* name, std::int64_t v, std::int64_t utime);
  void setB(const char* name, bool v, std::int64_t utime);
  Metric full(std::size_t index) const;

  std::uint64_t first_alias_;
  std::vector<double> deadband_;
  std::vector<Value> current_, reported_;
  std::vector<std::uint64_t> ts_ms_;
};

/// Topics: spBv1.0/<group>/<type>/<edge>[/<device>].
std::string nodeTopic(const std::string& group, const char* type, const std::string& edge);
std::string deviceTopic(const std::string& group, const char* type, const std::string& edge, const std::string& device);
std::string stateTopic(const std::string& host);
/// The Sparkplug device id of a shaft name: '/', '+' and '#' become '_'.
std::string deviceId(const std::string& shaft_name);

/// A primary host's STATE payload (Sparkplug 3.0: {"online": bool,
/// "timestamp": ms}).  false if it is not that (at most 1024 bytes).
bool parseState(const void* data, std::size_t size, bool& online, std::uint64_t& timestamp_ms);

}  // namespace hoist::mqtt::sparkplug
