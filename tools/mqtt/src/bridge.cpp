// hoist-mqtt's bridge: see hoist/mqtt/bridge.hpp.
#include "hoist/mqtt/bridge.hpp"

#include <mosquitto.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <spdlog/spdlog.h>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/bus/lcm_util.hpp"
#include "hoist/bus/subscriber.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/mqtt/command.hpp"
#include "hoist/mqtt/journal.hpp"
#include "hoist/mqtt/outbox.hpp"
#include "hoist/mqtt/sparkplug.hpp"
#include "hoist/mqtt/sparkplug_node.hpp"
#include "hoist/version.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/rt/log_rate_limiter.hpp"

namespace hoist::mqtt {

namespace {

using Clock = std::chrono::steady_clock;
using json = nlohmann::json;

using hoist::bus::kChannelAlarm;
using hoist::bus::kChannelAlarmAck;
using hoist::bus::kChannelCage;
using hoist::bus::kChannelEstimate;
using hoist::bus::kChannelForecast;
using hoist::bus::kChannelHealth;
constexpr int kMaxKindsPerShaft = 32;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

/// Alarm kinds are used in topic names: upper-case letters, digits and '_'.
bool validKind(const std::string& k) {
  if (k.empty() || k.size() > 32) return false;
  for (char c : k)
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return false;
  return true;
}

/// The names of alarm_t's levels and events (generated from alarm_t.lcm).
namespace alarm_names = hoist::msg::enums::alarm_t;

/// A token bucket: `rate` tokens per second, at most `burst`.
struct TokenBucket {
  double tokens = 0.0;
  Clock::time_point last{};
  bool take(Clock::time_point now, double rate, double burst) {
    if (last == Clock::time_point{}) tokens = burst;
    else tokens = std::min(burst, tokens + seconds(now - last) * rate);
    last = now;
    if (tokens < 1.0) return false;
    tokens -= 1.0;
    return true;
  }
  bool full(Clock::time_point now, double rate, double burst) const {
    return tokens + seconds(now - last) * rate >= burst;
  }
};
constexpr std::size_t kMaxUsersPerShaft = 256;  // rate-limit buckets kept per shaft

}  // namespace

struct Bridge::Impl {
  // ---- configuration ---------------------------------------------------------
  BridgeConfig cfg;
  BrokerUrl broker;
  std::string client_id;
  std::string status_topic, bridge_health_topic;

  // ---- LCM ---------------------------------------------------------------------
  std::string lcm_url;
  lcm::LCM lcm;
  /// The receive path for lcm_url (ours for udpm://: nothing stored per
  /// channel name; LCM's otherwise): hoist/bus/subscriber.hpp.
  hoist::bus::Subscriber rx{lcm};

  // ---- shafts ------------------------------------------------------------------
  struct AlarmState {
    std::optional<hoist::alarm_t> by_level[3];  // index = level (1 WARNING, 2 CRITICAL)
    hoist::alarm_t last;                        // latest event of either level
  };
  struct Shaft {
    std::string prefix, name;
    std::string t_cage, t_health, t_alarm, t_cmd, t_forecast, t_estimate;
    bool subscribed = false;       // command topic subscribed on the current connection
    // Discovery (hoist/mqtt/bridge.hpp): a discovered prefix is a candidate
    // until its health, with one non-zero instance id, has kept coming; only
    // then may it take a slot and its shaft name ("confirmed").
    bool configured = false, confirmed = false, bound = false;
    std::string t_result;          // hoist/<shaft>/cmd/result
    Clock::time_point bound_since{};
    Clock::time_point first_seen{}, last_seen{}, streak_start{}, last_refused_log{};
    std::int64_t streak_instance = 0;
    int streak = 0;                // health messages of streak_instance, gaps <= discovery_timeout
    std::int64_t states_asked = 0;  // daemon instance asked for its alarm states (requestAlarmStates)
    bool refused = false;          // confirmed-quality but no slot (table full) or its name is taken
    bool cage_new = false;
    bool alarms_settled = false;   // Sparkplug: alarm kinds never heard of are known inactive
    hoist::cage_state_t cage{};
    bool estimate_new = false;  // like the cage: the latest estimate at [bridge] cage_rate
    hoist::estimate_t estimate{};
    std::uint64_t estimates_in = 0, estimates_out = 0;
    std::map<std::string, AlarmState> alarms;  // by kind
    std::int64_t instance_id = 0;
    std::uint64_t cage_in = 0, cage_out = 0, health_in = 0, alarms_in = 0, commands = 0, forecasts_in = 0;
    TokenBucket cmd_total;                         // the shaft's commands, all users
    std::map<std::string, TokenBucket> cmd_users;  // per user (bounded: kMaxUsersPerShaft)
    Clock::time_point last_health{};
  };
  std::map<std::string, Shaft> shafts;           // by prefix: configured, confirmed and candidate prefixes
  std::map<std::string, std::string> cmd_topics;  // command topic -> prefix bound to its shaft name
  std::map<std::string, std::string> bound;       // shaft name -> the prefix published under it
  bool discover = false;
  std::uint64_t refused_total = 0, evicted_candidates = 0, aged_out = 0;
  bool table_full_logged = false;
  Clock::time_point last_discovery_sweep{};

  // ---- MQTT --------------------------------------------------------------------
  struct mosquitto* mosq = nullptr;
  enum class Conn { Disconnected, Connecting, Connected } conn = Conn::Disconnected;
  Clock::time_point next_attempt{}, connecting_since{}, connected_since_steady{};
  std::int64_t connected_since_utime = 0;
  double delay = 0.0;
  bool failing = false;     // the current series of attempts has been logged as failing
  std::string last_error;
  // Set by libmosquitto's callbacks (called inside mosquitto_loop, this thread).
  bool cb_connack = false;
  int cb_connack_rc = 0;
  bool cb_disconnected = false;
  int cb_disconnect_rc = 0;

  Outbox outbox;

  // ---- store-and-forward ([buffer] dir; hoist/mqtt/journal.hpp) ---------------------
  // While the broker is away (or the socket is congested, or too many
  // messages await their acknowledgement) messages go to the journal, in
  // order; on reconnection it is replayed before live data.  The messages
  // handed to libmosquitto and not yet acknowledged (QoS 1) are kept here:
  // libmosquitto resends them itself after a reconnection, and at shutdown
  // the ones still unacknowledged go back to the front of the journal.
  static constexpr std::size_t kMaxInflight = 256;
  std::unique_ptr<Journal> journal;
  JournalReport journal_report;
  struct Inflight {
    int mid;
    OutMsg m;
  };
  std::deque<Inflight> inflight;
  std::set<std::string> journaled_alarm_topics;  // alarm states waiting in the journal (no republish needed)
  std::uint64_t journal_replayed = 0, journal_fallback = 0, journal_prepended = 0;
  std::uint64_t journal_alarm_drops_seen = 0;
  // ---- Sparkplug B mode ([sparkplug] enabled; hoist/mqtt/sparkplug_node.hpp) ----
  // The JSON topics are not used then (the bridge's own health topic stays).
  std::unique_ptr<sparkplug::Node> sp;
  bool sp_session = false;          // births sent on this connection: live data may go out
  Clock::time_point sp_births_at{};  // messages queued before it are history (is_historical)
  std::uint64_t sp_births = 0, sp_rebirths = 0, sp_host_offline = 0;

  // ---- counters ----------------------------------------------------------------
  Clock::time_point started = Clock::now();
  std::int64_t started_utime = hoist::bus::wallUtime();
  std::uint64_t connects = 0, disconnects = 0, connect_failures = 0;
  std::uint64_t lcm_messages = 0, ignored_channels = 0, alarm_rejected = 0;
  std::map<std::string, std::uint64_t> decode_errors;  // "cage/truncated" -> n
  std::uint64_t published = 0, publish_errors = 0;
  std::uint64_t cmd_received = 0, cmd_forwarded = 0, cmd_rejected = 0, cmd_lcm_failures = 0;
  std::uint64_t results_published = 0, results_dropped = 0, stale_marked = 0, stale_dropped = 0;
  TokenBucket result_budget;  // cmd/result messages: at most 20/s (bursts of 50), so a flood is not echoed
  std::array<std::uint64_t, kCommandRejects> cmd_by_reason{};
  /// A few log lines per 10 s for commands and for LCM input, then counted
  /// (hoist/rt/log_rate_limiter.hpp).
  static constexpr int kCmdLog = 0, kLcmLog = 1;
  hoist::rt::LogRateLimiter<2> log_limit{5, 10.0};
  double sinceStart(Clock::time_point t) const { return std::chrono::duration<double>(t - started).count(); }
  bool logged_too_many_shafts = false;

