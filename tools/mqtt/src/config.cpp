// hoist-mqtt configuration: see hoist/mqtt/config.hpp.
#include "hoist/mqtt/config.hpp"

#include <filesystem>

#include "hoist/history/config.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <toml++/toml.h>

#include "hoist/io/config.hpp"
#include "hoist/io/error.hpp"
#include "hoist/io/toml_section.hpp"
#include "hoist/mqtt/command.hpp"
#include "hoist/mqtt/sparkplug_metrics.hpp"

namespace hoist::mqtt {

using hoist::io::ConfigError;

BrokerUrl parseBrokerUrl(const std::string& url) {
  BrokerUrl u;
  std::string rest;
  if (url.rfind("mqtt://", 0) == 0) {
    rest = url.substr(7);
  } else if (url.rfind("mqtts://", 0) == 0) {
    u.tls = true;
    u.port = 8883;
    rest = url.substr(8);
  } else {
    throw std::invalid_argument("must start with mqtt:// or mqtts:// (e.g. mqtt://127.0.0.1:1883)");
  }
  if (!rest.empty() && rest.back() == '/') rest.pop_back();
  std::string port;
  if (!rest.empty() && rest.front() == '[') {  // [IPv6]:port
    const auto close = rest.find(']');
    if (close == std::string::npos) throw std::invalid_argument("unterminated '[' in the host");
    u.host = rest.substr(1, close - 1);
    const std::string tail = rest.substr(close + 1);
    if (!tail.empty()) {
      if (tail.front() != ':') throw std::invalid_argument("expected ':PORT' after ']'");
      port = tail.substr(1);
      if (port.empty()) throw std::invalid_argument("empty port");
    }
  } else {
    const auto colon = rest.rfind(':');
    u.host = rest.substr(0, colon);
    if (colon != std::string::npos) {
      port = rest.substr(colon + 1);
      if (port.empty()) throw std::invalid_argument("empty port");
    }
  }
  if (u.host.empty()) throw std::invalid_argument("no host (expected mqtt://HOST:PORT)");
  for (char c : u.host)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_' || c == ':'))
      throw std::invalid_argument("bad character in the host name (paths, users and queries are not supported)");
  if (!port.empty()) {
    if (port.size() > 5) throw std::invalid_argument("port must be 1..65535");
    int p = 0;
    for (char c : port) {
      if (c < '0' || c > '9') throw std::invalid_argument("port must be a number 1..65535");
      p = p * 10 + (c - '0');
    }
    if (p < 1 || p > 65535) throw std::invalid_argument("port must be 1..65535");
    u.port = p;
  }
  return u;
}

bool BridgeConfig::wantsTls() const {
  bool tls = !ca_file.empty() || !ca_path.empty() || !cert_file.empty() || !key_file.empty();
  try {
    tls = tls || parseBrokerUrl(url).tls;
  } catch (const std::invalid_argument&) {
  }
  return tls;
}

namespace {

[[noreturn]] void bad(const std::string& key, const std::string& why) {
  throw std::invalid_argument(key + ": " + why);
}

void range(const char* key, double v, double lo, double hi, bool lo_open = false) {
  if (!std::isfinite(v) || v > hi || (lo_open ? !(v > lo) : v < lo)) {
    std::ostringstream os;
    os.precision(10);
    os << "must be in " << (lo_open ? "(" : "[") << lo << ", " << hi << "], got " << v;
    bad(key, os.str());
  }
}

bool readable(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return static_cast<bool>(in);
}

}  // namespace

void BridgeConfig::validate() const {
  BrokerUrl u;
  try {
    u = parseBrokerUrl(url);
  } catch (const std::invalid_argument& e) {
    bad("broker.url", e.what());
  }
  for (char c : client_id)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'))
      bad("broker.client_id", "may contain only letters, digits and _ - .");
  if (client_id.size() > 64) bad("broker.client_id", "at most 64 characters");
  range("broker.keepalive", keepalive, 5, 3600);
  range("broker.reconnect_min", reconnect_min, 0.01, 3600.0);
  range("broker.reconnect_max", reconnect_max, reconnect_min, 3600.0);
  range("broker.connect_timeout", connect_timeout, 0.1, 600.0);
  if (!password.empty() && username.empty()) bad("broker.password", "a password needs broker.username");
  if (!password_file.empty() && username.empty()) bad("broker.password_file", "a password needs broker.username");
  if (!password_file.empty() && !readable(password_file))
    bad("broker.password_file", "cannot read '" + password_file + "'");
  for (const auto& [key, f] : {std::pair<const char*, const std::string*>{"tls.ca_file", &ca_file},
                               {"tls.cert_file", &cert_file},
                               {"tls.key_file", &key_file}})
    if (!f->empty() && !readable(*f)) bad(key, "cannot read '" + *f + "'");
  if (cert_file.empty() != key_file.empty()) bad(cert_file.empty() ? "tls.cert_file" : "tls.key_file",
                                                 "a client certificate needs both tls.cert_file and tls.key_file");
  if (wantsTls() && ca_file.empty() && ca_path.empty())
    bad("tls.ca_file", "TLS needs the broker's CA: set tls.ca_file or tls.ca_path");
  if (!tls_version.empty() && tls_version != "tlsv1.2" && tls_version != "tlsv1.3")
    bad("tls.version", "must be \"tlsv1.2\" or \"tlsv1.3\", got \"" + tls_version + "\"");
  std::string why;
  for (const auto& p : channel_prefixes)
    if (!validChannelPrefix(p, &why)) bad("bridge.channel_prefixes", "'" + p + "': " + why);
  for (std::size_t i = 0; i < channel_prefixes.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (const std::string clash = shaftNameClash(shaftName(channel_prefixes[j]), shaftName(channel_prefixes[i]),
                                                   sparkplug);
          !clash.empty())
        bad("bridge.channel_prefixes", "'" + channel_prefixes[j] + "' and '" + channel_prefixes[i] + "' " + clash);
  range("bridge.cage_rate", cage_rate, 0.0, 1000.0, true);
  range("bridge.health_period", health_period, 0.1, 3600.0);
  range("bridge.max_shafts", max_shafts, 1, 10000);
  range("bridge.discovery_timeout", discovery_timeout, 1.0, 3600.0);
  if (static_cast<int>(channel_prefixes.size()) > max_shafts)
    bad("bridge.channel_prefixes", std::to_string(channel_prefixes.size()) + " prefixes > bridge.max_shafts = " +
                                       std::to_string(max_shafts));
  range("bridge.max_command_bytes", max_command_bytes, 64, 65536);
  range("bridge.command_rate", command_rate, 0.0, 1000.0, true);
  range("bridge.command_burst", command_burst, 1, 10000);
  range("bridge.max_command_age", max_command_age, 0.0, 86400.0);
  range("bridge.alarm_sync_time", alarm_sync_time, 0.0, 3600.0);
  range("buffer.stale_after", stale_after, 0.0, 3600.0, true);
  range("buffer.max_messages", max_messages, 1, 1000000);
  range("buffer.max_alarm_events", max_alarm_events, 1, 1000000);
  if (journal_max_bytes < 65536 || journal_max_bytes > 1000000000000ull)
    bad("buffer.max_bytes", std::to_string(journal_max_bytes) + " is outside 65536..1e12");
  range("buffer.fsync_interval", fsync_interval, 0.0, 3600.0);
  if (sparkplug) {
    if (sp_group_id.empty()) bad("sparkplug.group_id", "Sparkplug mode needs a group id (or --sparkplug GROUP/EDGE)");
    if (sp_edge_node_id.empty())
      bad("sparkplug.edge_node_id", "Sparkplug mode needs an edge node id (or --sparkplug GROUP/EDGE)");
  }
  for (const auto& [key, id] : {std::pair<const char*, const std::string*>{"sparkplug.group_id", &sp_group_id},
                                {"sparkplug.edge_node_id", &sp_edge_node_id},
                                {"sparkplug.primary_host_id", &sp_primary_host_id}})
    if (!id->empty())
      if (const std::string why = checkSparkplugId(*id); !why.empty()) bad(key, "'" + printable(*id) + "': " + why);
  range("sparkplug.deadband", sp_deadband, 0.0, 1e12);
  for (const auto& [name, db] : sp_deadbands) {
    const sparkplug::MetricDef* d = sparkplug::findDeviceMetric(name);
    if (!d) {
      bad("sparkplug.deadbands", "'" + printable(name) + "' is not a device metric" +
                                     hoist::io::didYouMean(name, sparkplug::deviceMetricNames()));
    }
    if (!sparkplug::isNumeric(d->type))
      bad("sparkplug.deadbands", "'" + name + "' is not numeric (a deadband applies to numbers only)");
    if (!std::isfinite(db) || db < 0.0)
      bad("sparkplug.deadbands", "'" + name + "' must be a finite number >= 0");
  }
}

std::string checkSparkplugId(const std::string& id) {
  if (id.empty()) return "must not be empty";
  if (id.size() > 64) return "at most 64 characters";
  for (char c : id)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == ' '))
      return "may contain only letters, digits, space and _ - . (Sparkplug forbids / + # in ids)";
  return {};
}

