// hoist-mqtt's Sparkplug B edge node: see hoist/mqtt/sparkplug_node.hpp.
#include "hoist/mqtt/sparkplug_node.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "hoist/mqtt/sparkplug.hpp"

namespace hoist::mqtt::sparkplug {

namespace {
constexpr std::uint64_t kAliasBlock = 1000;  // device k: aliases 1000 (k + 1) ...; the node's: 1 ...
constexpr const char* kUser = "sparkplug";   // alarm_ack_t.user of a DCMD write (DCMD carries no user)

bool startsWith(const std::string& s, const std::string& p) { return s.size() >= p.size() && s.compare(0, p.size(), p) == 0; }
}  // namespace

Node::Node(NodeOptions o) : opt_(std::move(o)) {}

OutMsg Node::make(std::string topic, const Payload& p, MsgClass cls, int qos) const {
  OutMsg m;
  m.topic = std::move(topic);
  m.payload = encode(p);
  m.qos = qos;
  m.retain = false;
  m.cls = cls;
  m.sparkplug = p.has_seq;  // NDEATH has no seq: sent as it is
  return m;
}

OutMsg Node::nextWill() {
  bd_seq_ = (bd_seq_ + 1) % 256;
  return death();
}

OutMsg Node::death() const {
  return make(nodeTopic(opt_.group, "NDEATH", opt_.edge), nodeDeath(bd_seq_ < 0 ? 0 : bd_seq_, 0), MsgClass::Alarm, 1);
}

std::vector<std::string> Node::subscriptions() const {
  std::vector<std::string> t{nodeTopic(opt_.group, "NCMD", opt_.edge), nodeTopic(opt_.group, "DCMD", opt_.edge) + "/+"};
  if (waitsForHost()) t.push_back(stateTopic(opt_.primary_host));
  return t;
}

std::vector<OutMsg> Node::births(const NodeCounters& c, std::uint64_t now_ms) {
  births_ms_ = now_ms;
  born_ = true;
  rebirth_held_ = false;  // these births answer any held Rebirth
  std::vector<OutMsg> out;
  out.push_back(make(nodeTopic(opt_.group, "NBIRTH", opt_.edge), nodeBirth(bd_seq_ < 0 ? 0 : bd_seq_, opt_.version, c, now_ms),
                     MsgClass::Alarm));
  last_counters_ = c;
  for (auto& d : devices_)
    if (d.active) out.push_back(deviceBirth(d.shaft, now_ms));
  return out;
}

DeviceMetrics& Node::device(const std::string& shaft_name) {
  for (auto& d : devices_)
    if (d.shaft == shaft_name) {
      d.active = true;
      return d.metrics;
    }
  const std::uint64_t base = kAliasBlock * (devices_.size() + 1);
  devices_.push_back(Dev{shaft_name, deviceId(shaft_name), DeviceMetrics(base, opt_.deadband, opt_.deadbands)});
  return devices_.back().metrics;
}

bool Node::hasDevice(const std::string& shaft_name) const {
  for (const auto& d : devices_)
    if (d.shaft == shaft_name && d.active) return true;
  return false;
}

void Node::retireDevice(const std::string& shaft_name) {
  for (auto& d : devices_)
    if (d.shaft == shaft_name) d.active = false;
}

std::string Node::shaftOf(const std::string& device_id) const {
  for (const auto& d : devices_)
    if (d.id == device_id && d.active) return d.shaft;
  return {};
}

OutMsg Node::deviceBirth(const std::string& shaft_name, std::uint64_t now_ms) {
  return make(deviceTopic(opt_.group, "DBIRTH", opt_.edge, deviceId(shaft_name)), device(shaft_name).birth(now_ms),
              MsgClass::Alarm);
}

OutMsg Node::deviceDeath(const std::string& shaft_name, std::uint64_t now_ms) {
  Payload p;
  p.timestamp_ms = now_ms;
  p.has_seq = true;
  return make(deviceTopic(opt_.group, "DDEATH", opt_.edge, deviceId(shaft_name)), p, MsgClass::Alarm);
}

std::optional<OutMsg> Node::deviceData(const std::string& shaft_name, Source src, MsgClass cls, std::uint64_t now_ms) {
  Payload p = device(shaft_name).changes(src, now_ms);
  if (p.metrics.empty()) return std::nullopt;
  return make(deviceTopic(opt_.group, "DDATA", opt_.edge, deviceId(shaft_name)), p, cls);
}

std::optional<OutMsg> Node::nodeData(const NodeCounters& c, std::uint64_t now_ms) {
  Payload p = sparkplug::nodeData(c, last_counters_, now_ms);
  last_counters_ = c;
  if (p.metrics.empty()) return std::nullopt;
  return make(nodeTopic(opt_.group, "NDATA", opt_.edge), p, MsgClass::Health);
}

void Node::deviceCommands(const std::string& device_id, const Payload& p, std::vector<Command>& out) const {
  const Dev* dev = nullptr;
  for (const auto& d : devices_)
    if (d.id == device_id && d.active) dev = &d;
  if (p.metrics.empty()) {
    Command c;
    c.device = device_id;
    c.reject = CommandReject::BadPayload;
    c.detail = "a DCMD without metrics";
    out.push_back(c);
    return;
  }
  for (const Metric& m : p.metrics) {
    Command c;
    c.device = device_id;
    c.metric = !m.name.empty() ? m.name : "alias " + std::to_string(m.alias);
    auto refuse = [&](CommandReject r, std::string why) {
      c.reject = r;
      c.detail = std::move(why);
      out.push_back(c);
    };
    if (!dev) {
      refuse(CommandReject::UnknownMetric, "no device '" + printable(device_id) + "' on this edge node");
      continue;
    }
    std::size_t idx = 0;
    const MetricDef* def = !m.name.empty() ? dev->metrics.byName(m.name, &idx)
                           : m.has_alias   ? dev->metrics.byAlias(m.alias, &idx)
                                           : nullptr;
    if (!def) {
      refuse(CommandReject::UnknownMetric, "no metric " + printable(c.metric) + " on device '" + printable(device_id) + "'");
      continue;
    }
    if (m.has_alias && !m.name.empty() && m.alias != dev->metrics.aliasOf(idx)) {
      refuse(CommandReject::UnknownMetric, "name '" + printable(m.name) + "' and alias " + std::to_string(m.alias) +
                                               " are different metrics");
      continue;
    }
    c.metric = def->name;
    if (!def->writable) {
      refuse(CommandReject::ReadOnly, "'" + def->name + "' is read-only (writable: Alarms/<KIND>/Ack, Shelve, Unshelve)");
      continue;
    }
    if (m.value.is_null) {
      refuse(CommandReject::BadValue, "'" + def->name + "' written without a value");
      continue;
    }
    if (m.has_type && m.type != def->type && !(def->type == DataType::Double && isNumeric(m.type))) {
      refuse(CommandReject::BadValue, "'" + def->name + "' is " + typeName(def->type) + ", written as datatype " +
                                          std::to_string(static_cast<unsigned>(m.type)));
      continue;
    }
    // "Alarms/<KIND>/<Action>"
    const std::string rest = def->name.substr(7);
    const std::string kind = rest.substr(0, rest.find('/'));
    const std::string action = rest.substr(rest.find('/') + 1);
    nlohmann::json j = {{"kind", kind}, {"level", 0}, {"user", kUser}};
    if (action == "Ack" || action == "Unshelve") {
      if (!m.value.b) {
        refuse(CommandReject::BadValue, "'" + def->name + "' takes true (false requests nothing)");
        continue;
      }
      j["action"] = action == "Ack" ? 1 : 3;
    } else {  // Shelve: seconds
      if (!std::isfinite(m.value.d)) {
        refuse(CommandReject::BadValue, "'" + def->name + "' takes a finite number of seconds");
        continue;
      }
      j["action"] = 2;
      j["shelve_duration"] = m.value.d;
    }
    c.what = Command::What::Alarm;
    c.json = j.dump();
    out.push_back(c);
  }
}

bool Node::acceptRebirth(std::uint64_t now_ms) {
  if (!born_ || now_ms >= births_ms_ + kRebirthMinMs) return true;
  rebirth_held_ = true;
  ++rebirths_coalesced_;
  return false;
}

bool Node::rebirthDue(std::uint64_t now_ms) {
  if (!rebirth_held_ || now_ms < births_ms_ + kRebirthMinMs) return false;
  rebirth_held_ = false;
  return true;
}

Node::Inbound Node::onMessage(const std::string& topic, const void* data, std::size_t size, std::size_t max_bytes,
                              bool retained, std::vector<Command>& out, std::uint64_t now_ms) {
  if (waitsForHost() && topic == stateTopic(opt_.primary_host)) {
    bool online = false;
    std::uint64_t ts = 0;
    // Sparkplug 3.0 (see the header): a STATE older than the session known,
    // from the far future, or not a STATE at all is ignored.
    const bool ok = parseState(data, size, online, ts) && !(now_ms > 0 && ts > now_ms + kStateFutureMs);
    if (!ok || ts < host_ts_) {
      ++state_ignored_;
      return Inbound::StateIgnored;
    }
    if (online) {
      host_ts_ = ts;
      have_session_ = true;
      host_online_ = true;
      return Inbound::HostOnline;
    }
    host_online_ = false;
    // No session known (nothing to end, nothing to mark), or its own death.
    if (!have_session_ || ts == host_ts_) return Inbound::HostOffline;
    ++state_unverified_;
    return Inbound::HostOfflineUnverified;
  }
  const std::string ncmd = nodeTopic(opt_.group, "NCMD", opt_.edge);
  const std::string dcmd = nodeTopic(opt_.group, "DCMD", opt_.edge) + "/";
  const bool is_ncmd = topic == ncmd, is_dcmd = startsWith(topic, dcmd);
  if (!is_ncmd && !is_dcmd) return Inbound::NotOurs;
  const std::string device_id = is_dcmd ? topic.substr(dcmd.size()) : std::string();
  if (retained) {
    Command c;
    c.device = device_id;
    c.reject = CommandReject::Retained;
    c.detail = "retained commands are never executed";
    out.push_back(c);
    return Inbound::Commands;
  }
  std::string why;
  const auto p = decode(data, size, max_bytes, why);
  if (!p) {
    Command c;
    c.device = device_id;
    c.reject = why.rfind("oversized", 0) == 0 ? CommandReject::Oversized : CommandReject::BadPayload;
    c.detail = why.substr(0, 120);
    out.push_back(c);
    return Inbound::Commands;
  }
  if (is_dcmd) {
    deviceCommands(device_id, *p, out);
    return Inbound::Commands;
  }
  if (p->metrics.empty()) {
    Command c;
    c.reject = CommandReject::BadPayload;
    c.detail = "an NCMD without metrics";
    out.push_back(c);
  }
  for (const Metric& m : p->metrics) {
    Command c;
    c.metric = !m.name.empty() ? m.name : "alias " + std::to_string(m.alias);
    const bool rebirth = m.name == "Node Control/Rebirth" || (m.name.empty() && m.has_alias && m.alias == kRebirthAlias);
    if (!rebirth) {
      bool known = false;
      for (const auto& d : nodeMetrics()) known = known || d.name == m.name;
      c.reject = known ? CommandReject::ReadOnly : CommandReject::UnknownMetric;
      c.detail = known ? "'" + m.name + "' is read-only (writable: Node Control/Rebirth)"
                       : "no node metric " + printable(c.metric) + " (writable: Node Control/Rebirth)";
    } else if (m.value.is_null || (m.has_type && m.type != DataType::Boolean) || !m.value.b) {
      c.reject = CommandReject::BadValue;
      c.detail = "'Node Control/Rebirth' takes the Boolean true";
    } else {
      c.what = Command::What::Rebirth;
      c.metric = "Node Control/Rebirth";
    }
    out.push_back(c);
  }
  return Inbound::Commands;
}

}  // namespace hoist::mqtt::sparkplug