  Impl(const BridgeConfig& c, const std::string& password)
      : cfg(c),
        broker(parseBrokerUrl(c.url)),
        lcm_url(hoist::bus::resolveLcmUrl(c.lcm_url)),
        lcm(lcm_url),
        outbox(static_cast<std::size_t>(c.max_messages), static_cast<std::size_t>(c.max_alarm_events)) {
    if (!lcm.good())
      throw std::runtime_error("cannot open LCM (" + hoist::bus::describeLcmUrl(lcm_url) +
                               "); is loopback multicast enabled? (scripts/setup.sh)");
    client_id = cfg.client_id;
    if (client_id.empty()) {
      char host[256] = "";
      gethostname(host, sizeof host - 1);
      client_id = "hoist-mqtt-";
      for (const char* p = host; *p && client_id.size() < 60; ++p)
        client_id.push_back(std::isalnum(static_cast<unsigned char>(*p)) || *p == '-' ? *p : '_');
    }
    status_topic = "hoist/_bridge/" + client_id + "/status";
    bridge_health_topic = "hoist/_bridge/" + client_id + "/health";

    if (cfg.sparkplug) {
      if (!sparkplug::available()) throw std::runtime_error(sparkplugMissing());
      sparkplug::NodeOptions o;
      o.group = cfg.sp_group_id;
      o.edge = cfg.sp_edge_node_id;
      o.primary_host = cfg.sp_primary_host_id;
      o.version = std::string("hoist-mqtt ") + hoist::kVersionString;
      o.deadband = cfg.sp_deadband;
      o.deadbands = cfg.sp_deadbands;
      sp = std::make_unique<sparkplug::Node>(o);
    }
    discover = cfg.channel_prefixes.empty();
    for (const auto& p : cfg.channel_prefixes) addShaft(p, true);
    std::string why;
    if (!rx.open(lcm_url, why)) throw std::runtime_error(why);
    // One subscription for every shaft; as LCM's regular expression (anchored):
    // ".*(HOIST_CAGE|HOIST_HEALTH|HOIST_ALARM|HOIST_FORECAST|HOIST_ESTIMATE)".
    rx.addMatching(
        [](std::string_view n) {
          auto ends = [&](std::string_view suffix) {
            return n.size() >= suffix.size() && n.substr(n.size() - suffix.size()) == suffix;
          };
          return ends(kChannelCage) || ends(kChannelHealth) || ends(kChannelAlarm) || ends(kChannelForecast) ||
                 ends(kChannelEstimate);
        },
        ".*(" + std::string(kChannelCage) + "|" + std::string(kChannelHealth) + "|" + std::string(kChannelAlarm) +
            "|" + std::string(kChannelForecast) + "|" + std::string(kChannelEstimate) + ")",
        [this](const lcm::ReceiveBuffer* rb, const std::string& channel) { onLcm(rb, channel); });

    mosq = mosquitto_new(client_id.c_str(), /*clean_session=*/true, this);
    if (!mosq) throw std::runtime_error("mosquitto_new failed: " + std::string(std::strerror(errno)));
    mosquitto_int_option(mosq, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
    if (!sp) {  // Sparkplug: the will (NDEATH) is set before each connection
      const std::string will =
          json{{"online", false}, {"client_id", client_id}, {"reason", "connection lost (last will)"}}.dump();
      check(mosquitto_will_set(mosq, status_topic.c_str(), static_cast<int>(will.size()), will.data(), 1, true),
            "will");
    }
    if (!cfg.username.empty())
      check(mosquitto_username_pw_set(mosq, cfg.username.c_str(), password.empty() ? nullptr : password.c_str()),
            "username/password");
    if (cfg.wantsTls()) {
      check(mosquitto_tls_set(mosq, cfg.ca_file.empty() ? nullptr : cfg.ca_file.c_str(),
                              cfg.ca_path.empty() ? nullptr : cfg.ca_path.c_str(),
                              cfg.cert_file.empty() ? nullptr : cfg.cert_file.c_str(),
                              cfg.key_file.empty() ? nullptr : cfg.key_file.c_str(), nullptr),
            "TLS files (tls.ca_file, tls.cert_file, tls.key_file)");
      check(mosquitto_tls_opts_set(mosq, 1, cfg.tls_version.empty() ? nullptr : cfg.tls_version.c_str(), nullptr),
            "tls.version");
      if (cfg.tls_insecure) check(mosquitto_tls_insecure_set(mosq, true), "tls.insecure");
    }
    mosquitto_connect_callback_set(mosq, [](struct mosquitto*, void* obj, int rc) {
      auto* self = static_cast<Impl*>(obj);
      self->cb_connack = true;
      self->cb_connack_rc = rc;
    });
    mosquitto_disconnect_callback_set(mosq, [](struct mosquitto*, void* obj, int rc) {
      auto* self = static_cast<Impl*>(obj);
      self->cb_disconnected = true;
      self->cb_disconnect_rc = rc;
    });
    mosquitto_message_callback_set(mosq, [](struct mosquitto*, void* obj, const struct mosquitto_message* m) {
      static_cast<Impl*>(obj)->onMqttMessage(m);
    });
    mosquitto_publish_callback_set(mosq, [](struct mosquitto*, void* obj, int mid) {
      static_cast<Impl*>(obj)->onAcknowledged(mid);
    });
    delay = cfg.reconnect_min;
    if (!cfg.journal_dir.empty()) openJournal();
  }

  void openJournal() {
    journal = std::make_unique<Journal>();
    journal_report = journal->open(cfg.journal_dir, {cfg.journal_max_bytes, cfg.fsync_interval});
    spdlog::info("store-and-forward journal {}: {}{} messages to replay ({} bytes), max_bytes {}, fsync every {} s",
                 journal_report.path, journal_report.created ? "new; " : "", journal_report.recovered,
                 journal_report.recovered_bytes, cfg.journal_max_bytes, cfg.fsync_interval);
    if (!journal_report.problem.empty())
      spdlog::error("store-and-forward journal {}: {}; {} bytes from there on skipped (the messages before it are "
                    "replayed; see journal.corrupt_bytes in the bridge's health)",
                    journal_report.path, journal_report.problem, journal_report.skipped_bytes);
  }

  /// A QoS 1 message was acknowledged by the broker (PUBACK).
  void onAcknowledged(int mid) {
    for (auto it = inflight.begin(); it != inflight.end(); ++it)
      if (it->mid == mid) {
        inflight.erase(it);
        return;
      }
  }

  ~Impl() {
    if (mosq) mosquitto_destroy(mosq);
  }

  static std::string sparkplugMissing() {
    return "[sparkplug] enabled, but this hoist-mqtt was built without nanopb (apt-get install nanopb "
           "libnanopb-dev, then rebuild)";
  }

  void check(int rc, const char* what) {
    if (rc != MOSQ_ERR_SUCCESS)
      throw std::runtime_error(std::string("libmosquitto refused ") + what + ": " + mosquitto_strerror(rc));
  }

  std::string brokerText() const {
    return std::string(broker.tls ? "mqtts://" : "mqtt://") + broker.host + ":" + std::to_string(broker.port);
  }

  // ---- shafts ------------------------------------------------------------------

  Shaft* addShaft(const std::string& prefix, bool configured) {
    Shaft s;
    s.prefix = prefix;
    s.name = shaftName(prefix);
    const std::string base = "hoist/" + s.name + "/";
    s.t_cage = base + "cage";
    s.t_health = base + "health";
    s.t_alarm = base + "alarm/";
    s.t_cmd = base + "cmd/ack";
    s.t_result = base + "cmd/result";
    s.t_forecast = base + "forecast";
    s.t_estimate = base + "estimate";
    s.configured = configured;
    s.first_seen = s.last_seen = Clock::now();
    auto [it, fresh] = shafts.emplace(prefix, std::move(s));
    if (configured) bind(it->second);
    return &it->second;
  }

  /// Publishes the shaft under its name: topics, command subscription, its alarm states.
  void bind(Shaft& s) {
    if (auto old = bound.find(s.name); old != bound.end() && old->second != s.prefix) {
      auto o = shafts.find(old->second);
      if (o != shafts.end()) o->second.bound = false;
      spdlog::warn("shaft '{}': now bridged from LCM prefix '{}' (was '{}', whose health stopped)", s.name,
                   printable(s.prefix), printable(old->second));
    }
    s.bound = true;
    s.bound_since = Clock::now();
    s.refused = false;
    bound[s.name] = s.prefix;
    cmd_topics[s.t_cmd] = s.prefix;
    const std::string base = "hoist/" + s.name + "/";
    if (sp)
      spdlog::info("shaft '{}': LCM {}HOIST_{{CAGE,HEALTH,ALARM,FORECAST,ESTIMATE}} -> Sparkplug device "
                   "spBv1.0/{}/{{DBIRTH,DDATA,DCMD}}/{}/{}{}",
                   s.name, s.prefix, cfg.sp_group_id, cfg.sp_edge_node_id, sparkplug::deviceId(s.name),
                   s.configured ? "" : fmt::format(" (discovered: daemon instance {})", s.streak_instance));
    else  // the JSON topics
      spdlog::info("shaft '{}': LCM {}HOIST_{{CAGE,HEALTH,ALARM,FORECAST,ESTIMATE}} -> "
                   "{}{{cage,health,alarm/<KIND>,forecast,estimate}}{}{}",
                   s.name, s.prefix, base,
                   cfg.commands ? ", " + s.t_cmd + " -> " + hoist::bus::channel(s.prefix, kChannelAlarmAck) : "",
                   s.configured ? "" : fmt::format(" (discovered: daemon instance {})", s.streak_instance));
    if (sp) {
      sparkplug::DeviceMetrics& d = sp->device(s.name);
      for (const auto& [kind, a] : s.alarms) setAlarmMetrics(d, kind, a);
      if (sp_session) sendOne(sp->deviceBirth(s.name, nowMs()), false);  // a new device after the NBIRTH
      return;
    }
    if (conn == Conn::Connected) subscribeCommands(s);
    for (const auto& [kind, a] : s.alarms) publishAlarmState(s, kind, a);
    // Discovered: bound on its daemon's health, which it has heard.
    if (!s.configured) requestAlarmStates(s, s.streak_instance);
  }

  /// Asks the shaft's daemon (instance `instance`, whose health was heard) to
  /// re-announce every alarm's current state now (alarm_ack_t
  /// ACTION_REANNOUNCE; it changes nothing, and the daemon honours one a
  /// second), once per daemon instance: an alarm raised before this bridge
  /// started, or before the shaft was discovered, is published at once as its
  /// state, not first as a CLEAR.  Sent also with --no-commands (it commands
  /// nothing); never into the void (no daemon heard yet).
  void requestAlarmStates(Shaft& s, std::int64_t instance) {
    if (instance == 0 || instance == s.states_asked) return;
    s.states_asked = instance;
    hoist::alarm_ack_t m{};
    m.utime = hoist::bus::wallUtime();
    m.kind = "*";
    m.action = hoist::alarm_ack_t::ACTION_REANNOUNCE;
    m.user = client_id;
    const std::string channel = hoist::bus::channel(s.prefix, kChannelAlarmAck);
    if (lcm.publish(channel, &m) != 0) spdlog::warn("shaft '{}': cannot ask for its alarm states on {}", s.name, channel);
  }

  std::size_t slotsUsed() const {
    std::size_t n = 0;
    for (const auto& [p, s] : shafts) n += (s.configured || s.confirmed) ? 1 : 0;
    return n;
  }

  double healthTimeout() const { return cfg.discovery_timeout; }

  /// Health silent for longer than discovery_timeout.
  bool silent(const Shaft& s, Clock::time_point now) const {
    return seconds(now - (s.health_in ? s.last_health : s.last_seen)) > healthTimeout();
  }

  /// A candidate has shown a daemon's health at the health rate: give it a
  /// slot and its name, if it can have them.
  void tryConfirm(Shaft& s, Clock::time_point now) {
    if (s.confirmed || s.configured) return;
    if (s.streak < 3 || seconds(now - s.streak_start) < 1.0) return;
    // Its name: free, or held by a prefix whose health has stopped.
    auto b = bound.find(s.name);
    Shaft* holder = nullptr;
    if (b != bound.end())
      if (auto h = shafts.find(b->second); h != shafts.end()) holder = &h->second;
    if (holder && (holder->configured || !silent(*holder, now))) {
      refuseLog(s, now, fmt::format("shaft name '{}' is already bridged from prefix '{}'{}: both are reported in the "
                                    "bridge's health (discovery.conflicts) and commands to hoist/{}/cmd/ack are "
                                    "refused until one stops; list the plant's shafts with --channel-prefix",
                                    s.name, printable(holder->prefix), holder->configured ? " (configured)" : "",
                                    s.name));
      return;
    }
    if (!holder && slotsUsed() >= static_cast<std::size_t>(cfg.max_shafts)) {
      // Table full: a confirmed shaft whose health has stopped makes room.
      Shaft* victim = nullptr;
      for (auto& [p, o] : shafts)
        if (o.confirmed && !o.configured && silent(o, now) && (!victim || o.last_health < victim->last_health))
          victim = &o;
      if (!victim) {
        refuseLog(s, now, fmt::format("the shaft table is full ({} shafts, [bridge] max_shafts): prefix '{}' is not "
                                      "bridged; list the plant's shafts with --channel-prefix",
                                      cfg.max_shafts, printable(s.prefix)));
        return;
      }
      spdlog::warn("shaft '{}' (prefix '{}'): its health stopped; its slot goes to prefix '{}'", victim->name,
                   printable(victim->prefix), printable(s.prefix));
      forget(victim->prefix);
    }
    s.confirmed = true;
    bind(s);
  }

  void refuseLog(Shaft& s, Clock::time_point now, const std::string& why) {
    if (!s.refused) ++refused_total;
    const bool first = !s.refused;
    s.refused = true;
    if (first || now - s.last_refused_log > std::chrono::seconds(60)) {
      s.last_refused_log = now;
      std::int64_t suppressed = 0;
      if (log_limit.allow(kLcmLog, sinceStart(now), suppressed)) spdlog::warn("discovery: {}", why);
    }
  }

  void forget(const std::string& prefix) {
    auto it = shafts.find(prefix);
    if (it == shafts.end()) return;
    if (it->second.bound) {
      if (sp && sp_session) sendOne(sp->deviceDeath(it->second.name, nowMs()), false);
      if (sp) sp->retireDevice(it->second.name);
      bound.erase(it->second.name);
      cmd_topics.erase(it->second.t_cmd);
      if (conn == Conn::Connected && it->second.subscribed)
        mosquitto_unsubscribe(mosq, nullptr, it->second.t_cmd.c_str());
    }
    shafts.erase(it);
  }

  /// Candidates that stopped talking age out (a single forged datagram never
  /// holds a slot for long).
  void sweepDiscovery(Clock::time_point now) {
    if (!discover || now - last_discovery_sweep < std::chrono::milliseconds(250)) return;
    last_discovery_sweep = now;
    for (auto it = shafts.begin(); it != shafts.end();) {
      const Shaft& s = it->second;
      if (!s.configured && !s.confirmed && seconds(now - s.last_seen) > healthTimeout()) {
        ++aged_out;
        it = shafts.erase(it);
      } else {
        ++it;
      }
    }
    if (table_full_logged && !tableFull()) {
      table_full_logged = false;
      spdlog::info("discovery: the shaft table has room again");
    }
  }

  bool tableFull() const {
    if (slotsUsed() < static_cast<std::size_t>(cfg.max_shafts)) return false;
    for (const auto& [p, s] : shafts)
      if (s.refused) return true;
    return false;
  }

  /// The slot of `prefix`: a configured or known one, else (discovery) a new
  /// candidate.  Candidates are bounded (4 x max_shafts); when full, the
  /// weakest one (shortest health streak, then least recently heard) goes.
  Shaft* shaftFor(const std::string& prefix) {
    if (auto it = shafts.find(prefix); it != shafts.end()) {
      it->second.last_seen = Clock::now();
      return &it->second;
    }
    if (!discover) return nullptr;
    std::string why;
    if (!validChannelPrefix(prefix, &why)) return nullptr;
    std::size_t candidates = 0;
    Shaft* weakest = nullptr;
    for (auto& [p, s] : shafts) {
      if (s.configured || s.confirmed) continue;
      ++candidates;
      if (!weakest || s.streak < weakest->streak || (s.streak == weakest->streak && s.last_seen < weakest->last_seen))
        weakest = &s;
    }
    if (candidates >= 4 * static_cast<std::size_t>(cfg.max_shafts) && weakest) {
      ++evicted_candidates;
      forget(weakest->prefix);
    }
    return addShaft(prefix, false);
  }

  void onHealth(Shaft& s, const hoist::health_t& m) {
    const auto now = Clock::now();
    const bool continues = s.streak > 0 && m.instance_id == s.streak_instance &&
                           seconds(now - s.last_health) <= healthTimeout();
    if (m.instance_id == 0) {
      s.streak = 0;
    } else if (continues) {
      ++s.streak;
    } else {
      s.streak = 1;
      s.streak_instance = m.instance_id;
      s.streak_start = now;
    }
    ++s.health_in;
    s.last_health = now;
    if (!s.bound) return tryConfirm(s, now);
    requestAlarmStates(s, m.instance_id);
    if (s.instance_id != 0 && m.instance_id != s.instance_id) daemonRestarted(s, m);
    s.instance_id = m.instance_id;
    if (sp) {
      sp->device(s.name).onHealth(m);
      return sparkplugData(s, sparkplug::Source::Health, MsgClass::Health);
    }
    publish({s.t_health, hoist::msg::toJson(m).dump(), 0, false, MsgClass::Health});
  }

  /// Prefixes other than the bound one that map to `name` (reported, never silently dropped).
  std::vector<std::string> rivals(const Shaft& s) const {
    std::vector<std::string> out;
    for (const auto& [p, o] : shafts)
      if (&o != &s && o.name == s.name) out.push_back(p);
    return out;
  }

  // ---- LCM side ------------------------------------------------------------------

  void decodeError(const char* type, hoist::msg::DecodeStatus st, const std::string& channel) {
    ++decode_errors[std::string(type) + "/" + hoist::msg::toString(st)];
    std::int64_t suppressed = 0;
    if (log_limit.allow(kLcmLog, sinceStart(Clock::now()), suppressed))
      spdlog::warn("undecodable {} on {} ({}){}", type, printable(channel), hoist::msg::toString(st),
                   suppressed ? fmt::format(" ({} similar lines suppressed)", suppressed) : "");
  }

  void onLcm(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    try {
      ++lcm_messages;
      auto ends = [&](std::string_view suffix) {
        return channel.size() >= suffix.size() &&
               std::string_view(channel).substr(channel.size() - suffix.size()) == suffix;
      };
      if (ends(kChannelCage)) {
        Shaft* s = shaftFor(channel.substr(0, channel.size() - kChannelCage.size()));
        if (!s) return void(++ignored_channels);
        hoist::cage_state_t m;
        const auto st = hoist::msg::checkedDecode(rb->data, rb->data_size, m);
        if (st != hoist::msg::DecodeStatus::ok) return decodeError("cage_state_t", st, channel);
        s->cage = m;
        s->cage_new = s->bound;
        ++s->cage_in;
      } else if (ends(kChannelHealth)) {
        Shaft* s = shaftFor(channel.substr(0, channel.size() - kChannelHealth.size()));
        if (!s) return void(++ignored_channels);
        hoist::health_t m;
        const auto st = hoist::msg::checkedDecode(rb->data, rb->data_size, m);
        if (st != hoist::msg::DecodeStatus::ok) return decodeError("health_t", st, channel);
        onHealth(*s, m);
      } else if (ends(kChannelAlarm)) {
        Shaft* s = shaftFor(channel.substr(0, channel.size() - kChannelAlarm.size()));
        if (!s) return void(++ignored_channels);
        hoist::alarm_t m;
        const auto st = hoist::msg::checkedDecode(rb->data, rb->data_size, m);
        if (st != hoist::msg::DecodeStatus::ok) return decodeError("alarm_t", st, channel);
        onAlarm(*s, m);
      } else if (ends(kChannelForecast)) {
        // The look-ahead forecast, as JSON (nested scenarios), at
        // the daemon's rate (~1 Hz); queued like health (low rate).
        Shaft* s = shaftFor(channel.substr(0, channel.size() - kChannelForecast.size()));
        if (!s) return void(++ignored_channels);
        hoist::forecast_t m;
        const auto st = hoist::msg::checkedDecode(rb->data, rb->data_size, m);
        if (st != hoist::msg::DecodeStatus::ok) return decodeError("forecast_t", st, channel);
        ++s->forecasts_in;
        if (s->bound && sp) {
          sp->device(s->name).onForecast(m);
          sparkplugData(*s, sparkplug::Source::Forecast, MsgClass::Health);
        } else if (s->bound) {
          publish({s->t_forecast, hoist::msg::toJson(m).dump(), 0, false, MsgClass::Health});
        }
      } else if (ends(kChannelEstimate)) {
        // The load estimate, at the cage rate; sent like the cage
        // state (the latest one at [bridge] cage_rate, QoS 0, not retained).
        Shaft* s = shaftFor(channel.substr(0, channel.size() - kChannelEstimate.size()));
        if (!s) return void(++ignored_channels);
        hoist::estimate_t m;
        const auto st = hoist::msg::checkedDecode(rb->data, rb->data_size, m);
        if (st != hoist::msg::DecodeStatus::ok) return decodeError("estimate_t", st, channel);
        s->estimate = m;
        s->estimate_new = s->bound;
        ++s->estimates_in;
      }
    } catch (const std::exception& e) {  // nothing may escape an LCM callback
      ++decode_errors["exception"];
      spdlog::error("error handling {}: {}", printable(channel), e.what());
    } catch (...) {
      ++decode_errors["exception"];
    }
  }

  void onAlarm(Shaft& s, const hoist::alarm_t& m) {
    if (!validKind(m.kind) || m.level < 1 || m.level > 2) {
      ++alarm_rejected;
      std::int64_t suppressed = 0;
      if (log_limit.allow(kLcmLog, sinceStart(Clock::now()), suppressed))
        spdlog::warn("ignored alarm on shaft '{}' with kind '{}' level {} (kind must be [A-Z0-9_]{{1,32}}, level 1 or 2)",
                     s.name, printable(m.kind, 32), int(m.level));
      return;
    }
    auto it = s.alarms.find(m.kind);
    if (it == s.alarms.end()) {
      if (static_cast<int>(s.alarms.size()) >= kMaxKindsPerShaft) return void(++alarm_rejected);
      it = s.alarms.emplace(m.kind, AlarmState{}).first;
    }
    it->second.by_level[m.level] = m;
    it->second.last = m;
    ++s.alarms_in;
    if (s.bound) publishAlarmState(s, it->first, it->second);
  }

  /// A new daemon process: alarm states from before its start are void (the
  /// new daemon announces what is active from its own start).
  void daemonRestarted(Shaft& s, const hoist::health_t& h) {
    const std::int64_t start = h.utime - static_cast<std::int64_t>(h.uptime * 1e6);
    spdlog::info("shaft '{}': new daemon instance; alarm states from before its start are cleared", s.name);
    for (auto& [kind, a] : s.alarms) {
      bool changed = false;
      for (auto& lv : a.by_level)
        if (lv && lv->utime < start && (lv->active || lv->shelved)) {
          lv->active = lv->acked = lv->shelved = lv->latched = false;
          lv->event_type = hoist::alarm_t::EVENT_CLEAR;
          lv->message = "cleared by hoist-mqtt: the daemon restarted";
          changed = true;
        }
      if (changed) publishAlarmState(s, kind, a);
    }
  }

  json alarmStateJson(const Shaft& s, const std::string& kind, const AlarmState& a) const {
    int level = 0;
    bool unacked = false, shelved = false;
    for (int lv = 1; lv <= 2; ++lv) {
      const auto& e = a.by_level[lv];
      if (!e) continue;
      if (e->active && !e->shelved) level = lv;
      unacked = unacked || (e->active && !e->acked && !e->shelved);
      shelved = shelved || e->shelved;
    }
    json j = json::object();
    j["shaft"] = s.name;
    j["kind"] = kind;
    j["active"] = level > 0;
    j["level"] = std::string(alarm_names::levelName(level));
    j["unacked"] = unacked;
    j["shelved"] = shelved;
    j["utime"] = a.last.utime;
    j["last_event"] = std::string(alarm_names::eventName(a.last.event_type));
    j["warning"] = a.by_level[1] ? hoist::msg::toJson(*a.by_level[1]) : json(nullptr);
    j["critical"] = a.by_level[2] ? hoist::msg::toJson(*a.by_level[2]) : json(nullptr);
    return j;
  }

  void publishAlarmState(const Shaft& s, const std::string& kind, const AlarmState& a) {
    if (sp) {
      setAlarmMetrics(sp->device(s.name), kind, a);
      return sparkplugData(s, sparkplug::Source::Alarm, MsgClass::Alarm);
    }
    publish({s.t_alarm + kind, alarmStateJson(s, kind, a).dump(), 1, true, MsgClass::Alarm});
  }

  // ---- Sparkplug B mode ------------------------------------------------------------

  /// Where a shaft's commands arrive (for the log).
  std::string cmdTopic(const Shaft& s) const {
    return sp ? sparkplug::deviceTopic(cfg.sp_group_id, "DCMD", cfg.sp_edge_node_id, sparkplug::deviceId(s.name))
              : s.t_cmd;
  }

  static std::uint64_t nowMs() { return static_cast<std::uint64_t>(hoist::bus::wallUtime() / 1000); }

  /// The kind's state as the JSON mode's alarm topic gives it: level = the
  /// highest active, unshelved level; acked = active and nothing unacknowledged.
  void setAlarmMetrics(sparkplug::DeviceMetrics& d, const std::string& kind, const AlarmState& a) {
    int level = 0;
    bool unacked = false, shelved = false;
    for (int lv = 1; lv <= 2; ++lv) {
      const auto& e = a.by_level[lv];
      if (!e) continue;
      if (e->active && !e->shelved) level = lv;
      unacked = unacked || (e->active && !e->acked && !e->shelved);
      shelved = shelved || e->shelved;
    }
    d.setAlarm(kind, level, level > 0, level > 0 && !unacked, shelved, a.last.utime);
  }

  /// DDATA with the shaft's metrics of `src` that changed (report by exception).
  void sparkplugData(const Shaft& s, sparkplug::Source src, MsgClass cls) {
    if (auto m = sp->deviceData(s.name, src, cls, nowMs())) publish(std::move(*m));
  }

  /// Alarm kinds without any event since the shaft was bridged are inactive
  /// once the daemon has had [bridge] alarm_sync_time to re-announce (null until then).
  void settleAlarms(Clock::time_point now) {
    for (auto& [p, s] : shafts)
      if (s.bound && !s.alarms_settled && seconds(now - s.bound_since) >= cfg.alarm_sync_time) {
        s.alarms_settled = true;
        sp->device(s.name).alarmsSettled(hoist::bus::wallUtime());
        sparkplugData(s, sparkplug::Source::Alarm, MsgClass::Alarm);
      }
  }

  sparkplug::NodeCounters nodeCounters() const {
    std::uint64_t dec = 0;
    for (const auto& [k, n] : decode_errors) dec += n;
    return {static_cast<std::int64_t>(cmd_received), static_cast<std::int64_t>(cmd_forwarded),
            static_cast<std::int64_t>(cmd_rejected), static_cast<std::int64_t>(dec)};
  }

  /// NBIRTH (seq 0) and every DBIRTH, then what was buffered (as history).
  void sparkplugBirths() {
    sp->resetSeq();
    sp_births_at = Clock::now();
    for (const auto& m : sp->births(nodeCounters(), nowMs())) sendOne(m, false);
    sp_session = true;
    ++sp_births;
    spdlog::info("Sparkplug: NBIRTH and {} DBIRTH on spBv1.0/{} as edge node '{}' (bdSeq {}){}", bound.size(),
                 cfg.sp_group_id, cfg.sp_edge_node_id, sp->bdSeq(),
                 outbox.empty() ? std::string() : fmt::format("; then {} buffered messages", outbox.size()));
  }

  void onSparkplugMessage(const struct mosquitto_message* m) {
    std::vector<sparkplug::Command> cmds;
    const auto in = sp->onMessage(m->topic, m->payload, m->payloadlen > 0 ? static_cast<std::size_t>(m->payloadlen) : 0,
                                  static_cast<std::size_t>(cfg.max_command_bytes), m->retain, cmds, nowMs());
    using In = sparkplug::Node::Inbound;
    if (in == In::StateIgnored) {
      std::int64_t suppressed = 0;
      if (log_limit.allow(kCmdLog, sinceStart(Clock::now()), suppressed))
        spdlog::warn("Sparkplug: a STATE on {} ignored (not a STATE payload, older than the last one, or stamped "
                     "more than {} s ahead of this clock: check both clocks); {} so far [{} similar suppressed]",
                     printable(m->topic), sparkplug::Node::kStateFutureMs / 1000, sp->stateIgnored(), suppressed);
      return;
    }
    if (in == In::HostOnline) {
      if (!sp_session) {
        spdlog::info("Sparkplug: primary host '{}' is online", cfg.sp_primary_host_id);
        sparkplugBirths();
        flushJournal();  // history first (the journal, then the memory buffer), then live data
        flushOutbox();
      }
      return;
    }
    if (in == In::HostOffline) {
      ++sp_host_offline;
      if (!sp_session) return;
      // Sparkplug 3.0: end the session (NDEATH, disconnect) and start over; meanwhile, store.
      spdlog::warn("Sparkplug: primary host '{}' went offline: NDEATH, reconnecting and storing until it is back",
                   cfg.sp_primary_host_id);
      endSparkplugSession();
      lost("the primary host went offline");
      cb_disconnected = false;  // our own disconnect: not a failure of the next attempt
      next_attempt = Clock::now();
      return;
    }
    if (in != In::Commands) return;
    const auto now = Clock::now();
    for (const auto& c : cmds) {
      ++cmd_received;
      std::int64_t suppressed = 0;
      const bool may_log = log_limit.allow(kCmdLog, sinceStart(now), suppressed);
      if (c.what == sparkplug::Command::What::Rebirth) {
        // Within kRebirthMinMs of the births a request is held and merged
        // (sparkplug::Node::acceptRebirth): one NCMD may carry 150 Rebirth
        // metrics, and each birth queues NBIRTH and every DBIRTH.
        if (!sp->acceptRebirth(nowMs())) {
          if (may_log)
            spdlog::info("Sparkplug: rebirth requested (NCMD) less than {} s after the births: held, and done "
                         "when that interval has passed ({} requests held or merged so far) [{} similar suppressed]",
                         sparkplug::Node::kRebirthMinMs / 1000.0, sp->rebirthsCoalesced(), suppressed);
          continue;
        }
        ++sp_rebirths;
        ++cmd_forwarded;
        if (may_log) spdlog::info("Sparkplug: rebirth requested (NCMD)");
        if (sp_session) sparkplugBirths();
        continue;
      }
      const std::string shaft = sp->shaftOf(c.device);
      auto b = bound.find(shaft);
      Shaft* s = b == bound.end() ? nullptr : &shafts.at(b->second);
      if (c.what == sparkplug::Command::What::Refused) {
        refuseSp(s, c.reject, c.detail, m->topic, may_log);
        continue;
      }
      if (!s) {
        refuseSp(nullptr, CommandReject::UnknownMetric, "no shaft '" + printable(c.device) + "'", m->topic, may_log);
        continue;
      }
      if (!cfg.commands) {
        refuseSp(s, CommandReject::Disabled, "alarm commands are off (--no-commands)", m->topic, may_log);
        continue;
      }
      // The same checker as hoist/<shaft>/cmd/ack.
      CommandResult r = parseAckCommand(c.json.data(), c.json.size(), static_cast<std::size_t>(cfg.max_command_bytes),
                                        hoist::bus::wallUtime(), cfg.max_command_age);
      if (r.reject != CommandReject::None) {
        refuseSp(s, r.reject, r.detail, m->topic, may_log);
        continue;
      }
      executeCommand(*s, r, m->payloadlen, may_log, now);
    }
  }

  void refuseSp(Shaft* s, CommandReject why, const std::string& detail, const char* topic, bool may_log) {
    if (s) return refuse(*s, why, detail, 0, may_log);
    ++cmd_rejected;
    ++cmd_by_reason[static_cast<int>(why)];
    if (may_log) spdlog::warn("rejected command on {}: {}: {}", topic, toString(why), detail);
  }

  /// NDEATH before an intended disconnect (MQTT 3.1.1: the broker does not send the will then).
  void endSparkplugSession() {
    if (conn == Conn::Connected) {
      const OutMsg d = sp->death();
      mosquitto_publish(mosq, nullptr, d.topic.c_str(), static_cast<int>(d.payload.size()), d.payload.data(), d.qos,
                        d.retain);
      const auto end = Clock::now() + std::chrono::milliseconds(300);
      while (Clock::now() < end && mosquitto_want_write(mosq) && mosquitto_loop(mosq, 10, 1) == MOSQ_ERR_SUCCESS) {
      }
      mosquitto_disconnect(mosq);
    }
    sp_session = false;
  }

  // ---- MQTT side: publishing -----------------------------------------------------

  /// Live data may go out now: connected and, in Sparkplug mode, the births
  /// are out (with a primary host: once its STATE said online).
  bool liveReady() const { return conn == Conn::Connected && (!sp || sp_session); }
  bool sessionReady() const { return liveReady(); }

  /// Publishes now if connected and nothing is waiting, else buffers
  /// (bounded): in the journal with store-and-forward, else in memory.
  void publish(OutMsg m) {
    if (journal) {
      // Store-and-forward needs the broker's acknowledgement to know what
      // arrived: JSON messages go at QoS 1 (Sparkplug keeps its own QoS).
      if (!m.sparkplug && m.qos < 1) m.qos = 1;
      if (liveReady() && journal->empty() && outbox.empty() && !mosquitto_want_write(mosq) &&
          inflight.size() < kMaxInflight && sendOne(m, false))
        return;
      return store(std::move(m));
    }
    if (liveReady() && outbox.empty() && !mosquitto_want_write(mosq)) {
      if (sendOne(m, false)) return;
    }
    outbox.push(std::move(m));
  }

  /// Into the journal (or, if it cannot take it, the memory buffer: counted).
  void store(OutMsg m) {
    if (m.queued == Clock::time_point{}) m.queued = Clock::now();
    if (journal->append(m)) {
      if (m.cls == MsgClass::Alarm && m.retain) journaled_alarm_topics.insert(m.topic);
      return;
    }
    if (journal_fallback++ == 0)
      spdlog::error("store-and-forward journal: cannot store a message ({}); buffering in memory (counted: "
                    "journal.fallback)",
                    journal->lastError().empty() ? "larger than a record may be" : journal->lastError());
    outbox.push(std::move(m));
  }

  /// Replays the journal, oldest first, as long as the connection takes it.
  void flushJournal() {
    while (journal && !journal->empty() && liveReady() && !mosquitto_want_write(mosq) &&
           inflight.size() < kMaxInflight) {
      auto m = journal->peek();
      if (!m) {  // unreadable now: counted by the journal, skipped
        journal->pop();
        continue;
      }
      if (!sendOne(*m, /*historical=*/true)) return;
      journal->pop();
      ++journal_replayed;
    }
  }

  /// The one send function: true if handed to libmosquitto.  `historical`:
  /// a message replayed from the journal (JSON: sent as stored, its payload
  /// carries its own utime).
  ///
  /// A Sparkplug message gets the node's next seq (and, if `historical`,
  /// is_historical on every metric) now, when it is sent.
  bool sendOne(const OutMsg& m, bool historical) {
    std::string stamped;
    if (m.sparkplug) stamped = sparkplug::stamp(m.payload, sp ? sp->nextSeq() : 0, historical);
    const std::string& payload = m.sparkplug ? stamped : m.payload;
    int mid = 0;
    const int rc = mosquitto_publish(mosq, &mid, m.topic.c_str(), static_cast<int>(payload.size()),
                                     payload.data(), m.qos, m.retain);
    if (rc == MOSQ_ERR_SUCCESS) {
      ++published;
      if (journal && m.qos > 0 && m.topic != status_topic) inflight.push_back({mid, m});
      return true;
    }
    ++publish_errors;
    if (rc == MOSQ_ERR_NO_CONN || rc == MOSQ_ERR_CONN_LOST) lost(std::string("publish: ") + mosquitto_strerror(rc));
    return false;
  }

  /// Buffered cage states older than [buffer] stale_after are marked
  /// "stale": true (with their age), or dropped with drop_stale; alarm
  /// transitions and the rest are sent as they are.
  void flushOutbox() {
    const auto now = Clock::now();
    while (sessionReady() && !outbox.empty() && !mosquitto_want_write(mosq)) {
      const OutMsg& m = outbox.front();
      if (m.sparkplug) {  // queued before this session's births: history
        if (!sendOne(m, m.queued < sp_births_at)) return;
        outbox.pop();
        continue;
      }
      if (m.cls == MsgClass::Cage && seconds(now - m.queued) > cfg.stale_after) {
        if (cfg.drop_stale) {
          ++stale_dropped;
          outbox.pop();
          continue;
        }
        OutMsg marked = m;
        if (!marked.payload.empty() && marked.payload.back() == '}') {
          marked.payload.pop_back();
          marked.payload += fmt::format(",\"stale\":true,\"stale_age\":{:.3f}}}", seconds(now - m.queued));
        }
        if (!sendOne(marked, false)) return;
        ++stale_marked;
        outbox.pop();
        continue;
      }
      if (!sendOne(m, false)) return;
      outbox.pop();
    }
  }

  void publishCages() {
    for (auto& [p, s] : shafts) {
      if (!s.cage_new || !s.bound) continue;
      s.cage_new = false;
      ++s.cage_out;
      if (sp) {
        sp->device(s.name).onCage(s.cage);
        sparkplugData(s, sparkplug::Source::Cage, MsgClass::Cage);
        continue;
      }
      publish({s.t_cage, hoist::msg::toJson(s.cage).dump(), 0, false, MsgClass::Cage});
    }
    for (auto& [p, s] : shafts) {
      if (!s.estimate_new || !s.bound) continue;
      s.estimate_new = false;
      ++s.estimates_out;
      if (sp) {
        sp->device(s.name).onEstimate(s.estimate);
        sparkplugData(s, sparkplug::Source::Estimate, MsgClass::Cage);
        continue;
      }
      publish({s.t_estimate, hoist::msg::toJson(s.estimate).dump(), 0, false, MsgClass::Cage});
    }
  }

  const char* connText() const {
    return conn == Conn::Connected ? "connected" : conn == Conn::Connecting ? "connecting" : "disconnected";
  }

  json bridgeHealth() const {
    const auto now = Clock::now();
    json j = json::object();
    j["utime"] = hoist::bus::wallUtime();
    j["client_id"] = client_id;
    j["uptime"] = seconds(now - started);
    j["broker"] = brokerText();
    j["connection"] = {{"state", connText()},
                       {"connected_since_utime", conn == Conn::Connected ? connected_since_utime : 0},
                       {"connects", connects},
                       {"disconnects", disconnects},
                       {"connect_failures", connect_failures},
                       {"last_error", last_error}};
    json dec = json::object();
    std::uint64_t dec_total = 0;
    for (const auto& [k, n] : decode_errors) {
      dec[k] = n;
      dec_total += n;
    }
    j["lcm"] = {{"url", hoist::bus::describeLcmUrl(lcm_url)},
                {"messages", lcm_messages},
                {"decode_errors", dec_total},
                {"decode_errors_by_reason", dec},
                {"alarm_rejected", alarm_rejected},
                {"ignored_channels", ignored_channels}};
    j["mqtt"] = {{"published", published}, {"publish_errors", publish_errors}};
    if (sp)
      j["sparkplug"] = {{"group_id", cfg.sp_group_id},
                        {"edge_node_id", cfg.sp_edge_node_id},
                        {"primary_host_id", cfg.sp_primary_host_id},
                        {"host_online", sp->waitsForHost() ? sp->hostOnline() : true},
                        {"session", sp_session},
                        {"bdseq", sp->bdSeq()},
                        {"births", sp_births},
                        {"rebirths", sp_rebirths},
                        {"rebirths_coalesced", sp->rebirthsCoalesced()},
                        {"state_ignored", sp->stateIgnored()},
                        {"host_offline", sp_host_offline}};
    j["stale_cage"] = {{"marked", stale_marked}, {"dropped", stale_dropped}};
    if (journal)
      j["journal"] = {{"path", journal->path()},
                      {"queued", journal->size()},
                      {"queued_alarms", journal->queuedAlarms()},
                      {"file_bytes", journal->fileBytes()},
                      {"max_bytes", cfg.journal_max_bytes},
                      {"appended", journal->appended()},
                      {"replayed", journal_replayed},
                      {"inflight", inflight.size()},
                      {"dropped_cage", journal->droppedCage()},
                      {"dropped_health", journal->droppedHealth()},
                      {"dropped_alarm", journal->droppedAlarm()},
                      {"oversized", journal->oversized()},
                      {"fallback", journal_fallback},
                      {"recovered", journal_report.recovered},
                      {"corrupt", journal_report.problem.empty() ? 0 : 1},
                      {"corrupt_bytes", journal_report.skipped_bytes},
                      {"corrupt_reason", journal_report.problem},
                      {"read_errors", journal->readErrors()},
                      {"write_errors", journal->writeErrors()},
                      {"last_error", journal->lastError()},
                      {"fsyncs", journal->fsyncs()},
                      {"compactions", journal->compactions()},
                      {"prepended_at_shutdown", journal_prepended}};
    j["buffer"] = {{"queued", outbox.size()},
                   {"queued_alarms", outbox.queuedAlarms()},
                   {"max_messages", cfg.max_messages},
                   {"max_alarm_events", cfg.max_alarm_events},
                   {"dropped_cage", outbox.droppedCage()},
                   {"dropped_health", outbox.droppedHealth()},
                   {"dropped_alarm", outbox.droppedAlarm()}};
    json by_reason = json::object();
    for (int i = 1; i < kCommandRejects; ++i) by_reason[toString(static_cast<CommandReject>(i))] = cmd_by_reason[i];
    j["commands"] = {{"enabled", cfg.commands},
                     {"received", cmd_received},
                     {"forwarded", cmd_forwarded},
                     {"rejected", cmd_rejected},
                     {"rejected_by_reason", by_reason},
                     {"results_published", results_published},
                     {"results_dropped", results_dropped},
                     {"lcm_publish_failures", cmd_lcm_failures}};
    json sh = json::array();
    json conflicts = json::array(), refused = json::array();
    std::size_t candidates = 0;
    for (const auto& [p, s] : shafts) {
      if (s.refused && refused.size() < 16) refused.push_back(p);
      if (!s.bound) {
        candidates += s.confirmed ? 0 : 1;
        continue;
      }
      if (auto r = rivals(s); !r.empty()) {
        json ps = json::array({p});
        for (const auto& x : r) ps.push_back(x);
        conflicts.push_back({{"shaft", s.name}, {"bridged_prefix", p}, {"prefixes", ps}});
      }
      int active = 0;
      for (const auto& [k, a] : s.alarms)
        for (const auto& lv : a.by_level) active += lv && lv->active ? 1 : 0;
      sh.push_back({{"name", s.name},
                    {"channel_prefix", s.prefix},
                    {"health_age", s.health_in ? seconds(now - s.last_health) : -1.0},
                    {"cage_in", s.cage_in},
                    {"cage_out", s.cage_out},
                    {"health_in", s.health_in},
                    {"forecasts_in", s.forecasts_in},
                    {"estimates_in", s.estimates_in},
                    {"estimates_out", s.estimates_out},
                    {"alarm_events_in", s.alarms_in},
                    {"alarms_active", active},
                    {"commands", s.commands}});
    }
    j["shafts"] = sh;
    j["discovery"] = {{"enabled", discover},
                      {"slots_used", slotsUsed()},
                      {"max_shafts", cfg.max_shafts},
                      {"table_full", tableFull()},
                      {"candidates", candidates},
                      {"refused", refused},
                      {"refused_total", refused_total},
                      {"conflicts", conflicts},
                      {"aged_out", aged_out},
                      {"evicted_candidates", evicted_candidates}};
    return j;
  }

  void publishBridgeHealth() { publish({bridge_health_topic, bridgeHealth().dump(), 0, false, MsgClass::Health}); }

  // ---- MQTT side: connection -----------------------------------------------------

  void tryConnect() {
    if (!failing && connects == 0 && connect_failures == 0)
      spdlog::info("connecting to the broker at {} as '{}'{}", brokerText(), client_id,
                   cfg.wantsTls() ? " (TLS)" : "");
    if (sp) {  // NDEATH with the next bdSeq is this connection's will
      const OutMsg will = sp->nextWill();
      check(mosquitto_will_set(mosq, will.topic.c_str(), static_cast<int>(will.payload.size()), will.payload.data(),
                               will.qos, will.retain),
            "will (NDEATH)");
    }
    errno = 0;
    const int rc = mosquitto_connect_async(mosq, broker.host.c_str(), broker.port, cfg.keepalive);
    if (rc == MOSQ_ERR_SUCCESS) {
      conn = Conn::Connecting;
      connecting_since = Clock::now();
      return;
    }
    failed(rc == MOSQ_ERR_ERRNO ? std::string(std::strerror(errno)) : std::string(mosquitto_strerror(rc)));
  }

  /// A connection attempt failed: retry later, log only the first of a series.
  void failed(const std::string& why) {
    ++connect_failures;
    last_error = why;
    conn = Conn::Disconnected;
    if (!failing)
      spdlog::warn("cannot connect to the broker at {}: {}; retrying with backoff up to {} s "
                   "(logged again when the connection state changes)",
                   brokerText(), why, cfg.reconnect_max);
    failing = true;
    next_attempt = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(delay));
    delay = std::min(delay * 2.0, cfg.reconnect_max);
  }