void applySparkplugOption(const std::string& group_edge, BridgeConfig& cfg) {
  const auto slash = group_edge.find('/');
  if (slash == std::string::npos || group_edge.find('/', slash + 1) != std::string::npos)
    throw std::invalid_argument("--sparkplug: expected GROUP/EDGE (one '/'), got '" + printable(group_edge) + "'");
  const std::string g = group_edge.substr(0, slash), e = group_edge.substr(slash + 1);
  if (const std::string why = checkSparkplugId(g); !why.empty())
    throw std::invalid_argument("--sparkplug: group '" + printable(g) + "': " + why);
  if (const std::string why = checkSparkplugId(e); !why.empty())
    throw std::invalid_argument("--sparkplug: edge node '" + printable(e) + "': " + why);
  cfg.sparkplug = true;
  cfg.sp_group_id = g;
  cfg.sp_edge_node_id = e;
}

namespace {

using hoist::io::SectionReader;

/// The sections hoist-mqtt takes, in the order they are listed in errors.
const std::vector<std::string>& sectionNames() {
  static const std::vector<std::string> names{"broker", "tls", "bridge", "buffer", "sparkplug", "history"};
  return names;
}

void apply(const toml::table& root, const std::string& source, BridgeConfig& c) {
  // Top level: only known sections (keys outside a section are refused too).
  for (const auto& [k, node] : root) {
    const std::string sec(k.str());
    bool known = false;
    for (const auto& n : sectionNames()) known = known || n == sec;
    if (known) continue;
    std::string msg = node.is_table() ? "unknown section" : "key outside a section";
    msg += hoist::io::didYouMean(sec, sectionNames()) + "; known sections: ";
    for (std::size_t i = 0; i < sectionNames().size(); ++i) msg += (i ? ", " : "") + sectionNames()[i];
    throw ConfigError(source, hoist::io::lineOf(node), sec, msg);
  }
  auto str = [](std::string& out) { return [&out](const toml::node&, const std::string& v) { out = v; }; };
  SectionReader broker(root, "broker", source), tls(root, "tls", source), bridge(root, "bridge", source),
      buffer(root, "buffer", source), sp(root, "sparkplug", source), history(root, "history", source);
  broker.string("url", str(c.url));
  broker.string("client_id", str(c.client_id));
  broker.integer("keepalive", c.keepalive);
  broker.string("username", str(c.username));
  broker.string("password", str(c.password));
  broker.string("password_file", str(c.password_file));
  broker.string("password_env", str(c.password_env));
  broker.number("reconnect_min", c.reconnect_min);
  broker.number("reconnect_max", c.reconnect_max);
  broker.number("connect_timeout", c.connect_timeout);
  tls.string("ca_file", str(c.ca_file));
  tls.string("ca_path", str(c.ca_path));
  tls.string("cert_file", str(c.cert_file));
  tls.string("key_file", str(c.key_file));
  tls.boolean("insecure", c.tls_insecure);
  tls.string("version", str(c.tls_version));
  bridge.string("lcm_url", str(c.lcm_url));
  bridge.on("channel_prefixes", [&bridge, &c](const toml::node& n) {
    const auto* a = n.as_array();
    if (!a) bridge.fail(n, "channel_prefixes", "must be an array of strings, e.g. [\"north/\", \"south/\"]");
    c.channel_prefixes.clear();
    for (const auto& e : *a) {
      const auto* s = e.as_string();
      if (!s) bridge.fail(e, "channel_prefixes", "must be an array of strings");
      c.channel_prefixes.push_back(s->get());
    }
  });
  bridge.boolean("commands", c.commands);
  bridge.number("cage_rate", c.cage_rate);
  bridge.number("health_period", c.health_period);
  bridge.integer("max_shafts", c.max_shafts);
  bridge.number("discovery_timeout", c.discovery_timeout);
  bridge.integer("max_command_bytes", c.max_command_bytes);
  bridge.number("command_rate", c.command_rate);
  bridge.integer("command_burst", c.command_burst);
  bridge.number("max_command_age", c.max_command_age);
  bridge.number("alarm_sync_time", c.alarm_sync_time);
  buffer.integer("max_messages", c.max_messages);
  buffer.integer("max_alarm_events", c.max_alarm_events);
  buffer.number("stale_after", c.stale_after);
  buffer.boolean("drop_stale", c.drop_stale);
  buffer.string("dir", str(c.journal_dir));
  buffer.on("max_bytes", [&buffer, &c](const toml::node& n) {
    double v = -1.0;
    if (const auto* i = n.as_integer()) v = static_cast<double>(i->get());
    else if (const auto* f = n.as_floating_point()) v = f->get();
    if (!(v >= 65536.0 && v <= 1e12) || v != std::floor(v))
      buffer.fail(n, "max_bytes", "must be a whole number of bytes in 65536..1e12");
    c.journal_max_bytes = static_cast<std::uint64_t>(v);
  });
  buffer.number("fsync_interval", c.fsync_interval);
  sp.boolean("enabled", c.sparkplug);
  sp.string("group_id", str(c.sp_group_id));
  sp.string("edge_node_id", str(c.sp_edge_node_id));
  sp.string("primary_host_id", str(c.sp_primary_host_id));
  sp.number("deadband", c.sp_deadband);
  sp.on("deadbands", [&sp, &c](const toml::node& n) {
    const auto* t = n.as_table();
    if (!t) sp.fail(n, "deadbands", "must be a table [sparkplug.deadbands] of \"metric name\" = deadband");
    for (const auto& [k, v] : *t) {
      double d = 0.0;
      if (const auto* i = v.as_integer()) d = static_cast<double>(i->get());
      else if (const auto* f = v.as_floating_point()) d = f->get();
      else sp.fail(v, "deadbands." + std::string(k.str()), std::string("must be a number, got ") + hoist::io::typeName(v));
      c.sp_deadbands[std::string(k.str())] = d;
    }
  });
  history.on("url", [&history, &c, &source](const toml::node& n) {
    const auto* v = n.as_string();
    if (!v) history.fail(n, "url", "must be a string: a SQLite path or postgresql://...");
    try {  // checked now (a password in it is refused); relative to the configuration's folder
      const auto u = hoist::history::parseDatabaseUrl(v->get(), "history.url",
                                                      std::filesystem::path(source).parent_path().string());
      c.history_url = u.backend == hoist::history::Backend::Sqlite ? "sqlite://" + std::filesystem::absolute(u.target).string()
                                                                   : v->get();
    } catch (const std::invalid_argument& e) {
      history.fail(n, "url", e.what());
    }
  });
  history.on("poll_seconds", [&history, &c](const toml::node& n) {
    const auto* f = n.as_floating_point();
    const auto* i = n.as_integer();
    const double v = f ? f->get() : i ? static_cast<double>(i->get()) : -1.0;
    if (!(v >= 0.1 && v <= 3600.0)) history.fail(n, "poll_seconds", "must be a number of seconds in 0.1..3600");
    c.history_poll = v;
  });
  for (SectionReader* r : {&broker, &tls, &bridge, &buffer, &sp, &history}) r->run();
  const std::vector<const SectionReader*> readers{&broker, &tls, &bridge, &buffer, &sp, &history};
  applyCredentials(c);  // before the files are checked: a credential replaces an unreadable file
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    hoist::io::rethrowWithLine(e.what(), source, readers, false);
  }
}

}  // namespace

