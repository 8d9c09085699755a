// hoist/dash hub.hpp -- the Foxglove WebSocket protocol (subprotocol
// foxglove.websocket.v1) between the hoist LCM channels and any number of
// clients, without any networking: the Beast server (server.hpp) feeds it the
// clients' frames, main.cpp the LCM messages, and it answers through the
// Client interface.  Single-threaded: every call comes from one Asio loop.
//
// What it implements (docs/dashboard.md): serverInfo, status, advertise
// (one channel per hoist LCM channel and shaft prefix, JSON encoding, JSON
// Schema from the message codec, plus one decimated cage channel and one
// decimated load-estimate channel per shaft),
// subscribe / unsubscribe with client-chosen ids, binary messageData, and
// (unless read-only) clientPublish of HOIST_ALARM_ACK in JSON.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "hoist/rt/token_bucket.hpp"

namespace hoist {
class alarm_ack_t;  // hoist/alarm_ack_t.hpp (lcm-gen)
}

namespace hoist::dash {

using Json = nlohmann::json;

/// The channel suffix (LCM channel name without the shaft prefix) of each
/// hoist message type ("hoist.cage_state_t" -> "HOIST_CAGE"); "" if none.
std::string channelSuffixOfType(const std::string& type_name);
/// The suffix `channel` ends with (longest match), "" if it is no hoist channel.
std::string hoistSuffixOf(const std::string& channel);

/// Min/max decimation of a stream of JSON messages: every numeric leaf (also
/// inside arrays) keeps its smallest and largest value over the interval, so
/// that no peak is lost at the display rate; booleans keep their OR in "max"
/// and AND in "min"; the interval's last message is kept whole.
class MinMaxDecimator {
 public:
  void add(const Json& sample);
  bool empty() const { return count_ == 0; }
  /// {"count", "first": {"t", "utime"}, "last": <message>, "min": {...}, "max": {...}}; resets.
  Json take();

 private:
  static void foldMin(Json& acc, const Json& v);
  static void foldMax(Json& acc, const Json& v);
  std::size_t count_ = 0;
  Json first_, last_, min_, max_;
};

/// One connected protocol client (a WebSocket session, or a test double).
class Client {
 public:
  virtual ~Client() = default;
  /// A JSON text frame (control: serverInfo, advertise, status).
  virtual void sendText(std::shared_ptr<const std::string> frame) = 0;
  /// A binary messageData frame; the client may drop it when it is behind.
  virtual void sendData(std::shared_ptr<const std::string> frame) = 0;

 private:
  friend class Hub;
  std::map<std::uint32_t, std::uint32_t> subs_;     // subscription id -> channel id
  std::map<std::uint32_t, std::uint32_t> by_chan_;  // channel id -> subscription id
  std::map<std::uint32_t, std::string> published_;  // client channel id -> LCM channel
  std::optional<rt::TokenBucket> commands_;          // its command rate (Options::command_rate), from the first
};

class Hub {
 public:
  struct Options {
    bool read_only = false;
    std::vector<std::string> prefixes;  ///< fixed prefixes (--channel-prefix); empty: discover
    bool discover = true;               ///< add prefixes seen on *HOIST_HEALTH
    std::size_t max_prefixes = 16;
    // Discovery (docs/dashboard.md "Shaft discovery"): a discovered prefix is
    // a candidate until `confirm_count` HOIST_HEALTH messages of one non-zero
    // daemon instance id arrived at most `health_gap_s` apart; a candidate
    // silent for `candidate_ttl_s` loses its slot, and a confirmed prefix
    // silent for `confirmed_idle_s` may be replaced when the table is full.
    int confirm_count = 3;
    double health_gap_s = 3.0;
    double candidate_ttl_s = 3.0;
    double confirmed_idle_s = 60.0;
    double history_s = 300.0;         ///< trend history kept per shaft (the page's longest window)
    double history_bucket_s = 0.2;    ///< its resolution (min and max per bucket)
    std::size_t max_lcm_bytes = 1 << 20;  ///< larger LCM messages are dropped (counted)
    Json shaft_meta = Json::object();     ///< prefix -> {warning_fraction, ...} (serverInfo metadata)
    // Client-published messages (commands) a second per client, in bursts of
    // `command_burst` (a token bucket; beyond it refused and counted, never
    // parsed).  64 clients at 2/s stay far inside a daemon's budget
    // (max_commands_per_tick = 4 at 100 Hz): a client flooding valid
    // commands cannot take another operator's (--command-rate, --command-burst).
    double command_rate = 2.0;
    double command_burst = 10.0;
  };
  /// Publishes encoded bytes on an LCM channel; false on failure.
  using Publisher = std::function<bool(const std::string& channel, const std::vector<std::uint8_t>& bytes)>;
  using Clock = std::function<std::uint64_t()>;  ///< wall time in ns since the epoch

