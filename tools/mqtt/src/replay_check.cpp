// What the bridge would publish now: see replay_check.hpp.
#include "replay_check.hpp"

#include "hoist/mqtt/sparkplug_metrics.hpp"
#include "shaft_data.hpp"

namespace hoist::mqtt {

std::string replayRefusal(const OutMsg& m, const BridgeConfig& cfg, const ShaftDirectory& dir,
                          const std::string& health_topic) {
  if (m.qos < 0 || m.qos > 1) return "QoS " + std::to_string(m.qos) + " (the bridge publishes at 0 or 1)";
  if (m.topic == health_topic) return !m.retain && !m.sparkplug ? "" : "the bridge's health is never retained";
  if (cfg.sparkplug) {
    if (!m.sparkplug || m.retain) return "not a Sparkplug data message as the bridge sends them (unretained)";
    if (m.topic == sparkplug::nodeTopic(cfg.sp_group_id, "NDATA", cfg.sp_edge_node_id)) return "";
    for (const auto& [p, s] : dir.all())
      if (s.bound && m.topic == sparkplug::deviceTopic(cfg.sp_group_id, "DDATA", cfg.sp_edge_node_id,
                                                       sparkplug::deviceId(s.name)))
        return "";
    return "not a DDATA/NDATA topic of this edge node's shafts";
  }
  if (m.sparkplug) return "a Sparkplug payload, but Sparkplug mode is off";
  for (const auto& [p, s] : dir.all()) {
    if (!s.bound) continue;
    const std::string base = "hoist/" + s.name + "/";
    if (m.topic.compare(0, base.size(), base) != 0) continue;
    const std::string rest = m.topic.substr(base.size());
    if (rest == "cage" || rest == "health" || rest == "forecast" || rest == "estimate" || rest == "cmd/result")
      return m.retain ? "retained, but the bridge never retains " + rest : "";
    if (rest.compare(0, 6, "alarm/") == 0 && ShaftData::validKind(rest.substr(6)))
      return m.retain ? "" : "an alarm state not retained";
    // A topic inside a bridged shaft's tree that the bridge does not write
    // (its command topic among them): try the other shafts, else refuse.
  }
  return "not a data topic of a shaft this bridge publishes now";
}

}  // namespace hoist::mqtt
