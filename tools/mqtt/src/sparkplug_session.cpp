// The bridge's Sparkplug B session: see sparkplug_session.hpp.
#include "sparkplug_session.hpp"

#include <spdlog/spdlog.h>

#include <stdexcept>

#include "hoist/mqtt/sparkplug.hpp"
#include "hoist/version.hpp"

namespace hoist::mqtt {

std::string SparkplugSession::missing() {
  return "[sparkplug] enabled, but this hoist-mqtt was built without nanopb (apt-get install nanopb "
         "libnanopb-dev, then rebuild)";
}

SparkplugSession::SparkplugSession(const BridgeConfig& cfg, MqttLink& link, const ShaftDirectory& dir,
                                   CommandGate& gate, LogBudget& log, std::function<sparkplug::NodeCounters()> counters)
    : cfg_(cfg), link_(link), dir_(dir), gate_(gate), log_(log), counters_(std::move(counters)) {
  if (!sparkplug::available()) throw std::runtime_error(missing());
  sparkplug::NodeOptions o;
  o.group = cfg.sp_group_id;
  o.edge = cfg.sp_edge_node_id;
  o.primary_host = cfg.sp_primary_host_id;
  o.version = std::string("hoist-mqtt ") + hoist::kVersionString;
  o.deadband = cfg.sp_deadband;
  o.deadbands = cfg.sp_deadbands;
  node_ = std::make_unique<sparkplug::Node>(o);
}

void SparkplugSession::sendData(const std::string& shaft, sparkplug::Source src, MsgClass cls) {
  if (auto m = node_->deviceData(shaft, src, cls, nowMs())) link_.publish(std::move(*m));
}

void SparkplugSession::deviceBound(const std::string& shaft) {
  if (link_.sessionOpen()) link_.sendOne(node_->deviceBirth(shaft, nowMs()), false);  // a new device after the NBIRTH
}

void SparkplugSession::deviceGone(const std::string& shaft) {
  if (link_.sessionOpen()) link_.sendOne(node_->deviceDeath(shaft, nowMs()), false);
  node_->retireDevice(shaft);
}

void SparkplugSession::sendBirths() {
  node_->resetSeq();
  const auto births_at = Clock::now();
  for (const auto& m : node_->births(counters_(), nowMs())) link_.sendOne(m, false);
  link_.openSession(births_at);
  ++births_;
  spdlog::info("Sparkplug: NBIRTH and {} DBIRTH on spBv1.0/{} as edge node '{}' (bdSeq {}){}", dir_.boundCount(),
               cfg_.sp_group_id, cfg_.sp_edge_node_id, node_->bdSeq(),
               link_.outbox().empty() ? std::string()
                                      : fmt::format("; then {} buffered messages", link_.outbox().size()));
}

void SparkplugSession::onConnected() {
  for (const auto& t : node_->subscriptions()) link_.subscribe(t);
  if (node_->waitsForHost())
    spdlog::info("Sparkplug: waiting for the primary host '{}' (spBv1.0/STATE/{} online) before the births; "
                 "storing until then",
                 cfg_.sp_primary_host_id, cfg_.sp_primary_host_id);
  else
    sendBirths();
  link_.flushJournal();
  link_.flushOutbox();
}

void SparkplugSession::end() {
  if (link_.connected()) {
    const OutMsg d = node_->death();
    link_.sendRaw(d.topic, d.payload.data(), static_cast<int>(d.payload.size()), d.qos, d.retain);
    link_.drainAndDisconnect(300, false);
  }
  link_.closeSession();
}

void SparkplugSession::tick(std::uint64_t now_ms) {
  if (link_.sessionOpen() && node_->rebirthDue(now_ms)) {  // a Rebirth held by acceptRebirth
    ++rebirths_;
    sendBirths();
  }
}

void SparkplugSession::healthTick() {
  if (link_.sessionOpen())
    if (auto m = node_->nodeData(counters_(), nowMs())) link_.publish(std::move(*m));
}

void SparkplugSession::onMessage(const struct mosquitto_message* m) {
  std::vector<sparkplug::Command> cmds;
  const auto in = node_->onMessage(m->topic, m->payload, m->payloadlen > 0 ? static_cast<std::size_t>(m->payloadlen) : 0,
                                   static_cast<std::size_t>(cfg_.max_command_bytes), m->retain, cmds, nowMs());
  using In = sparkplug::Node::Inbound;
  if (in == In::StateIgnored) {
    std::int64_t suppressed = 0;
    if (log_.allow(LogBudget::kCmd, Clock::now(), suppressed))
      spdlog::warn("Sparkplug: a STATE on {} ignored (not a STATE payload, older than the last one, or stamped "
                   "more than {} s ahead of this clock: check both clocks); {} so far [{} similar suppressed]",
                   printable(m->topic), sparkplug::Node::kStateFutureMs / 1000, node_->stateIgnored(), suppressed);
    return;
  }
  if (in == In::HostOnline) {
    if (!link_.sessionOpen()) {
      spdlog::info("Sparkplug: primary host '{}' is online", cfg_.sp_primary_host_id);
      sendBirths();
      link_.flushJournal();  // history first (the journal, then the memory buffer), then live data
      link_.flushOutbox();
    }
    return;
  }
  if (in == In::HostOfflineUnverified) {
    // Not the death of the session followed (another timestamp): a forgery
    // on a broker without the STATE ACL, or a host breaking Sparkplug's
    // rule.  Stored as for a death; the session's own online brings it back.
    std::int64_t suppressed = 0;
    if (log_.allow(LogBudget::kCmd, Clock::now(), suppressed))
      spdlog::warn("Sparkplug: an offline STATE on {} stamped otherwise than the host's online one (not its death: "
                   "forged, or a host breaking the Sparkplug 3.0 rule); storing until the host's online STATE is "
                   "read again (the reconnect reads the broker's retained one). Restrict who may write the topic "
                   "with the broker's ACL (docs/mqtt.md); {} so far [{} similar suppressed]",
                   printable(m->topic), node_->stateUnverified(), suppressed);
  }
  if (in == In::HostOffline || in == In::HostOfflineUnverified) {
    ++host_offline_;
    if (!link_.sessionOpen()) return;
    // Sparkplug 3.0: end the session (NDEATH, disconnect) and start over; meanwhile, store.
    spdlog::warn("Sparkplug: primary host '{}' went offline: NDEATH, reconnecting and storing until it is back",
                 cfg_.sp_primary_host_id);
    end();
    link_.lost("the primary host went offline");
    link_.reconnectNow();
    return;
  }
  if (in != In::Commands) return;
  const auto now = Clock::now();
  for (const auto& c : cmds) {
    gate_.countReceived();
    std::int64_t suppressed = 0;
    const bool may_log = log_.allow(LogBudget::kCmd, now, suppressed);
    if (c.what == sparkplug::Command::What::Rebirth) {
      // Within kRebirthMinMs of the births a request is held and merged
      // (sparkplug::Node::acceptRebirth): one NCMD may carry 200 Rebirth
      // metrics, and each birth queues NBIRTH and every DBIRTH.
      if (!node_->acceptRebirth(nowMs())) {
        if (may_log)
          spdlog::info("Sparkplug: rebirth requested (NCMD) less than {} s after the births: held, and done "
                       "when that interval has passed ({} requests held or merged so far) [{} similar suppressed]",
                       sparkplug::Node::kRebirthMinMs / 1000.0, node_->rebirthsCoalesced(), suppressed);
        continue;
      }
      ++rebirths_;
      gate_.countForwarded();
      if (may_log) spdlog::info("Sparkplug: rebirth requested (NCMD)");
      if (link_.sessionOpen()) sendBirths();
      continue;
    }
    const Shaft* s = dir_.boundByName(node_->shaftOf(c.device));
    if (c.what == sparkplug::Command::What::Refused) {
      gate_.refuse(s, c.reject, c.detail, m->topic, 0, may_log);
      continue;
    }
    if (!s) {
      gate_.refuse(nullptr, CommandReject::UnknownMetric, "no shaft '" + printable(c.device) + "'", m->topic, 0,
                   may_log);
      continue;
    }
    if (!cfg_.commands) {
      gate_.refuse(s, CommandReject::Disabled, "alarm commands are off (--no-commands)", m->topic, 0, may_log);
      continue;
    }
    // The same checker as hoist/<shaft>/cmd/ack.
    CommandResult r = parseAckCommand(c.json.data(), c.json.size(), static_cast<std::size_t>(cfg_.max_command_bytes),
                                      hoist::bus::wallUtime(), cfg_.max_command_age);
    if (r.reject != CommandReject::None) {
      gate_.refuse(s, r.reject, r.detail, m->topic, 0, may_log);
      continue;
    }
    gate_.execute(*s, r, m->payloadlen, may_log, now);
  }
}

}  // namespace hoist::mqtt
