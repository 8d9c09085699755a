// The bridge's own health: see bridge_health.hpp.
#include "bridge_health.hpp"

#include <spdlog/spdlog.h>

namespace hoist::mqtt {

using json = nlohmann::json;

BridgeHealth::BridgeHealth(const BridgeConfig& cfg, const std::string& client_id, const LcmSide& lcm,
                           const ShaftDirectory& dir, const ShaftData& data, const MqttLink& link,
                           const CommandGate& gate, const SparkplugSession* sp)
    : cfg_(cfg), client_id_(client_id), lcm_(lcm), dir_(dir), data_(data), link_(link), gate_(gate), sp_(sp) {}

namespace {
std::uint64_t alarmDrops(const MqttLink& link) {
  return link.outbox().droppedAlarm() + (link.journal() ? link.journal()->droppedAlarm() : 0);
}
}  // namespace

void BridgeHealth::watch(Clock::time_point now) {
  const std::uint64_t drops = alarmDrops(link_);
  if (drops > alarm_drops_seen_) {
    alarm_drops_unlogged_ += drops - alarm_drops_seen_;
    alarm_drops_seen_ = drops;
    last_drop_ = now;
    dropped_ever_ = true;
  }
  if (alarm_drops_unlogged_ > 0 && (last_drop_log_ == Clock::time_point{} || seconds(now - last_drop_log_) >= kDropLogS)) {
    last_drop_log_ = now;
    if (const Journal* j = link_.journal())
      spdlog::warn("store-and-forward journal {}: {} alarm transitions dropped (the journal reached [buffer] "
                   "max_bytes = {} with nothing else left to drop; {} in all): each kind's current state is "
                   "republished on reconnection, the transitions between are lost; the bridge's health is WARNING",
                   j->path(), alarm_drops_unlogged_, cfg_.journal_max_bytes, drops);
    else
      spdlog::warn("{} alarm transitions dropped from the memory buffer ([buffer] max_alarm_events = {}; {} in "
                   "all): each kind's current state is republished on reconnection, the transitions between are "
                   "lost; the bridge's health is WARNING",
                   alarm_drops_unlogged_, cfg_.max_alarm_events, drops);
    alarm_drops_unlogged_ = 0;
  }
}

json BridgeHealth::build() const {
  const auto now = Clock::now();
  const auto& ln = link_.counters();
  json j = json::object();
  j["utime"] = hoist::bus::wallUtime();
  j["client_id"] = client_id_;
  j["uptime"] = seconds(now - started_);
  j["broker"] = link_.brokerText();
  j["connection"] = {{"state", link_.stateText()},
                     {"connected_since_utime", link_.connected() ? link_.connectedSinceUtime() : 0},
                     {"connects", ln.connects},
                     {"disconnects", ln.disconnects},
                     {"connect_failures", ln.connect_failures},
                     {"last_error", link_.lastError()}};
  json dec = json::object();
  for (const auto& [k, n] : lcm_.decodeErrors()) dec[k] = n;
  j["lcm"] = {{"url", hoist::bus::describeLcmUrl(lcm_.url())},
              {"messages", lcm_.messages()},
              {"decode_errors", lcm_.decodeErrorsTotal()},
              {"decode_errors_by_reason", dec},
              {"alarm_rejected", data_.alarmRejected()},
              {"foreign_instance", data_.foreignInstance()},
              {"impostor_health", dir_.impostors()},
              {"ignored_channels", lcm_.ignoredChannels()}};
  j["mqtt"] = {{"published", ln.published}, {"publish_errors", ln.publish_errors}};
  if (sp_) {
    const auto& node = sp_->node();
    j["sparkplug"] = {{"group_id", cfg_.sp_group_id},
                      {"edge_node_id", cfg_.sp_edge_node_id},
                      {"primary_host_id", cfg_.sp_primary_host_id},
                      {"host_online", node.waitsForHost() ? node.hostOnline() : true},
                      {"session", link_.sessionOpen()},
                      {"bdseq", node.bdSeq()},
                      {"births", sp_->births()},
                      {"rebirths", sp_->rebirths()},
                      {"rebirths_coalesced", node.rebirthsCoalesced()},
                      {"state_ignored", node.stateIgnored()},
                      {"state_unverified", node.stateUnverified()},
                      {"host_offline", sp_->hostOffline()}};
  }
  j["stale_cage"] = {{"marked", ln.stale_marked}, {"dropped", ln.stale_dropped}};
  if (const Journal* jr = link_.journal()) {
    const JournalReport& rep = link_.journalReport();
    j["journal"] = {{"path", jr->path()},
                    {"queued", jr->size()},
                    {"queued_alarms", jr->queuedAlarms()},
                    {"file_bytes", jr->fileBytes()},
                    {"max_bytes", cfg_.journal_max_bytes},
                    {"appended", jr->appended()},
                    {"replayed", ln.journal_replayed},
                    {"replay_refused", ln.journal_refused},
                    {"inflight", link_.inflight()},
                    {"dropped_cage", jr->droppedCage()},
                    {"dropped_health", jr->droppedHealth()},
                    {"dropped_alarm", jr->droppedAlarm()},
                    {"oversized", jr->oversized()},
                    {"fallback", ln.journal_fallback},
                    {"recovered", rep.recovered},
                    {"corrupt", rep.problem.empty() ? 0 : 1},
                    {"corrupt_bytes", rep.skipped_bytes},
                    {"corrupt_reason", rep.problem},
                    {"read_errors", jr->readErrors()},
                    {"write_errors", jr->writeErrors()},
                    {"last_error", jr->lastError()},
                    {"fsyncs", jr->fsyncs()},
                    {"compactions", jr->compactions()},
                    {"prepended_at_shutdown", ln.journal_prepended}};
  }
  const Outbox& ob = link_.outbox();
  j["buffer"] = {{"queued", ob.size()},
                 {"queued_alarms", ob.queuedAlarms()},
                 {"max_messages", cfg_.max_messages},
                 {"max_alarm_events", cfg_.max_alarm_events},
                 {"dropped_cage", ob.droppedCage()},
                 {"dropped_health", ob.droppedHealth()},
                 {"dropped_alarm", ob.droppedAlarm()}};
  const auto& gn = gate_.counters();
  json by_reason = json::object();
  for (int i = 1; i < kCommandRejects; ++i) by_reason[toString(static_cast<CommandReject>(i))] = gn.by_reason[i];
  j["commands"] = {{"enabled", cfg_.commands},
                   {"received", gn.received},
                   {"forwarded", gn.forwarded},
                   {"rejected", gn.rejected},
                   {"rejected_by_reason", by_reason},
                   {"results_published", gn.results_published},
                   {"results_dropped", gn.results_dropped},
                   {"lcm_publish_failures", gn.lcm_failures}};
  json sh = json::array();
  json conflicts = json::array(), refused = json::array();
  std::size_t candidates = 0;
  for (const auto& [p, s] : dir_.all()) {
    if (s.refused && refused.size() < 16) refused.push_back(p);
    if (!s.bound) {
      candidates += s.confirmed ? 0 : 1;
      continue;
    }
    if (auto r = dir_.rivals(s); !r.empty()) {
      json ps = json::array({p});
      for (const auto& x : r) ps.push_back(x);
      conflicts.push_back({{"shaft", s.name}, {"bridged_prefix", p}, {"prefixes", ps}});
    }
    static const ShaftData::Feed kNone{};
    const ShaftData::Feed* f = data_.find(p);
    if (!f) f = &kNone;
    sh.push_back({{"name", s.name},
                  {"channel_prefix", s.prefix},
                  {"health_age", s.health_in ? seconds(now - s.last_health) : -1.0},
                  {"cage_in", f->cage_in},
                  {"cage_out", f->cage_out},
                  {"health_in", s.health_in},
                  {"forecasts_in", f->forecasts_in},
                  {"estimates_in", f->estimates_in},
                  {"estimates_out", f->estimates_out},
                  {"alarm_events_in", f->alarms_in},
                  {"alarms_active", data_.activeAlarms(p)},
                  {"commands", gate_.commands(p)}});
  }
  j["shafts"] = sh;
  json warnings = json::array();
  if (dropped_ever_ && seconds(now - last_drop_) < kDropWarnS)
    warnings.push_back(fmt::format("{} alarm transitions dropped (journal or memory buffer full); the last {:.0f} s ago",
                                   alarmDrops(link_), seconds(now - last_drop_)));
  j["level"] = warnings.empty() ? "OK" : "WARNING";
  j["warnings"] = warnings;
  j["discovery"] = {{"enabled", dir_.discovering()},
                    {"slots_used", dir_.slotsUsed()},
                    {"max_shafts", cfg_.max_shafts},
                    {"table_full", dir_.tableFull()},
                    {"candidates", candidates},
                    {"refused", refused},
                    {"refused_total", dir_.refusedTotal()},
                    {"conflicts", conflicts},
                    {"aged_out", dir_.agedOut()},
                    {"evicted_candidates", dir_.evictedCandidates()}};
  return j;
}

}  // namespace hoist::mqtt
