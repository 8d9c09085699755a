// hoist/mqtt/sparkplug_node.hpp -- hoist-mqtt's Sparkplug B edge node: the
// session state the bridge (hoist/mqtt/bridge.hpp) dispatches to in
// Sparkplug mode.  No sockets: it makes the messages (OutMsg with
// sparkplug = true; the bridge stamps seq when it sends them) and classifies
// what arrives.
//
// Topics (Sparkplug B 3.0): spBv1.0/<group>/{NBIRTH,NDEATH,NDATA,NCMD}/<edge>,
// spBv1.0/<group>/{DBIRTH,DDEATH,DDATA,DCMD}/<edge>/<shaft>, and with a
// primary host spBv1.0/STATE/<host>.
//   * NDEATH is the MQTT will (QoS 1, not retained) with bdSeq; bdSeq goes up
//     by one (mod 256) per CONNECT, and the NBIRTH of that session carries it.
//   * seq: 0..255 over every message of the node but NDEATH; NBIRTH has 0.
//   * NCMD "Node Control/Rebirth" = true: the bridge sends every birth again.
//   * DCMD writes Alarms/<KIND>/Ack (true), /Shelve (seconds > 0),
//     /Unshelve (true): each becomes the JSON command of hoist/<shaft>/cmd/ack
//     and goes through the same checker (hoist/mqtt/command.hpp).
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "hoist/mqtt/command.hpp"
#include "hoist/mqtt/outbox.hpp"
#include "hoist/mqtt/sparkplug_metrics.hpp"

namespace hoist::mqtt::sparkplug {

/// False when hoist-mqtt was built without nanopb (no Sparkplug mode).
bool available();

struct NodeOptions {
  std::string group, edge, primary_host, version;
  double deadband = 0.0;
  std::map<std::string, double> deadbands;
};

/// One command of an NCMD or DCMD (a payload may carry several).
struct Command {
  enum class What : std::uint8_t { Rebirth, Alarm, Refused } what = What::Refused;
  std::string device;           ///< DCMD: the device id
  std::string json;             ///< What::Alarm: the payload for parseAckCommand
  std::string metric;           ///< for the log: the metric's name (or "alias N")
  CommandReject reject = CommandReject::None;
  std::string detail;
};

class Node {
 public:
  explicit Node(NodeOptions o);

  // ---- the session -------------------------------------------------------------
  /// The NDEATH for the will of the next CONNECT (bdSeq goes up by one).
  OutMsg nextWill();
  /// NDEATH with the current bdSeq (published before a clean disconnect).
  OutMsg death() const;
  std::int64_t bdSeq() const { return bd_seq_; }
  /// Subscriptions after each CONNECT (QoS 1): NCMD, DCMD/+, STATE/<host>.
  std::vector<std::string> subscriptions() const;
  bool waitsForHost() const { return !opt_.primary_host.empty(); }
  bool hostOnline() const { return host_online_; }
  /// The births (NBIRTH, then every device's DBIRTH, in device order).
  std::vector<OutMsg> births(const NodeCounters& c, std::uint64_t now_ms);
  /// The next seq (0..255), and its reset to 0 before an NBIRTH.
  std::uint8_t nextSeq() { return static_cast<std::uint8_t>(seq_++ & 0xff); }
  void resetSeq() { seq_ = 0; }

  // ---- devices (one per shaft) ---------------------------------------------------
  /// The device of a shaft name (created with its alias block on first use).
  DeviceMetrics& device(const std::string& shaft_name);
  bool hasDevice(const std::string& shaft_name) const;
  /// The shaft is no longer bridged: no DBIRTH for it until device() again
  /// (its aliases stay reserved for it).
  void retireDevice(const std::string& shaft_name);
  OutMsg deviceBirth(const std::string& shaft_name, std::uint64_t now_ms);
  OutMsg deviceDeath(const std::string& shaft_name, std::uint64_t now_ms);
  /// DDATA of the metrics of `src` that changed (nullopt: nothing changed).
  std::optional<OutMsg> deviceData(const std::string& shaft_name, Source src, MsgClass cls, std::uint64_t now_ms);
  std::optional<OutMsg> nodeData(const NodeCounters& c, std::uint64_t now_ms);
  /// The shaft name of a device id, "" if none.
  std::string shaftOf(const std::string& device_id) const;