  /// An established connection was lost.
  void lost(const std::string& why) {
    if (conn != Conn::Connected) return;
    ++disconnects;
    last_error = why;
    conn = Conn::Disconnected;
    sp_session = false;
    for (auto& [p, s] : shafts) s.subscribed = false;
    if (journal)
      spdlog::warn("connection to the broker at {} lost: {}; reconnecting with backoff up to {} s, storing in the "
                   "journal {} (at most {} bytes)",
                   brokerText(), why, cfg.reconnect_max, journal->path(), cfg.journal_max_bytes);
    else
      spdlog::warn("connection to the broker at {} lost: {}; reconnecting with backoff up to {} s, buffering at most "
                   "{} messages and {} alarm transitions",
                   brokerText(), why, cfg.reconnect_max, cfg.max_messages, cfg.max_alarm_events);
    failing = true;  // further failed attempts are the same state
    delay = cfg.reconnect_min;
    next_attempt = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(delay));
    delay = std::min(delay * 2.0, cfg.reconnect_max);
  }

  void subscribeCommands(Shaft& s) {
    if (!cfg.commands || s.subscribed) return;
    const int rc = mosquitto_subscribe(mosq, nullptr, s.t_cmd.c_str(), 1);
    if (rc == MOSQ_ERR_SUCCESS) s.subscribed = true;
    else spdlog::warn("cannot subscribe to {}: {}", s.t_cmd, mosquitto_strerror(rc));
  }

