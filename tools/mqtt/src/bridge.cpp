// hoist-mqtt's bridge: see hoist/mqtt/bridge.hpp.  This file wires the rooms
// and runs the loop; each room writes only its own state and reads the
// others through const views:
//
//   LcmSide         lcm_side.hpp          LCM in (route table, one templated decode) and alarm commands out
//   ShaftDirectory  shaft_directory.hpp   prefixes -> shaft names, discovery
//   ShaftData       shaft_data.hpp        what the daemons said, published as JSON topics or Sparkplug metrics
//   MqttLink        mqtt_link.hpp         the connection, the one send function, outbox, journal, in flight
//   SparkplugSession sparkplug_session.hpp the edge node, STATE, births, DCMD/NCMD
//   CommandGate     command_gate.hpp      operator commands: check, rate limit, forward, answer
//   BridgeHealth    bridge_health.hpp     hoist/_bridge/<client_id>/health
//   TripFeed        hoist/mqtt/trip_feed.hpp  [history]: hoist/<shaft>/trip/last, Condition/... metrics
// (replay_check.hpp: what the bridge would publish now, for the journal's replay.)
#include "hoist/mqtt/bridge.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "bridge_common.hpp"
#include "bridge_health.hpp"
#include "command_gate.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/history/config.hpp"
#include "hoist/mqtt/trip_feed.hpp"
#include "lcm_side.hpp"
#include "mqtt_link.hpp"
#include "replay_check.hpp"
#include "shaft_data.hpp"
#include "shaft_directory.hpp"
#include "sparkplug_session.hpp"

namespace hoist::mqtt {

namespace {

using json = nlohmann::json;

std::string makeClientId(const BridgeConfig& cfg) {
  if (!cfg.client_id.empty()) return cfg.client_id;
  char host[256] = "";
  gethostname(host, sizeof host - 1);
  std::string id = "hoist-mqtt-";
  for (const char* p = host; *p && id.size() < 60; ++p)
    id.push_back(std::isalnum(static_cast<unsigned char>(*p)) || *p == '-' ? *p : '_');
  return id;
}

}  // namespace

/// The wiring: owns every room (members are constructed in this order and
/// destroyed in reverse, so each room outlives the rooms that reference it),
/// and answers the directory's and the link's events.
struct Bridge::Impl final : ShaftDirectory::Events, MqttLink::Events {
  const BridgeConfig cfg;
  LogBudget log;
  const std::string client_id;
  const std::string status_topic = "hoist/_bridge/" + client_id + "/status";
  const std::string health_topic = "hoist/_bridge/" + client_id + "/health";
  LcmSide lcm;
  ShaftDirectory dir{cfg, log, *this};
  std::unique_ptr<SparkplugSession> sp;  // [sparkplug] enabled; constructed after the gate
  MqttLink link;
  ShaftData data{cfg, link, log};
  CommandGate gate{cfg, cfg.sparkplug, dir, data, lcm, link, log};
  std::unique_ptr<BridgeHealth> health;
  std::unique_ptr<TripFeed> trips;               // [history] url set
  std::map<std::string, std::string> trip_last;  // JSON mode: topic -> retained payload (republished on connect)

