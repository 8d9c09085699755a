// hoist-mqtt's Sparkplug B metrics: see hoist/mqtt/sparkplug_metrics.hpp.
#include "hoist/mqtt/sparkplug_metrics.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "hoist/msg/names.hpp"

namespace hoist::mqtt::sparkplug {

bool isNumeric(DataType t) {
  switch (t) {
    case DataType::Boolean:
    case DataType::String:
    case DataType::Text:
      return false;
    default:
      return true;
  }
}

const char* typeName(DataType t) {
  switch (t) {
    case DataType::Int8: return "Int8";
    case DataType::Int16: return "Int16";
    case DataType::Int32: return "Int32";
    case DataType::Int64: return "Int64";
    case DataType::UInt8: return "UInt8";
    case DataType::UInt16: return "UInt16";
    case DataType::UInt32: return "UInt32";
    case DataType::UInt64: return "UInt64";
    case DataType::Float: return "Float";
    case DataType::Double: return "Double";
    case DataType::Boolean: return "Boolean";
    case DataType::String: return "String";
    case DataType::DateTime: return "DateTime";
    case DataType::Text: return "Text";
  }
  return "?";
}

namespace {

std::vector<MetricDef> makeDeviceMetrics() {
  using D = DataType;
  std::vector<MetricDef> m;
  auto add = [&](const std::string& name, D t, const char* units, Source s, bool w = false) {
    m.push_back({name, t, units, s, w});
  };
  const Source C = Source::Cage, H = Source::Health, A = Source::Alarm, F = Source::Forecast, E = Source::Estimate;
  add("Cage/Seq", D::Int64, "", C);
  add("Cage/Model Time", D::Double, "s", C);
  add("Cage/Length", D::Double, "m", C);
  add("Cage/Velocity", D::Double, "m/s", C);
  add("Cage/Acceleration", D::Double, "m/s^2", C);
  add("Cage/Longitudinal", D::Double, "m", C);
  add("Cage/Lateral", D::Double, "m", C);
  add("Cage/Rotation", D::Double, "rad", C);
  add("Cage/Y Top", D::Double, "m", C);
  add("Cage/Y Bottom", D::Double, "m", C);
  add("Cage/Guide Deflection", D::Double, "m", C);
  add("Cage/Clearance Pos Y", D::Double, "m", C);
  add("Cage/Clearance Neg Y", D::Double, "m", C);
  add("Cage/Clearance Guide", D::Double, "m", C);
  add("Cage/Min Clearance", D::Double, "m", C);
  add("Cage/Rope Force", D::Double, "N", C);
  add("Cage/Alarm Level", D::Int32, "", C);
  add("Cage/Degraded", D::Boolean, "", C);
  add("Health/Instance Id", D::Int64, "", H);
  add("Health/Uptime", D::Double, "s", H);
  add("Health/Degraded", D::Boolean, "", H);
  add("Health/Input Age", D::Double, "s", H);
  add("Health/Deadline Misses", D::Int64, "", H);
  add("Health/Step p99", D::Double, "us", H);
  add("Health/Rejected", D::Int64, "", H);
  add("Health/Model Faults", D::Int64, "", H);
  add("Health/Alarms Active", D::Int32, "", H);
  add("Health/Alarms Unacked", D::Int32, "", H);
  add("Health/Alarms Shelved", D::Int32, "", H);
  add("Health/Preload Scale", D::Double, "", H);
  for (const auto& k : hoist::msg::enums::alarm_t::kKindNames) {
    const std::string base = "Alarms/" + std::string(k) + "/";
    add(base + "Level", D::Int32, "", A);
    add(base + "Active", D::Boolean, "", A);
    add(base + "Acked", D::Boolean, "", A);
    add(base + "Shelved", D::Boolean, "", A);
    add(base + "Ack", D::Boolean, "", Source::Command, true);
    add(base + "Shelve", D::Double, "s", Source::Command, true);
    add(base + "Unshelve", D::Boolean, "", Source::Command, true);
  }
  add("Forecast/Seq", D::Int64, "", F);
  add("Forecast/Scenarios", D::Int32, "", F);
  add("Forecast/All OK", D::Boolean, "", F);
  add("Forecast/Min Clearance", D::Double, "m", F);
  add("Forecast/Time To Warning", D::Double, "s", F);
  add("Forecast/Time To Critical", D::Double, "s", F);
  add("Forecast/Rope Force Min", D::Double, "N", F);
  add("Forecast/Rope Force Max", D::Double, "N", F);
  add("Estimate/Seq", D::Int64, "", E);
  add("Estimate/Load Force", D::Double, "N", E);
  add("Estimate/Load Force Sigma", D::Double, "N", E);
  add("Estimate/Moment", D::Double, "N m", E);
  add("Estimate/Moment Sigma", D::Double, "N m", E);
  add("Estimate/Lateral", D::Double, "m", E);
  add("Estimate/Rotation", D::Double, "rad", E);
  add("Estimate/NIS", D::Double, "", E);
  add("Estimate/Drift", D::Double, "", E);
  add("Estimate/In Use", D::Boolean, "", E);
  add("Estimate/Mismatch", D::Boolean, "", E);
  add("Estimate/Sensors", D::Int32, "", E);
  // From the history database's trips (hoist/mqtt/trip_feed.hpp), when
  // [history] url is set; null until the first trip record.
  const Source T = Source::Condition;
  add("Condition/Last Trip", D::Int64, "", T);
  add("Condition/Preload Scale", D::Double, "", T);
  add("Condition/Preload Scale Sigma", D::Double, "", T);
  add("Condition/Last Trip Informative", D::Boolean, "", T);
  add("Condition/Trips In Trend", D::Int64, "", T);
  add("Condition/Guide Preload Low", D::Int32, "", T);
  return m;
}

std::uint64_t ms(std::int64_t utime) { return utime > 0 ? static_cast<std::uint64_t>(utime / 1000) : 0; }

bool differs(const MetricDef& d, const Value& a, const Value& b, double deadband) {
  if (a.is_null != b.is_null) return true;
  if (a.is_null) return false;
  switch (d.type) {
    case DataType::Boolean: return a.b != b.b;
    case DataType::String:
    case DataType::Text: return a.s != b.s;
    case DataType::Float:
    case DataType::Double:
      if (std::isnan(a.d) || std::isnan(b.d)) return std::isnan(a.d) != std::isnan(b.d);
      return deadband > 0.0 ? std::fabs(a.d - b.d) > deadband : a.d != b.d;
    default:
      return deadband > 0.0 ? std::fabs(static_cast<double>(a.i - b.i)) > deadband : a.i != b.i;
  }
}

Value valD(double v) {
  Value x;
  x.is_null = false;
  x.d = v;
  return x;
}
Value valI(std::int64_t v) {
  Value x;
  x.is_null = false;
  x.i = v;
  return x;
}
Value valB(bool v) {
  Value x;
  x.is_null = false;
  x.b = v;
  return x;
}
Value valS(std::string v) {
  Value x;
  x.is_null = false;
  x.s = std::move(v);
  return x;
}

}  // namespace

const std::vector<MetricDef>& deviceMetrics() {
  static const std::vector<MetricDef> m = makeDeviceMetrics();
  return m;
}

const MetricDef* findDeviceMetric(std::string_view name) {
  for (const auto& d : deviceMetrics())
    if (d.name == name) return &d;
  return nullptr;
}

std::vector<std::string> deviceMetricNames() {
  std::vector<std::string> n;
  for (const auto& d : deviceMetrics()) n.push_back(d.name);
  return n;
}

const std::vector<MetricDef>& nodeMetrics() {
  static const std::vector<MetricDef> m{
      {"bdSeq", DataType::Int64, "", Source::Node, false},
      {"Node Control/Rebirth", DataType::Boolean, "", Source::Node, true},
      {"Properties/Version", DataType::String, "", Source::Node, false},
      {"Bridge/Commands Received", DataType::Int64, "", Source::Node, false},
      {"Bridge/Commands Forwarded", DataType::Int64, "", Source::Node, false},
      {"Bridge/Commands Refused", DataType::Int64, "", Source::Node, false},
      {"Bridge/Decode Errors", DataType::Int64, "", Source::Node, false},
  };
  return m;
}

namespace {
Metric nodeMetric(std::size_t i, Value v, std::uint64_t now_ms, bool with_name) {
  const MetricDef& d = nodeMetrics()[i];
  Metric m;
  if (with_name) {
    m.name = d.name;
    m.has_type = true;
    m.type = d.type;
  }
  m.has_alias = true;
  m.alias = i + 1;
  m.timestamp_ms = now_ms;
  m.value = std::move(v);
  return m;
}
}  // namespace

Payload nodeBirth(std::int64_t bd_seq, const std::string& version, const NodeCounters& c, std::uint64_t now_ms) {
  Payload p;
  p.timestamp_ms = now_ms;
  p.has_seq = true;
  const Value vals[] = {valI(bd_seq), valB(false), valS(version), valI(c.commands_received),
                        valI(c.commands_forwarded), valI(c.commands_refused), valI(c.decode_errors)};
  for (std::size_t i = 0; i < nodeMetrics().size(); ++i) p.metrics.push_back(nodeMetric(i, vals[i], now_ms, true));
  return p;
}

Payload nodeDeath(std::int64_t bd_seq, std::uint64_t now_ms) {
  Payload p;
  p.timestamp_ms = now_ms;
  Metric m = nodeMetric(0, valI(bd_seq), now_ms, true);
  m.has_alias = false;  // the host may not know the alias yet
  p.metrics.push_back(m);
  return p;
}

Payload nodeData(const NodeCounters& c, const NodeCounters& last, std::uint64_t now_ms) {
  Payload p;
  p.timestamp_ms = now_ms;
  p.has_seq = true;
  const std::int64_t now[] = {c.commands_received, c.commands_forwarded, c.commands_refused, c.decode_errors};
  const std::int64_t was[] = {last.commands_received, last.commands_forwarded, last.commands_refused,
                              last.decode_errors};
  for (std::size_t i = 0; i < 4; ++i)
    if (now[i] != was[i]) p.metrics.push_back(nodeMetric(3 + i, valI(now[i]), now_ms, false));
  return p;
}

DeviceMetrics::DeviceMetrics(std::uint64_t first_alias, double default_deadband,
                             const std::map<std::string, double>& deadbands)
    : first_alias_(first_alias) {
  const auto& defs = deviceMetrics();
  current_.resize(defs.size());
  reported_.resize(defs.size());
  ts_ms_.assign(defs.size(), 0);
  deadband_.resize(defs.size());
  for (std::size_t i = 0; i < defs.size(); ++i) {
    auto it = deadbands.find(defs[i].name);
    deadband_[i] = it != deadbands.end() ? it->second : isNumeric(defs[i].type) ? default_deadband : 0.0;
    // The writable metrics read as "nothing requested".
    if (defs[i].writable) current_[i] = defs[i].type == DataType::Boolean ? valB(false) : valD(0.0);
  }
}

const MetricDef* DeviceMetrics::byAlias(std::uint64_t alias, std::size_t* index) const {
  if (alias < first_alias_ || alias - first_alias_ >= current_.size()) return nullptr;
  if (index) *index = alias - first_alias_;
  return &deviceMetrics()[alias - first_alias_];
}

const MetricDef* DeviceMetrics::byName(std::string_view name, std::size_t* index) const {
  const auto& defs = deviceMetrics();
  for (std::size_t i = 0; i < defs.size(); ++i)
    if (defs[i].name == name) {
      if (index) *index = i;
      return &defs[i];
    }
  return nullptr;
}

void DeviceMetrics::set(std::size_t index, const Value& v, std::int64_t utime) {
  current_[index] = v;
  ts_ms_[index] = ms(utime);
}

void DeviceMetrics::setD(const char* name, double v, std::int64_t utime) {
  std::size_t i = 0;
  if (byName(name, &i)) set(i, valD(v), utime);
}
void DeviceMetrics::setI(const char* name, std::int64_t v, std::int64_t utime) {
  std::size_t i = 0;
  if (byName(name, &i)) set(i, valI(v), utime);
}
void DeviceMetrics::setB(const char* name, bool v, std::int64_t utime) {
  std::size_t i = 0;
  if (byName(name, &i)) set(i, valB(v), utime);
}

void DeviceMetrics::onCage(const hoist::cage_state_t& m) {
  const auto u = m.utime;
  setI("Cage/Seq", m.seq, u);
  setD("Cage/Model Time", m.t, u);
  setD("Cage/Length", m.l, u);
  setD("Cage/Velocity", m.v, u);
  setD("Cage/Acceleration", m.a, u);
  setD("Cage/Longitudinal", m.x_c, u);
  setD("Cage/Lateral", m.y_c, u);
  setD("Cage/Rotation", m.theta, u);
  setD("Cage/Y Top", m.y_top, u);
  setD("Cage/Y Bottom", m.y_bottom, u);
  setD("Cage/Guide Deflection", m.guide_deflection, u);
  setD("Cage/Clearance Pos Y", m.clearance_pos_y, u);
  setD("Cage/Clearance Neg Y", m.clearance_neg_y, u);
  setD("Cage/Clearance Guide", m.clearance_guide, u);
  setD("Cage/Min Clearance", m.min_clearance, u);
  setD("Cage/Rope Force", m.lambdas[0], u);
  setI("Cage/Alarm Level", m.alarm_level, u);
  setB("Cage/Degraded", m.degraded, u);
}

void DeviceMetrics::onHealth(const hoist::health_t& m) {
  const auto u = m.utime;
  setI("Health/Instance Id", m.instance_id, u);
  setD("Health/Uptime", m.uptime, u);
  setB("Health/Degraded", m.degraded, u);
  setD("Health/Input Age", m.input_age, u);
  setI("Health/Deadline Misses", m.deadline_misses, u);
  setD("Health/Step p99", m.step_p99_us, u);
  setI("Health/Rejected", m.rejected_total, u);
  setI("Health/Model Faults", m.model_faults, u);
  setI("Health/Alarms Active", m.alarms_active, u);
  setI("Health/Alarms Unacked", m.alarms_unacked, u);
  setI("Health/Alarms Shelved", m.alarms_shelved, u);
  setD("Health/Preload Scale", m.preload_scale, u);
}

void DeviceMetrics::onForecast(const hoist::forecast_t& m) {
  const auto u = m.utime;
  setI("Forecast/Seq", m.seq, u);
  const int n = std::max(0, std::min<int>(m.num_scenarios, static_cast<int>(m.scenarios.size())));
  setI("Forecast/Scenarios", n, u);
  if (n == 0) return;
  bool ok = true;
  double min_c = m.scenarios[0].min_clearance, fmin = m.scenarios[0].lambda0_min, fmax = m.scenarios[0].lambda0_max;
  double t_w = -1.0, t_c = -1.0;
  for (int k = 0; k < n; ++k) {
    const auto& s = m.scenarios[static_cast<std::size_t>(k)];
    ok = ok && s.status == hoist::forecast_scenario_t::STATUS_OK;
    min_c = std::min(min_c, s.min_clearance);
    fmin = std::min(fmin, s.lambda0_min);
    fmax = std::max(fmax, s.lambda0_max);
    if (s.t_warning >= 0.0 && (t_w < 0.0 || s.t_warning < t_w)) t_w = s.t_warning;
    if (s.t_critical >= 0.0 && (t_c < 0.0 || s.t_critical < t_c)) t_c = s.t_critical;
  }
  setB("Forecast/All OK", ok, u);
  setD("Forecast/Min Clearance", min_c, u);
  setD("Forecast/Time To Warning", t_w, u);
  setD("Forecast/Time To Critical", t_c, u);
  setD("Forecast/Rope Force Min", fmin, u);
  setD("Forecast/Rope Force Max", fmax, u);
}

void DeviceMetrics::onEstimate(const hoist::estimate_t& m) {
  const auto u = m.utime;
  setI("Estimate/Seq", m.seq, u);
  setD("Estimate/Load Force", m.Fa, u);
  setD("Estimate/Load Force Sigma", m.sigma_Fa, u);
  setD("Estimate/Moment", m.moment, u);
  setD("Estimate/Moment Sigma", m.sigma_moment, u);
  setD("Estimate/Lateral", m.y_c, u);
  setD("Estimate/Rotation", m.theta, u);
  setD("Estimate/NIS", m.nis, u);
  setD("Estimate/Drift", m.drift, u);
  setB("Estimate/In Use", m.in_use, u);
  setB("Estimate/Mismatch", m.mismatch, u);
  setI("Estimate/Sensors", m.sensors, u);
}

void DeviceMetrics::onCondition(const ConditionValues& c, std::int64_t utime) {
  setI("Condition/Last Trip", c.last_trip, utime);
  std::size_t i = 0;
  // Before an informative trip the combined estimate means nothing: null.
  if (byName("Condition/Preload Scale", &i)) set(i, c.valid ? valD(c.preload_scale) : Value{}, utime);
  if (byName("Condition/Preload Scale Sigma", &i)) set(i, c.valid ? valD(c.preload_sigma) : Value{}, utime);
  setB("Condition/Last Trip Informative", c.last_informative, utime);
  setI("Condition/Trips In Trend", c.trips_in_trend, utime);
  setI("Condition/Guide Preload Low", c.guide_preload_low, utime);
}

bool DeviceMetrics::setAlarm(const std::string& kind, int level, bool active, bool acked, bool shelved,
                             std::int64_t utime) {
  const std::string base = "Alarms/" + kind + "/";
  std::size_t i = 0;
  if (!byName(base + "Level", &i)) return false;
  set(i, valI(level), utime);
  setB((base + "Active").c_str(), active, utime);
  setB((base + "Acked").c_str(), acked, utime);
  setB((base + "Shelved").c_str(), shelved, utime);
  return true;
}

void DeviceMetrics::alarmsSettled(std::int64_t utime) {
  const auto& defs = deviceMetrics();
  for (std::size_t i = 0; i < defs.size(); ++i)
    if (defs[i].source == Source::Alarm && current_[i].is_null)
      set(i, defs[i].type == DataType::Boolean ? valB(false) : valI(0), utime);
}

Metric DeviceMetrics::full(std::size_t i) const {
  const MetricDef& d = deviceMetrics()[i];
  Metric m;
  m.name = d.name;
  m.has_alias = true;
  m.alias = aliasOf(i);
  m.has_type = true;
  m.type = d.type;
  m.units = d.units;
  m.timestamp_ms = ts_ms_[i];
  m.value = current_[i];
  return m;
}

Payload DeviceMetrics::birth(std::uint64_t now_ms) {
  Payload p;
  p.timestamp_ms = now_ms;
  p.has_seq = true;
  for (std::size_t i = 0; i < current_.size(); ++i) {
    p.metrics.push_back(full(i));
    if (p.metrics.back().timestamp_ms == 0) p.metrics.back().timestamp_ms = now_ms;
    reported_[i] = current_[i];
  }
  return p;
}

Payload DeviceMetrics::changes(Source src, std::uint64_t now_ms) {
  Payload p;
  p.timestamp_ms = now_ms;
  p.has_seq = true;
  const auto& defs = deviceMetrics();
  for (std::size_t i = 0; i < defs.size(); ++i) {
    if (defs[i].source != src || !differs(defs[i], current_[i], reported_[i], deadband_[i])) continue;
    Metric m;
    m.has_alias = true;
    m.alias = aliasOf(i);
    m.has_type = true;  // hosts decode the value by it (the specification allows it in DATA)
    m.type = defs[i].type;
    m.timestamp_ms = ts_ms_[i] ? ts_ms_[i] : now_ms;
    m.value = current_[i];
    p.metrics.push_back(std::move(m));
    reported_[i] = current_[i];
  }
  return p;
}

std::string nodeTopic(const std::string& group, const char* type, const std::string& edge) {
  return "spBv1.0/" + group + "/" + type + "/" + edge;
}

std::string deviceTopic(const std::string& group, const char* type, const std::string& edge,
                        const std::string& device) {
  return nodeTopic(group, type, edge) + "/" + device;
}

std::string stateTopic(const std::string& host) { return "spBv1.0/STATE/" + host; }

std::string deviceId(const std::string& shaft_name) {
  std::string d = shaft_name;
  for (char& c : d)
    if (c == '/' || c == '+' || c == '#') c = '_';
  return d;
}

bool parseState(const void* data, std::size_t size, bool& online, std::uint64_t& timestamp_ms) {
  if (!data || size == 0 || size > 1024) return false;
  const auto j = nlohmann::json::parse(static_cast<const char*>(data), static_cast<const char*>(data) + size, nullptr,
                                       /*allow_exceptions=*/false);
  if (!j.is_object()) return false;
  auto on = j.find("online");
  auto ts = j.find("timestamp");
  if (on == j.end() || !on->is_boolean() || ts == j.end() || !ts->is_number_integer() ||
      ts->get<std::int64_t>() < 0)
    return false;
  online = on->get<bool>();
  timestamp_ms = ts->get<std::uint64_t>();
  return true;
}

}  // namespace hoist::mqtt::sparkplug