  void onConnected() {
    conn = Conn::Connected;
    ++connects;
    failing = false;
    last_error.clear();
    delay = cfg.reconnect_min;
    connected_since_steady = Clock::now();
    connected_since_utime = hoist::bus::wallUtime();
    spdlog::info("connected to the broker at {} as '{}'{}", brokerText(), client_id,
                 outbox.empty() ? std::string() : fmt::format("; sending {} buffered messages", outbox.size()));
    if (sp) {
      for (const auto& t : sp->subscriptions())
        if (const int rc = mosquitto_subscribe(mosq, nullptr, t.c_str(), 1); rc != MOSQ_ERR_SUCCESS)
          spdlog::warn("cannot subscribe to {}: {}", t, mosquitto_strerror(rc));
      if (sp->waitsForHost())
        spdlog::info("Sparkplug: waiting for the primary host '{}' (spBv1.0/STATE/{} online) before the births; "
                     "storing until then",
                     cfg.sp_primary_host_id, cfg.sp_primary_host_id);
      else
        sparkplugBirths();
      flushJournal();
      flushOutbox();
      publishBridgeHealth();
      return;
    }
    const std::string online =
        json{{"online", true}, {"client_id", client_id}, {"since_utime", connected_since_utime}}.dump();
    sendOne({status_topic, online, 1, true, MsgClass::Alarm}, false);
    for (auto& [p, s] : shafts)
      if (s.bound) subscribeCommands(s);
    if (journal && !journal->empty())
      spdlog::info("replaying {} stored messages from the journal before live data", journal->size());
    flushJournal();
    flushOutbox();
    // The broker may have restarted without its retained messages: republish
    // every alarm's current state (after the buffered transitions, so the
    // retained message ends up being the current state).  A state waiting in
    // the journal is its kind's latest and is replayed retained: not sent
    // twice (unless the journal had to drop alarm transitions).
    const bool journal_lost_alarms = journal && journal->droppedAlarm() != journal_alarm_drops_seen;
    if (journal) journal_alarm_drops_seen = journal->droppedAlarm();
    for (const auto& [p, s] : shafts)
      if (s.bound)
        for (const auto& [kind, a] : s.alarms)
          if (journal_lost_alarms || !journaled_alarm_topics.count(s.t_alarm + kind)) publishAlarmState(s, kind, a);
    journaled_alarm_topics.clear();
    publishBridgeHealth();
  }

