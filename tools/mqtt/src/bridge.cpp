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
#include "hoist/mqtt/outbox.hpp"
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
    bool refused = false;          // confirmed-quality but no slot (table full) or its name is taken
    bool cage_new = false;
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
    const std::string will = json{{"online", false}, {"client_id", client_id}, {"reason", "connection lost (last will)"}}.dump();
    check(mosquitto_will_set(mosq, status_topic.c_str(), static_cast<int>(will.size()), will.data(), 1, true), "will");
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
    delay = cfg.reconnect_min;
  }

  ~Impl() {
    if (mosq) mosquitto_destroy(mosq);
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
    spdlog::info("shaft '{}': LCM {}HOIST_{{CAGE,HEALTH,ALARM,FORECAST,ESTIMATE}} -> "
                 "{}{{cage,health,alarm/<KIND>,forecast,estimate}}{}{}",
                 s.name, s.prefix, base,
                 cfg.commands ? ", " + s.t_cmd + " -> " + hoist::bus::channel(s.prefix, kChannelAlarmAck) : "",
                 s.configured ? "" : fmt::format(" (discovered: daemon instance {})", s.streak_instance));
    if (conn == Conn::Connected) subscribeCommands(s);
    for (const auto& [kind, a] : s.alarms) publishAlarmState(s, kind, a);
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
    if (s.instance_id != 0 && m.instance_id != s.instance_id) daemonRestarted(s, m);
    s.instance_id = m.instance_id;
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
        // Issue 17: the look-ahead forecast, as JSON (nested scenarios), at
        // the daemon's rate (~1 Hz); queued like health (low rate).
        Shaft* s = shaftFor(channel.substr(0, channel.size() - kChannelForecast.size()));
        if (!s) return void(++ignored_channels);
        hoist::forecast_t m;
        const auto st = hoist::msg::checkedDecode(rb->data, rb->data_size, m);
        if (st != hoist::msg::DecodeStatus::ok) return decodeError("forecast_t", st, channel);
        ++s->forecasts_in;
        if (s->bound) publish({s->t_forecast, hoist::msg::toJson(m).dump(), 0, false, MsgClass::Health});
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
    publish({s.t_alarm + kind, alarmStateJson(s, kind, a).dump(), 1, true, MsgClass::Alarm});
  }

  // ---- MQTT side: publishing -----------------------------------------------------

  /// Publishes now if connected and nothing is waiting, else buffers (bounded).
  void publish(OutMsg m) {
    if (conn == Conn::Connected && outbox.empty() && !mosquitto_want_write(mosq)) {
      if (send(m)) return;
    }
    outbox.push(std::move(m));
  }

  /// true if handed to libmosquitto.
  bool send(const OutMsg& m) {
    const int rc = mosquitto_publish(mosq, nullptr, m.topic.c_str(), static_cast<int>(m.payload.size()),
                                     m.payload.data(), m.qos, m.retain);
    if (rc == MOSQ_ERR_SUCCESS) {
      ++published;
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
    while (conn == Conn::Connected && !outbox.empty() && !mosquitto_want_write(mosq)) {
      const OutMsg& m = outbox.front();
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
        if (!send(marked)) return;
        ++stale_marked;
        outbox.pop();
        continue;
      }
      if (!send(m)) return;
      outbox.pop();
    }
  }

  void publishCages() {
    for (auto& [p, s] : shafts) {
      if (!s.cage_new || !s.bound) continue;
      s.cage_new = false;
      ++s.cage_out;
      publish({s.t_cage, hoist::msg::toJson(s.cage).dump(), 0, false, MsgClass::Cage});
    }
    for (auto& [p, s] : shafts) {
      if (!s.estimate_new || !s.bound) continue;
      s.estimate_new = false;
      ++s.estimates_out;
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
    j["stale_cage"] = {{"marked", stale_marked}, {"dropped", stale_dropped}};
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
    for (auto& [p, s] : shafts) s.subscribed = false;
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
    const std::string online =
        json{{"online", true}, {"client_id", client_id}, {"since_utime", connected_since_utime}}.dump();
    send({status_topic, online, 1, true, MsgClass::Alarm});
    for (auto& [p, s] : shafts)
      if (s.bound) subscribeCommands(s);
    flushOutbox();
    // The broker may have restarted without its retained messages: republish
    // every alarm's current state (after the buffered transitions, so the
    // retained message ends up being the current state).
    for (const auto& [p, s] : shafts)
      if (s.bound)
        for (const auto& [kind, a] : s.alarms) publishAlarmState(s, kind, a);
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
      spdlog::warn("rejected command on {} ({} bytes): {}: {}", s.t_cmd, payloadlen, toString(why), detail);
    answer(s, "refused", toString(why), detail, ack);
  }

  /// An acknowledge matches an active, unacknowledged alarm the bridge knows of.
  bool ackMatches(const Shaft& s, const hoist::alarm_ack_t& ack) const {
    const bool any_kind = ack.kind.empty() || ack.kind == "*";
    for (const auto& [kind, a] : s.alarms) {
      if (!any_kind && kind != ack.kind) continue;
      for (int lv = 1; lv <= 2; ++lv)
        if ((ack.level == 0 || ack.level == lv) && a.by_level[lv] && a.by_level[lv]->active && !a.by_level[lv]->acked)
          return true;
    }
    return false;
  }

  void onMqttMessage(const struct mosquitto_message* m) {
    try {
      if (!m || !m->topic) return;
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
      const hoist::alarm_ack_t* cmd = &r.ack;
      for (const auto& rp : rivals(s))
        if (const Shaft& o = shafts.at(rp); o.refused && !silent(o, now))
          return refuse(s, CommandReject::AmbiguousShaft,
                        fmt::format("shaft '{}' is claimed by LCM prefixes '{}' and '{}'", s.name, printable(s.prefix),
                                    printable(rp)),
                        m->payloadlen, may_log, cmd);
      if (!rateAllows(s, r.ack.user, now))
        return refuse(s, CommandReject::RateLimited,
                      fmt::format("user '{}' over {} commands/s (burst {}) on shaft '{}'", printable(r.ack.user),
                                  cfg.command_rate, cfg.command_burst, s.name),
                      m->payloadlen, may_log, cmd);
      // An acknowledge for no alarm: answered (the daemon would do nothing).
      // Until the daemon has re-announced its active alarms since the shaft
      // was bridged, the bridge's view may be incomplete: forwarded then.
      const bool view_complete = seconds(now - s.bound_since) >= cfg.alarm_sync_time;
      std::string note;
      if (r.ack.action == hoist::alarm_ack_t::ACTION_ACK && !ackMatches(s, r.ack)) {
        if (view_complete) {
          ++cmd_rejected;
          ++cmd_by_reason[static_cast<int>(CommandReject::NoMatchingAlarm)];
          const std::string why = fmt::format("no active, unacknowledged alarm {} (level {}) on shaft '{}'",
                                              r.ack.kind.empty() || r.ack.kind == "*" ? std::string("of any kind")
                                                                                      : printable(r.ack.kind, 32),
                                              int(r.ack.level), s.name);
          spdlog::info("acknowledge on {} from '{}' matches no alarm: {}", s.t_cmd, printable(r.ack.user), why);
          return answer(s, "refused", toString(CommandReject::NoMatchingAlarm), why, cmd);
        }
        note = "no matching alarm known yet (the bridge has not yet heard the daemon re-announce its alarms); "
               "forwarded, the daemon decides";
      }
      const std::string channel = hoist::bus::channel(s.prefix, kChannelAlarmAck);
      if (lcm.publish(channel, &r.ack) != 0) {
        ++cmd_lcm_failures;
        if (may_log) spdlog::error("command on {}: LCM publish on {} failed", s.t_cmd, channel);
        return answer(s, "refused", "lcm_publish_failed", "LCM publish on " + channel + " failed", cmd);
      }
      ++cmd_forwarded;
      ++s.commands;
      answer(s, "accepted", "forwarded", note.empty() ? "forwarded to " + channel : note, cmd);
      if (may_log)
        spdlog::info("command on {} from '{}': action {} kind '{}' level {}{} -> {}", s.t_cmd, printable(r.ack.user),
                     int(r.ack.action), r.ack.kind.empty() ? "*" : printable(r.ack.kind, 32), int(r.ack.level),
                     r.ack.action == hoist::alarm_ack_t::ACTION_SHELVE ? fmt::format(" for {} s", r.ack.shelve_duration)
                                                                       : std::string(),
                     channel);
    } catch (const std::exception& e) {
      spdlog::error("error handling an MQTT message: {}", e.what());
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
                 cfg.commands ? "accepted on hoist/<shaft>/cmd/ack" : "disabled (--no-commands)",
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
      flushOutbox();

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
        publishBridgeHealth();
        next_health += health_period;
        if (next_health < now) next_health = now + health_period;
      }
    }

    spdlog::info("hoist-mqtt: stopping");
    if (conn == Conn::Connected) {
      const std::string offline = json{{"online", false}, {"client_id", client_id}, {"reason", "shutdown"}}.dump();
      mosquitto_publish(mosq, nullptr, status_topic.c_str(), static_cast<int>(offline.size()), offline.data(), 1, true);
      // Give the last messages a moment to leave, then disconnect cleanly (no LWT).
      const auto end = Clock::now() + std::chrono::milliseconds(500);
      while (Clock::now() < end && mosquitto_want_write(mosq) && mosquitto_loop(mosq, 10, 1) == MOSQ_ERR_SUCCESS) {
      }
      mosquitto_disconnect(mosq);
      mosquitto_loop(mosq, 10, 1);
    }
    return 0;
  }
};

Bridge::Bridge(const BridgeConfig& cfg, const std::string& password) : impl_(std::make_unique<Impl>(cfg, password)) {}
Bridge::~Bridge() = default;
int Bridge::run(const volatile std::sig_atomic_t& stop) { return impl_->run(stop); }

}  // namespace hoist::mqtt
