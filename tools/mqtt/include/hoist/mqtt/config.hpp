// hoist/mqtt/config.hpp -- hoist-mqtt's configuration (TOML; docs/mqtt.md).
//
//   [broker]  url, client_id, keepalive, username, password, password_file,
//             password_env, reconnect_min, reconnect_max, connect_timeout
//   [tls]     ca_file, ca_path, cert_file, key_file, insecure, version
//   [bridge]  lcm_url, channel_prefixes, commands, cage_rate, health_period,
//             max_shafts, discovery_timeout, max_command_bytes, command_rate, command_burst,
//             max_command_age, alarm_sync_time
//   [buffer]  max_messages, max_alarm_events, stale_after, drop_stale,
//             dir, max_bytes, fsync_interval (store-and-forward journal)
//   [sparkplug] enabled, group_id, edge_node_id, primary_host_id, deadband,
//             [sparkplug.deadbands] "<metric name>" = deadband
//
// Every key is optional.  Rejected with hoist::io::ConfigError
// ("file:line: section.key: reason", exit status 2): TOML syntax errors,
// unknown sections and keys (with "did you mean"), wrong types, values out
// of range, a broker URL that is not mqtt:// or mqtts://HOST[:PORT], an
// unreadable password file, TLS files that cannot be read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace hoist::mqtt {

/// mqtt://HOST[:PORT] (default port 1883) or mqtts://HOST[:PORT] (TLS,
/// default 8883); HOST may be a bracketed IPv6 address ([::1]).
struct BrokerUrl {
  bool tls = false;
  std::string host;
  int port = 1883;
};

/// Throws std::invalid_argument with the reason.
BrokerUrl parseBrokerUrl(const std::string& url);

struct BridgeConfig {
  // [broker]
  std::string url = "mqtt://127.0.0.1:1883";
  std::string client_id;          ///< "" = hoist-mqtt-<hostname>
  int keepalive = 30;             ///< [s], 5..3600
  std::string username;           ///< "" = no authentication
  std::string password;           ///< discouraged (readable in the file); see password_file / password_env
  std::string password_file;      ///< first line of this file is the password
  std::string password_env = "HOIST_MQTT_PASSWORD";  ///< environment variable holding the password
  double reconnect_min = 0.5;     ///< first retry delay [s]
  double reconnect_max = 30.0;    ///< largest retry delay [s] (the delay doubles per failure)
  double connect_timeout = 10.0;  ///< no CONNACK within this: retry [s]

  // [tls] (used when any file is set or the URL is mqtts://)
  std::string ca_file, ca_path, cert_file, key_file;
  bool tls_insecure = false;      ///< skip the server host name check (testing only)
  std::string tls_version;        ///< "" (library default), "tlsv1.2" or "tlsv1.3"

  // [bridge]
  std::string lcm_url;                     ///< "" = $LCM_DEFAULT_URL, else LCM's default
  std::vector<std::string> channel_prefixes;  ///< empty = discover from *HOIST_{HEALTH,CAGE,ALARM} channels
  bool commands = true;                    ///< accept hoist/<shaft>/cmd/ack
  double cage_rate = 10.0;                 ///< cage states per second per shaft [Hz], (0, 1000]
  double health_period = 5.0;              ///< the bridge's own health topic period [s]
  int max_shafts = 64;                     ///< shafts bridged at most (configured + discovered)
  double discovery_timeout = 5.0;          ///< a discovered prefix silent this long ages out / may be replaced [s]
  int max_command_bytes = 1024;            ///< larger command payloads are rejected
  double command_rate = 2.0;               ///< commands per second per user and shaft (token bucket) [1/s]
  int command_burst = 10;                  ///< ... with this many at once; a shaft's total is 4x both
  double max_command_age = 60.0;           ///< a client's utime must be within this of the bridge's clock [s]; 0 = off
  double alarm_sync_time = 12.0;           ///< a shaft bridged this long: its alarm states are complete (re-announce 10 s) [s]