  void serviceCallbacks() {
    if (cb_connack) {
      cb_connack = false;
      if (cb_connack_rc == 0) onConnected();
      else failed(std::string("refused by the broker: ") + mosquitto_connack_string(cb_connack_rc));
    }
    if (cb_disconnected) {
      cb_disconnected = false;
      if (conn == Conn::Connected)
        lost(cb_disconnect_rc == 0 ? "disconnected" : std::string(mosquitto_strerror(cb_disconnect_rc)));
      else if (conn == Conn::Connecting)
        failed(cb_disconnect_rc == 0 ? "disconnected" : std::string(mosquitto_strerror(cb_disconnect_rc)));
    }
  }

  // ---- MQTT side: commands -------------------------------------------------------

  /// Rate limit per user and shaft ([bridge] command_rate, command_burst),
  /// and 4x that for the shaft's total (so many user names gain nothing).
  bool rateAllows(Shaft& s, const std::string& user, Clock::time_point now) {
    const double rate = cfg.command_rate, burst = cfg.command_burst;
    auto it = s.cmd_users.find(user);
    if (it == s.cmd_users.end()) {
      if (s.cmd_users.size() >= kMaxUsersPerShaft)
        for (auto u = s.cmd_users.begin(); u != s.cmd_users.end();)  // forget idle users
          u = u->second.full(now, rate, burst) ? s.cmd_users.erase(u) : std::next(u);
      if (s.cmd_users.size() >= kMaxUsersPerShaft) return false;
      it = s.cmd_users.emplace(user, TokenBucket{}).first;
    }
    TokenBucket probe = it->second;
    if (!probe.take(now, rate, burst)) {
      it->second = probe;
      return false;
    }
    if (!s.cmd_total.take(now, 4.0 * rate, 4.0 * burst)) return false;
    it->second = probe;
    return true;
  }