  Impl(const BridgeConfig& c, const std::string& password)
      : cfg(c),
        client_id(makeClientId(c)),
        lcm(hoist::bus::resolveLcmUrl(c.lcm_url), log),
        link(cfg, password, client_id, status_topic, *this,
             cfg.sparkplug ? MqttLink::SparkplugHooks{[this] { return sp->nextWill(); }, [this] { return sp->nextSeq(); }}
                           : MqttLink::SparkplugHooks{},
             [this](const OutMsg& m) { return replayRefusal(m, cfg, dir, health_topic); }, log) {
    if (cfg.sparkplug) {
      sp = std::make_unique<SparkplugSession>(cfg, link, dir, gate, log, [this] { return nodeCounters(); });
      data.useSparkplug(sp.get());
    }
    health = std::make_unique<BridgeHealth>(cfg, client_id, lcm, dir, data, link, gate, sp.get());
    // Data of another daemon instance than the shaft's (an impostor under its
    // prefix) is dropped and counted: ShaftData::admit.
    lcm.route<hoist::cage_state_t>(hoist::bus::kChannelCage, [this](const Shaft& s, const hoist::cage_state_t& m) {
      if (data.admit(s, m.instance_id, hoist::bus::kChannelCage.data(), false)) data.onCage(s, m);
    });
    lcm.route<hoist::health_t>(hoist::bus::kChannelHealth,
                               [this](const Shaft& s, const hoist::health_t& m) { onHealth(s, m); });
    lcm.route<hoist::alarm_t>(hoist::bus::kChannelAlarm,
                              [this](const Shaft& s, const hoist::alarm_t& m) { data.onAlarm(s, m); });
    lcm.route<hoist::forecast_t>(hoist::bus::kChannelForecast, [this](const Shaft& s, const hoist::forecast_t& m) {
      if (data.admit(s, m.instance_id, hoist::bus::kChannelForecast.data(), false)) data.onForecast(s, m);
    });
    lcm.route<hoist::estimate_t>(hoist::bus::kChannelEstimate, [this](const Shaft& s, const hoist::estimate_t& m) {
      if (data.admit(s, m.instance_id, hoist::bus::kChannelEstimate.data(), false)) data.onEstimate(s, m);
    });
    if (!cfg.history_url.empty()) {
      history::HistoryConfig hc;
      hc.url = cfg.history_url;  // absolute (config.cpp)
      trips = std::make_unique<TripFeed>(history::resolveStoreOptions(hc, "", "history.url"), ConditionSettings{},
                                         cfg.history_poll);
    }
    dir.addConfigured();
    lcm.listen([this](const std::string& prefix) { return dir.resolve(prefix); });
  }

  sparkplug::NodeCounters nodeCounters() const {
    const auto& n = gate.counters();
    return {static_cast<std::int64_t>(n.received), static_cast<std::int64_t>(n.forwarded),
            static_cast<std::int64_t>(n.rejected), static_cast<std::int64_t>(lcm.decodeErrorsTotal())};
  }

  void publishHealth() { link.publish({health_topic, health->build().dump(), 0, false, MsgClass::Health}); }

  /// The shared command topic and the per-identity ones (hoist/<shaft>/cmd/ack/<user>).
  void subscribeCommands(const Shaft& s) {
    if (!cfg.commands) return;
    link.subscribe(s.t.cmd);
    link.subscribe(s.t.cmd + "/+");
  }

  // ---- the directory's events ----

  void bound(const Shaft& s) override {
    const std::string origin = s.configured ? "" : fmt::format(" (discovered: daemon instance {})", s.streak_instance);
    if (sp) {
      spdlog::info("shaft '{}': LCM {}HOIST_{{CAGE,HEALTH,ALARM,FORECAST,ESTIMATE}} -> Sparkplug device "
                   "spBv1.0/{}/{{DBIRTH,DDATA,DCMD}}/{}/{}{}",
                   s.name, s.prefix, cfg.sp_group_id, cfg.sp_edge_node_id, sparkplug::deviceId(s.name), origin);
      data.bound(s);
      sp->deviceBound(s.name);
      if (trips) trips->watch(s.name);
      return;
    }
    spdlog::info("shaft '{}': LCM {}HOIST_{{CAGE,HEALTH,ALARM,FORECAST,ESTIMATE}} -> "
                 "{}{{cage,health,alarm/<KIND>,forecast,estimate}}{}{}",
                 s.name, s.prefix, "hoist/" + s.name + "/",
                 cfg.commands ? ", " + s.t.cmd + " -> " + hoist::bus::channel(s.prefix, hoist::bus::kChannelAlarmAck)
                              : "",
                 origin);
    if (link.connected()) subscribeCommands(s);
    data.bound(s);
    if (trips) trips->watch(s.name);
    // Discovered: bound on its daemon's health, which it has heard.
    if (!s.configured) requestAlarmStates(s, s.streak_instance);
  }