  Hub(Options opt, Publisher publish, Clock clock);

  void addClient(Client& c);     ///< sends serverInfo and advertise
  void removeClient(Client& c);
  std::size_t clientCount() const { return clients_.size(); }

  /// A raw LCM message: validated and decoded by the codec (failures
  /// counted, never thrown), then sent to the subscribers.
  void onLcm(const std::string& channel, const void* data, std::size_t size);
  /// Flush the decimated channels (call at the display rate, ~25 Hz); also
  /// ages out discovered prefixes and updates the discovery status.
  void flushDecimated();
  /// From now on, ask each shaft's daemon to re-announce its alarms' current
  /// states (alarm_ack_t ACTION_REANNOUNCE; it changes nothing) when its
  /// health first arrives -- at start, for a shaft discovered later, for a
  /// new daemon instance -- so that alarms raised before are listed at once.
  /// Call once the LCM receive path is open (main.cpp).
  void requestAlarmStates();
  /// Ages out silent candidate prefixes; updates the discovery status.
  void maintainDiscovery();
  /// The shaft name of a channel prefix: the prefix without one trailing
  /// separator ('/', '_', '-', '.'), "default" for "" (hoist-mqtt's rule).
  static std::string shaftName(const std::string& prefix);

  void onClientText(Client& c, std::string_view text);
  void onClientBinary(Client& c, std::string_view bytes);

  /// Counted events (rejections, drops, ...), by name.
  void count(const std::string& what, std::uint64_t n = 1) { counters_[what] += n; }
  std::uint64_t counter(const std::string& what) const;
  Json stats() const;
  const std::vector<std::string>& prefixes() const { return prefix_list_; }
  bool readOnly() const { return opt_.read_only; }

  static constexpr const char* kDecimatedSuffix = "HOIST_CAGE/decimated";
  /// HOIST_ESTIMATE decimated like the cage (the page's load-estimate panel).
  static constexpr const char* kEstimateDecimatedSuffix = "HOIST_ESTIMATE/decimated";
  /// The recent trend history of a shaft, sent whole on subscribe (docs/dashboard.md).
  static constexpr const char* kHistorySuffix = "HOIST_CAGE/history";
  /// The cage fields the history keeps (min and max per bucket); "lambdas.K" is lambdas[K].
  static const std::vector<std::string>& historyFields();

 private:
  struct Channel {
    std::uint32_t id = 0;
    std::string topic, prefix, suffix, schema_name, schema;
    std::shared_ptr<const std::string> latest;                   // replayed on subscribe (health, shape)
    std::map<std::string, std::shared_ptr<const std::string>> table;  // alarms: kind/level -> latest
  };
  struct Evidence {  // what a discovered prefix has shown of itself
    std::uint64_t first_ns = 0, last_ns = 0;
    int count = 0;             // health messages of `instance` at most health_gap_s apart
    std::int64_t instance = 0;
    bool confirmed = false;
  };
  struct HistBucket {
    std::int64_t first_utime = 0, last_utime = 0;
    std::vector<double> min, max;  // historyFields() order
  };
  struct AlarmIdentity {  // one alarm's activation, kept across re-announces
    std::int64_t activation_utime = 0, reannounce_utime = 0;
    double activation_t = 0.0;
    bool known = false;  // false: first heard after its RAISE (hoist-dash started later)
  };
  void annotateAlarm(const std::string& prefix, Json& j);
  void addHistory(const std::string& prefix, const Json& decimated);
  std::string historyOf(const std::string& prefix) const;
  void addPrefix(const std::string& prefix);
  void requestAlarmStates(const std::string& prefix);
  void maybeRequestAlarmStates(const std::string& prefix, const Json& health);
  /// A shaft's health names another daemon instance than before: the alarm
  /// states older than the new instance's start are void -- removed from the
  /// table and sent to the clients as cleared ("the daemon restarted", as
  /// hoist-mqtt does); the new instance is asked to re-announce its own.
  /// Another instance while the followed one has been heard within
  /// health_gap_s is an impostor under its prefix: false (the caller drops
  /// its health), counted (health_impostor) and logged; the shaft is kept.
  bool noteInstance(const std::string& prefix, const Json& health);
  /// True if `j` (a message on `prefix` + `suffix`) comes from the daemon
  /// instance whose health the hub follows; alarm events need that instance
  /// known, other data passes before the first health.  Else counted
  /// (<suffix>_foreign_instance) and logged (rate-limited), issue 33.
  bool fromFollowedInstance(const std::string& prefix, const std::string& suffix, const Json& j);
  void removePrefix(const std::string& prefix);
  void onDiscoveryHealth(const std::string& prefix, const Json& health);
  void noteHealth(Evidence& e, std::int64_t instance, std::uint64_t now) const;
  void setStatus(const std::string& id, int level, const std::string& msg);  ///< persistent, to every client
  void clearStatus(const std::string& id);
  void checkNameClashes();
  bool logAllowed();  ///< discovery log lines: at most 10 per 10 s
  Channel* channelFor(const std::string& topic);
  Json advertiseOf(const std::vector<const Channel*>& chans) const;
  void broadcast(Channel& ch, const std::shared_ptr<const std::string>& payload);
  void sendTo(Client& c, std::uint32_t sub_id, const std::string& payload);
  void status(Client& c, int level, const std::string& msg);
  void handleSubscribe(Client& c, const Json& j);
  void handleUnsubscribe(Client& c, const Json& j);
  void handleClientAdvertise(Client& c, const Json& j);
  void handleClientUnadvertise(Client& c, const Json& j);
  void handleClientMessage(Client& c, std::uint32_t chan, std::string_view payload);
  /// ACTION_CALIBRATE from a client: validated as the daemon validates it, then published on `channel`.
  void sendCalibration(Client& c, const std::string& channel, alarm_ack_t& ack, bool names_an_alarm);