  /// The command's answer on hoist/<shaft>/cmd/result (QoS 1, not retained).
  void answer(Shaft& s, const char* result, const char* reason, const std::string& detail,
              const hoist::alarm_ack_t* ack) {
    if (sp) return;  // Sparkplug has no answer topic: counted (bridge health, NDATA Bridge/Commands ...)
    if (!result_budget.take(Clock::now(), 20.0, 50.0)) return void(++results_dropped);
    json j = json::object();
    j["utime"] = hoist::bus::wallUtime();
    j["shaft"] = s.name;
    j["result"] = result;
    j["reason"] = reason;
    j["detail"] = detail;
    if (ack) {
      j["command"] = {{"kind", ack->kind.empty() ? std::string("*") : printable(ack->kind, 32)},
                      {"level", int(ack->level)},
                      {"action", int(ack->action)},
                      {"user", printable(ack->user)},
                      {"utime", ack->utime}};
      if (ack->action == hoist::alarm_ack_t::ACTION_SHELVE) j["command"]["shelve_duration"] = ack->shelve_duration;
    }
    ++results_published;
    publish({s.t_result, j.dump(), 1, false, MsgClass::Health});
  }

  void refuse(Shaft& s, CommandReject why, const std::string& detail, int payloadlen, bool may_log,
              const hoist::alarm_ack_t* ack = nullptr) {
    ++cmd_rejected;
    ++cmd_by_reason[static_cast<int>(why)];
    if (may_log)
      spdlog::warn("rejected command on {} ({} bytes): {}: {}", cmdTopic(s), payloadlen, toString(why), detail);
    answer(s, "refused", toString(why), detail, ack);
  }