void applyBridgeToml(const std::string& text, const std::string& source, BridgeConfig& cfg) {
  apply(hoist::io::parseToml(text, source), source, cfg);
}

BridgeConfig loadBridgeConfig(const std::string& path) {
  BridgeConfig c;
  apply(hoist::io::loadTomlFile(path), path, c);
  return c;
}

std::string resolvePassword(const BridgeConfig& cfg, const std::string& source) {
  if (!cfg.password.empty()) return cfg.password;
  if (!cfg.password_file.empty()) {
    std::ifstream in(cfg.password_file, std::ios::binary);
    if (!in) throw ConfigError(source, 0, "broker.password_file", "cannot read '" + cfg.password_file + "'");
    std::string line;
    std::getline(in, line);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty())
      throw ConfigError(source, 0, "broker.password_file", "'" + cfg.password_file + "' is empty");
    return line;
  }
  if (!cfg.password_env.empty())
    if (const char* v = std::getenv(cfg.password_env.c_str()); v && *v) return v;
  return {};
}

std::vector<std::string> applyCredentials(BridgeConfig& cfg) {
  std::vector<std::string> used;
  const char* dir = std::getenv("CREDENTIALS_DIRECTORY");
  if (!dir || !*dir) return used;
  // Blank (only white space): the unit's SetCredential= default, i.e. no credential.
  auto nonEmpty = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    char ch = 0;
    for (int n = 0; in.get(ch) && n < 4096; ++n)
      if (!std::isspace(static_cast<unsigned char>(ch))) return true;
    return false;
  };
  const std::string pw = std::string(dir) + "/mqtt-password", key = std::string(dir) + "/mqtt-tls-key";
  if (nonEmpty(pw)) {
    cfg.password.clear();
    cfg.password_file = pw;
    used.push_back("mqtt-password");
  }
  if (nonEmpty(key)) {
    cfg.key_file = key;
    used.push_back("mqtt-tls-key");
  }
  return used;
}

