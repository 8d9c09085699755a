// hoist-mqtt configuration: see hoist/mqtt/config.hpp.
#include "hoist/mqtt/config.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

#include <toml++/toml.h>

#include "hoist/io/config.hpp"
#include "hoist/io/error.hpp"

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
      if (shaftName(channel_prefixes[i]) == shaftName(channel_prefixes[j]))
        bad("bridge.channel_prefixes", "'" + channel_prefixes[j] + "' and '" + channel_prefixes[i] +
                                           "' give the same shaft name '" + shaftName(channel_prefixes[i]) + "'");
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
}

namespace {

int lineOf(const toml::node& n) { return static_cast<int>(n.source().begin.line); }

struct Reader {
  const std::string& source;
  std::map<std::string, std::map<std::string, std::function<void(const toml::node&, const std::string&)>>> keys;
  std::map<std::string, int> lines;  // "section.key" -> line

  [[noreturn]] void fail(const toml::node& n, const std::string& key, const std::string& why) const {
    throw ConfigError(source, lineOf(n), key, why);
  }
  void str(const char* sec, const char* key, std::string& out) {
    keys[sec][key] = [this, &out](const toml::node& n, const std::string& k) {
      auto s = n.as_string();
      if (!s) fail(n, k, "must be a string");
      out = s->get();
    };
  }
  void num(const char* sec, const char* key, double& out) {
    keys[sec][key] = [this, &out](const toml::node& n, const std::string& k) {
      if (auto i = n.as_integer()) out = static_cast<double>(i->get());
      else if (auto f = n.as_floating_point()) out = f->get();
      else fail(n, k, "must be a number");
      if (!std::isfinite(out)) fail(n, k, "must be finite");
    };
  }
  void integer(const char* sec, const char* key, int& out) {
    keys[sec][key] = [this, &out](const toml::node& n, const std::string& k) {
      auto i = n.as_integer();
      if (!i) fail(n, k, "must be an integer");
      if (i->get() < -1000000000 || i->get() > 1000000000) fail(n, k, "out of range");
      out = static_cast<int>(i->get());
    };
  }
  void boolean(const char* sec, const char* key, bool& out) {
    keys[sec][key] = [this, &out](const toml::node& n, const std::string& k) {
      auto b = n.as_boolean();
      if (!b) fail(n, k, "must be true or false");
      out = b->get();
    };
  }
  void strings(const char* sec, const char* key, std::vector<std::string>& out) {
    keys[sec][key] = [this, &out](const toml::node& n, const std::string& k) {
      auto a = n.as_array();
      if (!a) fail(n, k, "must be an array of strings, e.g. [\"north/\", \"south/\"]");
      out.clear();
      for (const auto& e : *a) {
        auto s = e.as_string();
        if (!s) fail(e, k, "must be an array of strings");
        out.push_back(s->get());
      }
    };
  }

  void run(const toml::table& root) {
    std::vector<std::string> sections;
    for (const auto& s : keys) sections.push_back(s.first);
    for (const auto& [k, node] : root) {
      const std::string sec(k.str());
      auto it = keys.find(sec);
      if (it == keys.end()) {
        const std::string m = hoist::io::closestMatch(sec, sections);
        std::string msg = node.is_table() ? "unknown section" : "key outside a section";
        if (!m.empty()) msg += " (did you mean '" + m + "'?)";
        msg += "; known sections: broker, tls, bridge, buffer";
        fail(node, sec, msg);
      }
      const auto* tbl = node.as_table();
      if (!tbl) fail(node, sec, "must be a table [" + sec + "]");
      std::vector<std::string> names;
      for (const auto& kv : it->second) names.push_back(kv.first);
      for (const auto& [kk, value] : *tbl) {
        const std::string key(kk.str());
        const std::string full = sec + "." + key;
        auto h = it->second.find(key);
        if (h == it->second.end()) {
          const std::string m = hoist::io::closestMatch(key, names);
          std::string known;
          for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
          fail(value, full, "unknown key" + (m.empty() ? std::string() : " (did you mean '" + m + "'?)") +
                                "; known: " + known);
        }
        h->second(value, full);
        lines[full] = lineOf(value);
      }
    }
  }
};

void apply(const toml::table& root, const std::string& source, BridgeConfig& c) {
  Reader r{source, {}, {}};
  r.str("broker", "url", c.url);
  r.str("broker", "client_id", c.client_id);
  r.integer("broker", "keepalive", c.keepalive);
  r.str("broker", "username", c.username);
  r.str("broker", "password", c.password);
  r.str("broker", "password_file", c.password_file);
  r.str("broker", "password_env", c.password_env);
  r.num("broker", "reconnect_min", c.reconnect_min);
  r.num("broker", "reconnect_max", c.reconnect_max);
  r.num("broker", "connect_timeout", c.connect_timeout);
  r.str("tls", "ca_file", c.ca_file);
  r.str("tls", "ca_path", c.ca_path);
  r.str("tls", "cert_file", c.cert_file);
  r.str("tls", "key_file", c.key_file);
  r.boolean("tls", "insecure", c.tls_insecure);
  r.str("tls", "version", c.tls_version);
  r.str("bridge", "lcm_url", c.lcm_url);
  r.strings("bridge", "channel_prefixes", c.channel_prefixes);
  r.boolean("bridge", "commands", c.commands);
  r.num("bridge", "cage_rate", c.cage_rate);
  r.num("bridge", "health_period", c.health_period);
  r.integer("bridge", "max_shafts", c.max_shafts);
  r.num("bridge", "discovery_timeout", c.discovery_timeout);
  r.integer("bridge", "max_command_bytes", c.max_command_bytes);
  r.num("bridge", "command_rate", c.command_rate);
  r.integer("bridge", "command_burst", c.command_burst);
  r.num("bridge", "max_command_age", c.max_command_age);
  r.num("bridge", "alarm_sync_time", c.alarm_sync_time);
  r.integer("buffer", "max_messages", c.max_messages);
  r.integer("buffer", "max_alarm_events", c.max_alarm_events);
  r.num("buffer", "stale_after", c.stale_after);
  r.boolean("buffer", "drop_stale", c.drop_stale);
  r.str("buffer", "dir", c.journal_dir);
  double max_bytes = static_cast<double>(c.journal_max_bytes);
  r.num("buffer", "max_bytes", max_bytes);
  r.num("buffer", "fsync_interval", c.fsync_interval);
  r.run(root);
  if (max_bytes != static_cast<double>(c.journal_max_bytes)) {
    const int line = r.lines.count("buffer.max_bytes") ? r.lines["buffer.max_bytes"] : 0;
    if (!(max_bytes >= 65536.0 && max_bytes <= 1e12) || max_bytes != std::floor(max_bytes))
      throw ConfigError(source, line, "buffer.max_bytes", "must be a whole number of bytes in 65536..1e12");
    c.journal_max_bytes = static_cast<std::uint64_t>(max_bytes);
  }
  applyCredentials(c);  // before the files are checked: a credential replaces an unreadable file
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    const auto colon = what.find(": ");
    const std::string key = colon == std::string::npos ? std::string() : what.substr(0, colon);
    auto it = r.lines.find(key);
    throw ConfigError(source, it == r.lines.end() ? 0 : it->second, key,
                      colon == std::string::npos ? what : what.substr(colon + 2));
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