  /// An acknowledge matches an active, unacknowledged alarm the bridge knows of.
  bool ackMatches(const Shaft& s, const hoist::alarm_ack_t& ack) const {
    const bool any_kind = ack.kind.empty() || ack.kind == "*";
    for (const auto& [kind, a] : s.alarms) {
      if (!any_kind && kind != ack.kind) continue;
      for (int lv = 1; lv <= 2; ++lv)
        // Active or returned to normal (RTN UNACK): not yet acknowledged.
        if ((ack.level == 0 || ack.level == lv) && a.by_level[lv] && !a.by_level[lv]->acked)
          return true;
    }
    return false;
  }

  void onMqttMessage(const struct mosquitto_message* m) {
    try {
      if (!m || !m->topic) return;
      if (sp) return onSparkplugMessage(m);
      auto it = cmd_topics.find(m->topic);
      if (it == cmd_topics.end() || !cfg.commands) return;
      Shaft& s = shafts.at(it->second);
      if (m->payloadlen == 0) return;  // an empty payload deletes a retained message: nothing to do
      ++cmd_received;
      const auto now = Clock::now();
      std::int64_t suppressed = 0;
      const bool may_log = log_limit.allow(kCmdLog, sinceStart(now), suppressed);
      if (may_log && suppressed) spdlog::warn("{} command log lines suppressed", suppressed);
      if (m->retain) {
        // A retained command would be executed again on every (re)subscription:
        // never executed; the bridge deletes it from the broker (empty retained message).
        refuse(s, CommandReject::Retained,
               "retained messages are never executed (publish commands with retain=false); deleting it", m->payloadlen,
               may_log);
        mosquitto_publish(mosq, nullptr, m->topic, 0, nullptr, 1, true);
        return;
      }
      CommandResult r = parseAckCommand(m->payload, m->payloadlen > 0 ? static_cast<std::size_t>(m->payloadlen) : 0,
                                        static_cast<std::size_t>(cfg.max_command_bytes), hoist::bus::wallUtime(),
                                        cfg.max_command_age);
      if (r.reject != CommandReject::None) return refuse(s, r.reject, r.detail, m->payloadlen, may_log);
      executeCommand(s, r, m->payloadlen, may_log, now);
    } catch (const std::exception& e) {
      spdlog::error("error handling an MQTT message: {}", e.what());
    }
  }