  void forgetting(const Shaft& s) override {
    if (s.bound) {
      if (sp) sp->deviceGone(s.name);
      else {
        link.unsubscribe(s.t.cmd);
        link.unsubscribe(s.t.cmd + "/+");
      }
    }
    gate.forget(s.prefix);
    data.forget(s.prefix);
  }

  // ---- LCM ----

  void onHealth(const Shaft& s, const hoist::health_t& m) {
    const auto seen = dir.onHealth(s, m.instance_id);
    if (!seen.bound) return;
    requestAlarmStates(s, m.instance_id);
    data.onHealth(s, m, seen.restarted);
  }

  /// Asks the shaft's daemon (instance `instance`, whose health was heard) to
  /// re-announce every alarm's current state now (alarm_ack_t
  /// ACTION_REANNOUNCE; it changes nothing, and the daemon honours one a
  /// second), once per daemon instance: an alarm raised before this bridge
  /// started, or before the shaft was discovered, is published at once as its
  /// state, not first as a CLEAR.  Sent also with --no-commands (it commands
  /// nothing); never into the void (no daemon heard yet).
  void requestAlarmStates(const Shaft& s, std::int64_t instance) {
    if (!dir.askStates(s, instance)) return;
    hoist::alarm_ack_t m{};
    m.utime = hoist::bus::wallUtime();
    m.kind = "*";
    m.action = hoist::alarm_ack_t::ACTION_REANNOUNCE;
    m.user = client_id;
    const std::string channel = hoist::bus::channel(s.prefix, hoist::bus::kChannelAlarmAck);
    if (!lcm.publishAck(channel, m)) spdlog::warn("shaft '{}': cannot ask for its alarm states on {}", s.name, channel);
  }

  /// A new last trip of a bound shaft (the trip feed): retained
  /// hoist/<shaft>/trip/last (QoS 1), or the device's Condition/... metrics.
  void publishTrip(const TripUpdate& u) {
    bool bound = false;
    for (const auto& [p, s] : dir.all()) bound = bound || (s.bound && s.name == u.shaft);
    if (!bound) return;
    if (sp) {
      sp->metrics(u.shaft).onCondition(u.cond, hoist::bus::wallUtime());
      sp->sendData(u.shaft, sparkplug::Source::Condition, MsgClass::Health);
      return;
    }
    const std::string topic = "hoist/" + u.shaft + "/trip/last";
    trip_last[topic] = u.last.dump();
    link.publish({topic, trip_last[topic], 1, true, MsgClass::Health});
  }

  // ---- the link's events ----

  void connected() override {
    if (sp) {
      sp->onConnected();
      publishHealth();
      return;
    }
    const std::string online =
        json{{"online", true}, {"client_id", client_id}, {"since_utime", link.connectedSinceUtime()}}.dump();
    link.sendOne({status_topic, online, 1, true, MsgClass::Alarm}, false);
    for (const auto& [p, s] : dir.all())
      if (s.bound) subscribeCommands(s);
    if (link.journal() && !link.journal()->empty())
      spdlog::info("replaying {} stored messages from the journal before live data", link.journal()->size());
    link.flushJournal();
    link.flushOutbox();
    // The broker may have restarted without its retained messages: republish
    // every alarm's current state (after the buffered transitions, so the
    // retained message ends up being the current state).  A state waiting in
    // the journal is its kind's latest and is replayed retained: not sent
    // twice (unless the journal had to drop alarm transitions).
    data.republishAlarms(dir, link.takeJournalAlarmLoss());
    link.clearJournaledAlarms();
    for (const auto& [topic, payload] : trip_last) link.publish({topic, payload, 1, true, MsgClass::Health});
    publishHealth();
  }