  // [buffer] (while the broker is unreachable or the socket is congested)
  int max_messages = 1000;       ///< cage and health messages buffered (oldest cage states dropped first)
  int max_alarm_events = 10000;  ///< alarm transitions buffered (never dropped for cage states)
  double stale_after = 1.0;      ///< a buffered cage state older than this when sent carries "stale": true [s]
  bool drop_stale = false;       ///< ... or is dropped (counted); alarm transitions are always sent
  // Store-and-forward (hoist/mqtt/journal.hpp): with a directory, what the
  // bridge cannot send goes to a bounded on-disk journal instead of the
  // memory buffer above, survives a restart, and is replayed in order on
  // reconnection; JSON messages then go out at QoS 1 (acknowledged).
  std::string journal_dir;                         ///< [buffer] dir; "" = memory buffer only
  std::uint64_t journal_max_bytes = 64ull << 20;   ///< [buffer] max_bytes: the journal file at most
  double fsync_interval = 1.0;                     ///< [buffer] fsync_interval [s]; 0 = every append

  // [sparkplug] (Sparkplug B mode instead of the JSON topics; docs/mqtt.md)
  bool sparkplug = false;              ///< enabled
  std::string sp_group_id;             ///< Sparkplug group id (required when enabled)
  std::string sp_edge_node_id;         ///< edge node id (required when enabled)
  std::string sp_primary_host_id;      ///< "" = no primary host; else wait for its STATE online before births
  double sp_deadband = 0.0;            ///< default deadband of every numeric device metric (in its units)
  std::map<std::string, double> sp_deadbands;
  // [history]: the trip records' database, read-only (hoist/mqtt/trip_feed.hpp):
  // retained hoist/<shaft>/trip/last and the Sparkplug Condition/... metrics.
  std::string history_url;    ///< "" = no trip feed; SQLite path (relative to the config) or postgresql://
  double history_poll = 5.0;  ///< seconds between checks for a new trip, 0.1..3600  ///< per metric name (hoist/mqtt/sparkplug_metrics.hpp)

  bool wantsTls() const;
  /// Throws std::invalid_argument("section.key: reason").
  void validate() const;
};

/// Applies `--sparkplug GROUP/EDGE`: enables Sparkplug mode with those ids.
/// Throws std::invalid_argument("--sparkplug: reason") if not GROUP/EDGE.
void applySparkplugOption(const std::string& group_edge, BridgeConfig& cfg);
/// "" if `id` is usable as a Sparkplug group, edge node or host id, else why.
std::string checkSparkplugId(const std::string& id);

/// Reads and validates a configuration file.  Throws hoist::io::ConfigError.
BridgeConfig loadBridgeConfig(const std::string& path);
/// Applies TOML text on top of `cfg` (tests); `source` names it in errors.
void applyBridgeToml(const std::string& text, const std::string& source, BridgeConfig& cfg);

/// The password: `password`, else the first line of `password_file`, else
/// the environment variable `password_env` (if set); "" if none.  Throws
/// hoist::io::ConfigError (key broker.password_file) if the file is unreadable.
std::string resolvePassword(const BridgeConfig& cfg, const std::string& source);

/// systemd credentials: when $CREDENTIALS_DIRECTORY is set and holds a
/// non-blank `mqtt-password` (`mqtt-tls-key`), password_file (key_file)
/// becomes that file (and `password` is cleared).  A blank credential (the
/// unit's SetCredential= default when the file is absent) changes nothing.
/// Returns the credentials used.
std::vector<std::string> applyCredentials(BridgeConfig& cfg);

/// MQTT shaft name of an LCM channel prefix: the prefix without one trailing
/// separator ('/', '_', '-', '.'), or "default" for the empty prefix.
std::string shaftName(const std::string& prefix);
/// True if `prefix` is a valid channel prefix (the daemon's rule: letters,
/// digits, _ - . /; at most 64 characters) whose shaft name is usable in a topic.
bool validChannelPrefix(const std::string& prefix, std::string* why = nullptr);

/// "" if shafts named `a` and `b` can be bridged side by side, else why not
/// (completing "'<prefix a>' and '<prefix b>' ..."): the same name; one's
/// topic tree inside the other's (hoist/x/ and hoist/x/alarm/: the bridge
/// never publishes inside another shaft's tree); or, with `sparkplug`, the
/// same Sparkplug device id (a/1 and a_1).  Used by validate() for the
/// configured prefixes and by discovery.
std::string shaftNameClash(const std::string& a, const std::string& b, bool sparkplug);

}  // namespace hoist::mqtt