std::string shaftName(const std::string& prefix) {
  std::string s = prefix;
  if (!s.empty() && (s.back() == '/' || s.back() == '_' || s.back() == '-' || s.back() == '.')) s.pop_back();
  return s.empty() ? std::string("default") : s;
}

std::string shaftNameClash(const std::string& a, const std::string& b, bool sparkplug) {
  if (a == b) return "give the same shaft name '" + a + "'";
  const std::string ta = a + "/", tb = b + "/";
  if (tb.compare(0, ta.size(), ta) == 0 || ta.compare(0, tb.size(), tb) == 0) {
    const std::string& inner = ta.size() > tb.size() ? a : b;
    const std::string& outer = ta.size() > tb.size() ? b : a;
    return "give shaft names whose topics overlap: 'hoist/" + inner + "/' lies inside shaft '" + outer +
           "''s tree 'hoist/" + outer + "/'";
  }
  if (sparkplug && sparkplug::deviceId(a) == sparkplug::deviceId(b))
    return "give shafts '" + a + "' and '" + b + "' the same Sparkplug device id '" + sparkplug::deviceId(a) +
           "' ('/', '+' and '#' become '_')";
  return "";
}

bool validChannelPrefix(const std::string& prefix, std::string* why) {
  auto no = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  if (prefix.size() > 64) return no("longer than 64 characters");
  for (char c : prefix)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '/'))
      return no("may contain only letters, digits and _ - . / (as hoist-twind's [service] channel_prefix)");
  const std::string name = shaftName(prefix);
  if (name.front() == '/' || name.back() == '/' || name.find("//") != std::string::npos)
    return no("its shaft name would make an MQTT topic with an empty level");
  if (name.rfind("_bridge", 0) == 0) return no("shaft names starting with '_bridge' are reserved for the bridge's own topics");
  return true;
}

}  // namespace hoist::mqtt