  void message(const struct mosquitto_message* m) override {
    try {
      if (!m || !m->topic) return;
      if (sp) return sp->onMessage(m);
      gate.onMessage(m);
    } catch (const std::exception& e) {
      spdlog::error("error handling an MQTT message: {}", e.what());
    }
  }

  // ---- the loop ----

  int run(const volatile std::sig_atomic_t& stop) {
    const auto cage_period =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / cfg.cage_rate));
    const auto health_period =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cfg.health_period));
    auto next_cage = Clock::now() + cage_period;
    auto next_health = Clock::now() + health_period;
    spdlog::info("hoist-mqtt: LCM {}; broker {}; cage states at {} Hz; commands {}; shafts: {}",
                 hoist::bus::describeLcmUrl(lcm.url()), link.brokerText(), cfg.cage_rate,
                 !cfg.commands ? "disabled (--no-commands)"
                 : sp          ? "accepted as DCMD writes of Alarms/<KIND>/{Ack,Shelve,Unshelve}"
                               : "accepted on hoist/<shaft>/cmd/ack",
                 dir.discovering() ? "discovered from their *HOIST_{HEALTH,CAGE,ALARM} channels"
                                   : std::to_string(dir.all().size()) + " configured");
    const int lcm_fd = lcm.fd();
    while (!stop) {
      auto now = Clock::now();
      link.tick(now);

      pollfd fds[2];
      int nfds = 0;
      fds[nfds++] = {lcm_fd, POLLIN, 0};
      const int sock = link.socket();
      if (sock >= 0) fds[nfds++] = {sock, static_cast<short>(POLLIN | (link.wantWrite() ? POLLOUT : 0)), 0};
      auto wake = std::min({next_cage, next_health, now + std::chrono::milliseconds(100)});
      if (link.state() == MqttLink::Conn::Disconnected) wake = std::min(wake, link.nextAttempt());
      const int timeout_ms = static_cast<int>(
          std::clamp<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(wake - now).count(), 0, 100));
      const int n = ::poll(fds, nfds, timeout_ms);
      if (n < 0 && errno != EINTR) spdlog::error("poll: {}", std::strerror(errno));

      if (n > 0 && (fds[0].revents & POLLIN)) lcm.drain(256);  // bounded: the broker side is never starved
      link.loop();
      if (sp) sp->tick(nowMs());
      link.flushJournal();
      link.flushOutbox();
      link.sync();

      now = Clock::now();
      health->watch(now);
      dir.tick(now);
      if (now >= next_cage) {
        data.publishCages(dir);
        next_cage += cage_period;
        if (next_cage < now) next_cage = now + cage_period;
      }
      if (trips)
        for (const auto& u : trips->take()) publishTrip(u);
      if (now >= next_health) {
        if (sp) {
          sp->healthTick();
          data.settleAlarms(dir, now);
        }
        publishHealth();
        next_health += health_period;
        if (next_health < now) next_health = now + health_period;
      }
    }

    spdlog::info("hoist-mqtt: stopping");
    if (sp) {
      sp->end();
      link.finalLoop();
    } else if (link.connected()) {
      const std::string offline = json{{"online", false}, {"client_id", client_id}, {"reason", "shutdown"}}.dump();
      link.sendRaw(status_topic, offline.data(), static_cast<int>(offline.size()), 1, true);
      // Give the last messages a moment to leave, then disconnect cleanly (no LWT).
      // With the journal, wait (a little longer) for the acknowledgements too.
      link.drainAndDisconnect(link.journal() ? 2000 : 500, link.journal() != nullptr);
      link.finalLoop();
    }
    link.closeJournal();
    return 0;
  }
};

Bridge::Bridge(const BridgeConfig& cfg, const std::string& password) : impl_(std::make_unique<Impl>(cfg, password)) {}
Bridge::~Bridge() = default;
int Bridge::run(const volatile std::sig_atomic_t& stop) { return impl_->run(stop); }

}  // namespace hoist::mqtt