  // ---- inbound -----------------------------------------------------------------
  enum class Inbound : std::uint8_t { NotOurs, Commands, HostOnline, HostOffline, HostOfflineUnverified, StateIgnored };
  /// Classifies one received message: NCMD/DCMD (commands appended to `out`),
  /// or the primary host's STATE.  Sparkplug 3.0 stamps a host's online
  /// STATE and its death (the will) with one timestamp, that of the session's
  /// CONNECT; a later session has a later one.  A STATE older than the last
  /// accepted online one (an earlier session's) is ignored.  Else:
  ///   * online: HostOnline, that session now the one known -- also the
  ///     same session's online after an offline: the host republishes it
  ///     when it reads an offline on its own topic, and the broker's
  ///     retained copy is read again at the reconnect;
  ///   * offline with the session's timestamp: its death (HostOffline);
  ///   * offline with a later timestamp: no death of the session known -- a
  ///     forgery, or a host that breaks the rule.  The caller stores as for
  ///     a death (HostOfflineUnverified, counted in stateUnverified()),
  ///     and the bar stays the session's, so its online brings it back.
  /// Without the broker's ACL on the STATE topic a forger can still end
  /// sessions (a copied timestamp is a death); never lose the data.
  /// `now_ms` (wall clock; 0 = unchecked): a STATE stamped more than
  /// kStateFutureMs after it is ignored -- else one forged far-future online
  /// STATE would make every genuine one "older" until a restart.  Every
  /// ignored STATE is counted (stateIgnored()).
  Inbound onMessage(const std::string& topic, const void* data, std::size_t size, std::size_t max_bytes,
                    bool retained, std::vector<Command>& out, std::uint64_t now_ms = 0);
  static constexpr std::uint64_t kStateFutureMs = 600'000;
  std::int64_t stateIgnored() const { return state_ignored_; }
  std::int64_t stateUnverified() const { return state_unverified_; }
  /// A Rebirth request (NCMD) at `now_ms`: true = do the births now.  Within
  /// kRebirthMinMs of the last births it is held instead (false), and any
  /// further requests merge into the held one, which rebirthDue() releases
  /// when the interval has passed: a host that missed the births still gets
  /// them, and a flood (one NCMD may carry 200 Rebirth metrics, each birth
  /// queues NBIRTH and every DBIRTH) costs at most two births per interval.
  /// Held and merged requests are counted (rebirthsCoalesced()).
  bool acceptRebirth(std::uint64_t now_ms);
  /// A held Rebirth whose interval has passed: true once (do the births).
  bool rebirthDue(std::uint64_t now_ms);
  static constexpr std::uint64_t kRebirthMinMs = 2'000;
  std::int64_t rebirthsCoalesced() const { return rebirths_coalesced_; }

  const NodeOptions& options() const { return opt_; }

 private:
  OutMsg make(std::string topic, const Payload& p, MsgClass cls, int qos = 0) const;
  void deviceCommands(const std::string& device, const Payload& p, std::vector<Command>& out) const;

  NodeOptions opt_;
  std::int64_t bd_seq_ = -1;
  unsigned seq_ = 0;
  bool host_online_ = false;
  bool have_session_ = false;  // an online STATE was accepted: host_ts_ is its session's timestamp
  std::uint64_t host_ts_ = 0;
  std::uint64_t births_ms_ = 0;  // wall time of the last births()
  bool born_ = false, rebirth_held_ = false;
  std::int64_t state_ignored_ = 0, state_unverified_ = 0, rebirths_coalesced_ = 0;
  NodeCounters last_counters_;
  struct Dev {
    std::string shaft, id;
    DeviceMetrics metrics;
    bool active = true;
  };
  std::deque<Dev> devices_;  // in creation order (alias blocks 1000, 2000, ...)
};

}  // namespace hoist::mqtt::sparkplug