  Options opt_;
  bool request_states_ = false;  // requestAlarmStates() was called
  std::map<std::string, std::int64_t> instance_;      // prefix -> daemon instance followed (its latest accepted health)
  std::map<std::string, std::uint64_t> instance_last_ns_;  // prefix -> when that instance's health was last heard
  std::map<std::string, std::int64_t> states_asked_;  // prefix -> daemon instance asked (bounded by the prefixes)
  Publisher publish_;
  Clock clock_;
  std::set<Client*> clients_;
  std::vector<std::string> prefix_list_;
  std::map<std::string, Channel> channels_;             // by topic
  std::map<std::uint32_t, Channel*> by_id_;
  std::map<std::string, MinMaxDecimator> decimators_;   // by prefix
  std::map<std::string, MinMaxDecimator> estimate_decimators_;  // by prefix (HOIST_ESTIMATE)
  std::map<std::string, std::map<std::string, std::shared_ptr<const std::string>>> pending_alarms_;
  std::map<std::string, std::uint64_t> pending_since_;  // when each pending prefix was first heard (aged out)
  std::uint32_t next_id_ = 1;
  std::map<std::string, Evidence> disc_;     // discovered prefixes in the table
  std::map<std::string, Evidence> refused_;  // recently refused prefixes (bounded)
  std::uint64_t last_refusal_ns_ = 0, refused_total_ = 0, last_maintain_ns_ = 0;
  std::string last_refused_;
  std::uint64_t log_window_ns_ = 0, log_lines_ = 0;
  std::map<std::string, Json> statuses_;     // persistent statuses by id (sent to new clients)
  std::map<std::string, std::uint64_t> status_sent_ns_;  // last broadcast of each persistent status (at most 1/s per id)
  std::set<std::string> status_dirty_;                   // changed since its last broadcast (sent by maintainDiscovery)
  std::map<std::string, std::deque<HistBucket>> history_;      // by prefix
  std::map<std::string, AlarmIdentity> alarm_ids_;             // by prefix + kind/level
  std::map<std::string, std::uint64_t> counters_;
  std::string session_id_;
};

/// Checks an operator command before it is published: the page's policy
/// (a kind named, "*" for all; action ACK, SHELVE or UNSHELVE; a shelve of
/// at most 1e6 s) on top of the daemon's own rule
/// (hoist::contract::validateAlarmCommand: a known kind, level 0..2, a
/// finite shelve_duration > 0), then the operator-name rule
/// (validateCommandUser).  Returns "" when valid, else the reason.
std::string validateAckFields(const std::string& kind, int level, int action, double shelve_duration,
                              const std::string& user);
/// The user rule of every operator command: 1..64 characters, no control
/// character.  "" when valid, else the reason.
std::string validateCommandUser(const std::string& user);

}  // namespace hoist::dash