  /// A command that passed the checker (parseAckCommand): shaft conflicts,
  /// rate limit, a matching alarm, then HOIST_ALARM_ACK on LCM.  Both modes.
  void executeCommand(Shaft& s, const CommandResult& r, int payloadlen, bool may_log, Clock::time_point now) {
    {
      const hoist::alarm_ack_t* cmd = &r.ack;
      for (const auto& rp : rivals(s))
        if (const Shaft& o = shafts.at(rp); o.refused && !silent(o, now))
          return refuse(s, CommandReject::AmbiguousShaft,
                        fmt::format("shaft '{}' is claimed by LCM prefixes '{}' and '{}'", s.name, printable(s.prefix),
                                    printable(rp)),
                        payloadlen, may_log, cmd);
      if (!rateAllows(s, r.ack.user, now))
        return refuse(s, CommandReject::RateLimited,
                      fmt::format("user '{}' over {} commands/s (burst {}) on shaft '{}'", printable(r.ack.user),
                                  cfg.command_rate, cfg.command_burst, s.name),
                      payloadlen, may_log, cmd);
      // An acknowledge for no alarm: answered (the daemon would do nothing).
      // Until the daemon has re-announced its active alarms since the shaft
      // was bridged, the bridge's view may be incomplete: forwarded then.
      const bool view_complete = seconds(now - s.bound_since) >= cfg.alarm_sync_time;
      std::string note;
      if (r.ack.action == hoist::alarm_ack_t::ACTION_ACK && !ackMatches(s, r.ack)) {
        if (view_complete) {
          ++cmd_rejected;
          ++cmd_by_reason[static_cast<int>(CommandReject::NoMatchingAlarm)];
          const std::string why = fmt::format("no unacknowledged alarm {} (level {}) on shaft '{}'",
                                              r.ack.kind.empty() || r.ack.kind == "*" ? std::string("of any kind")
                                                                                      : printable(r.ack.kind, 32),
                                              int(r.ack.level), s.name);
          spdlog::info("acknowledge on {} from '{}' matches no alarm: {}", cmdTopic(s), printable(r.ack.user), why);
          return answer(s, "refused", toString(CommandReject::NoMatchingAlarm), why, cmd);
        }
        note = "no matching alarm known yet (the bridge has not yet heard the daemon re-announce its alarms); "
               "forwarded, the daemon decides";
      }
      const std::string channel = hoist::bus::channel(s.prefix, kChannelAlarmAck);
      if (lcm.publish(channel, &r.ack) != 0) {
        ++cmd_lcm_failures;
        if (may_log) spdlog::error("command on {}: LCM publish on {} failed", cmdTopic(s), channel);
        return answer(s, "refused", "lcm_publish_failed", "LCM publish on " + channel + " failed", cmd);
      }
      ++cmd_forwarded;
      ++s.commands;
      answer(s, "accepted", "forwarded", note.empty() ? "forwarded to " + channel : note, cmd);
      if (may_log)
        spdlog::info("command on {} from '{}': action {} kind '{}' level {}{} -> {}", cmdTopic(s), printable(r.ack.user),
                     int(r.ack.action), r.ack.kind.empty() ? "*" : printable(r.ack.kind, 32), int(r.ack.level),
                     r.ack.action == hoist::alarm_ack_t::ACTION_SHELVE ? fmt::format(" for {} s", r.ack.shelve_duration)
                                                                       : std::string(),
                     channel);
    }
  }

  // ---- the loop ------------------------------------------------------------------

  int run(const volatile std::sig_atomic_t& stop) {
    const auto cage_period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / cfg.cage_rate));
    const auto health_period =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cfg.health_period));
    auto next_cage = Clock::now() + cage_period;
    auto next_health = Clock::now() + health_period;
    next_attempt = Clock::now();
    spdlog::info("hoist-mqtt: LCM {}; broker {}; cage states at {} Hz; commands {}; shafts: {}",
                 hoist::bus::describeLcmUrl(lcm_url), brokerText(), cfg.cage_rate,
                 !cfg.commands ? "disabled (--no-commands)"
                 : sp          ? "accepted as DCMD writes of Alarms/<KIND>/{Ack,Shelve,Unshelve}"
                               : "accepted on hoist/<shaft>/cmd/ack",
                 discover ? "discovered from their *HOIST_{HEALTH,CAGE,ALARM} channels" : std::to_string(shafts.size()) + " configured");
    const int lcm_fd = rx.fd();
    while (!stop) {
      auto now = Clock::now();
      if (conn == Conn::Disconnected && now >= next_attempt) tryConnect();
      if (conn == Conn::Connecting && now - connecting_since > std::chrono::duration<double>(cfg.connect_timeout))
        failed("no answer (CONNACK) within " + fmt::format("{}", cfg.connect_timeout) + " s");

      pollfd fds[2];
      int nfds = 0;
      fds[nfds++] = {lcm_fd, POLLIN, 0};
      const int sock = conn != Conn::Disconnected ? mosquitto_socket(mosq) : -1;
      if (sock >= 0) fds[nfds++] = {sock, static_cast<short>(POLLIN | (mosquitto_want_write(mosq) ? POLLOUT : 0)), 0};
      auto wake = std::min({next_cage, next_health, now + std::chrono::milliseconds(100)});
      if (conn == Conn::Disconnected) wake = std::min(wake, next_attempt);
      const int timeout_ms = static_cast<int>(
          std::clamp<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(wake - now).count(), 0, 100));
      const int n = ::poll(fds, nfds, timeout_ms);
      if (n < 0 && errno != EINTR) spdlog::error("poll: {}", std::strerror(errno));

      if (n > 0 && (fds[0].revents & POLLIN)) {
        // Drain what is there, bounded so the broker side is never starved.
        rx.drain(256);
      }
      if (conn != Conn::Disconnected) {
        const int rc = mosquitto_loop(mosq, 0, 1);
        serviceCallbacks();
        if (rc != MOSQ_ERR_SUCCESS) {
          const std::string why = rc == MOSQ_ERR_ERRNO ? std::string(std::strerror(errno)) : mosquitto_strerror(rc);
          if (conn == Conn::Connected) lost(why);
          else if (conn == Conn::Connecting) failed(why);
        }
      }
      if (sp && sp_session && sp->rebirthDue(nowMs())) {  // a Rebirth held by acceptRebirth
        ++sp_rebirths;
        sparkplugBirths();
      }
      flushJournal();
      flushOutbox();
      if (journal) journal->sync();

      now = Clock::now();
      sweepDiscovery(now);
      if (!table_full_logged && tableFull()) {
        table_full_logged = true;
        spdlog::warn("discovery: the shaft table is full ({} of [bridge] max_shafts = {}) and a prefix was refused; "
                     "see discovery.refused in the bridge's health",
                     slotsUsed(), cfg.max_shafts);
      }
      if (now >= next_cage) {
        publishCages();
        next_cage += cage_period;
        if (next_cage < now) next_cage = now + cage_period;
      }
      if (now >= next_health) {
        if (sp && sp_session)
          if (auto m = sp->nodeData(nodeCounters(), nowMs())) publish(std::move(*m));
        if (sp) settleAlarms(now);
        publishBridgeHealth();
        next_health += health_period;
        if (next_health < now) next_health = now + health_period;
      }
    }

    spdlog::info("hoist-mqtt: stopping");
    if (sp) {
      endSparkplugSession();
      mosquitto_loop(mosq, 10, 1);
    } else if (conn == Conn::Connected) {
      const std::string offline = json{{"online", false}, {"client_id", client_id}, {"reason", "shutdown"}}.dump();
      mosquitto_publish(mosq, nullptr, status_topic.c_str(), static_cast<int>(offline.size()), offline.data(), 1, true);
      // Give the last messages a moment to leave, then disconnect cleanly (no LWT).
      // With the journal, wait (a little longer) for the acknowledgements too.
      const auto end = Clock::now() + std::chrono::milliseconds(journal ? 2000 : 500);
      while (Clock::now() < end && (mosquitto_want_write(mosq) || (journal && !inflight.empty())) &&
             mosquitto_loop(mosq, 10, 1) == MOSQ_ERR_SUCCESS) {
      }
      mosquitto_disconnect(mosq);
      mosquitto_loop(mosq, 10, 1);
    }
    if (journal) {
      // What the broker has not acknowledged goes back to the journal's
      // front (it is older than everything in it): sent again after a restart.
      std::vector<OutMsg> unacked;
      for (auto& f : inflight) unacked.push_back(std::move(f.m));
      inflight.clear();
      if (!unacked.empty()) {
        if (journal->prepend(unacked)) journal_prepended += unacked.size();
        else spdlog::error("store-and-forward journal: {} unacknowledged messages lost: {}", unacked.size(),
                           journal->lastError());
      }
      spdlog::info("store-and-forward journal: {} messages kept for the next start", journal->size());
      journal->close();
    }
    return 0;
  }
};

Bridge::Bridge(const BridgeConfig& cfg, const std::string& password) : impl_(std::make_unique<Impl>(cfg, password)) {}
Bridge::~Bridge() = default;
int Bridge::run(const volatile std::sig_atomic_t& stop) { return impl_->run(stop); }

}  // namespace hoist::mqtt
