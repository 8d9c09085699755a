// mqtt_link.hpp -- the bridge's MQTT link: the libmosquitto connection
// (connect with exponential backoff, loss, callbacks), and everything on the
// way out: the one send function, the bounded memory buffer
// (hoist/mqtt/outbox.hpp), the store-and-forward journal
// (hoist/mqtt/journal.hpp) and the QoS 1 messages in flight.  Private to
// tools/mqtt; the map of the rooms is bridge.cpp.
//
// Writes only its own state.  What a connection means to the rest (the
// status topic, subscriptions, Sparkplug births) is the Events listener's.
// In Sparkplug mode live data waits for the session (openSession()), and
// each Sparkplug message is stamped with the session's next seq when sent.
#pragma once

#include <mosquitto.h>

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "bridge_common.hpp"
#include "hoist/mqtt/config.hpp"
#include "hoist/mqtt/journal.hpp"
#include "hoist/mqtt/outbox.hpp"

namespace hoist::mqtt {

class MqttLink {
 public:
  class Events {
   public:
    virtual ~Events() = default;
    /// CONNACK accepted: the link is Connected (subscriptions are gone).
    virtual void connected() = 0;
    /// A message on a subscribed topic (inside loop()).
    virtual void message(const struct mosquitto_message* m) = 0;
  };
  /// Sparkplug hooks (both empty in JSON mode): the will before each
  /// connection (NDEATH with the next bdSeq), and the next seq of a message sent.
  struct SparkplugHooks {
    std::function<OutMsg()> next_will;
    std::function<std::uint8_t()> next_seq;
  };
  /// "" if a record read back from the journal is one the bridge would
  /// publish now (its own shafts' data topics, with the retain flag it
  /// sets), else why not: such a record is dropped, counted and logged,
  /// never sent (a planted journal must not reach a command topic, STATE or $SYS).
  using ReplayCheck = std::function<std::string(const OutMsg&)>;

  /// `cfg` and `events` are referenced and must outlive the link; the
  /// password is handed to libmosquitto.  Throws std::runtime_error if
  /// libmosquitto refuses the settings.  The journal ([buffer] dir) is opened here.
  MqttLink(const BridgeConfig& cfg, const std::string& password, const std::string& client_id,
           const std::string& status_topic, Events& events, SparkplugHooks sp, ReplayCheck replay_check,
           LogBudget& log);
  ~MqttLink();
  MqttLink(const MqttLink&) = delete;
  MqttLink& operator=(const MqttLink&) = delete;

  enum class Conn { Disconnected, Connecting, Connected };

  // ---- connection ----
  /// Connects when due, times out a silent attempt; call every loop.
  void tick(Clock::time_point now);
  /// The socket to poll (-1 if none) and whether it wants POLLOUT.
  int socket() const;
  bool wantWrite() const { return mosquitto_want_write(mosq_); }
  /// libmosquitto's network step and the callbacks it raised.
  void loop();
  /// An established connection was lost (or ended on purpose: ownDisconnect).
  void lost(const std::string& why);
  /// After our own disconnect: reconnect at once, not counted as a failure.
  void reconnectNow();
  Conn state() const { return conn_; }
  bool connected() const { return conn_ == Conn::Connected; }
  Clock::time_point nextAttempt() const { return next_attempt_; }
  const char* stateText() const;
  std::string brokerText() const;

  // ---- the way out ----
  /// Sparkplug: live data may go out (births sent); messages queued before
  /// `births_at` are history.
  void openSession(Clock::time_point births_at);
  void closeSession() { session_ = false; }
  bool sessionOpen() const { return session_; }
  /// Connected and, in Sparkplug mode, the session open.
  bool liveReady() const { return conn_ == Conn::Connected && (!sparkplug_ || session_); }
  /// Publishes now if connected and nothing is waiting, else buffers (journal or memory).
  void publish(OutMsg m);
  /// The one send function: true if handed to libmosquitto.  `historical`:
  /// replayed from the journal / queued before the births.
  bool sendOne(const OutMsg& m, bool historical);
  /// A message outside the buffers (retained-command deletion, NDEATH at the end).
  void sendRaw(const std::string& topic, const void* payload, int len, int qos, bool retain);
  void flushJournal();
  void flushOutbox();
  void sync() {
    if (journal_) journal_->sync();
  }
  void subscribe(const std::string& topic);
  void unsubscribe(const std::string& topic);
  bool subscribed(const std::string& topic) const { return subscribed_.count(topic) > 0; }
  /// Waits up to `ms` for the socket to drain (and, with `acks`, the
  /// acknowledgements), then disconnects cleanly.
  void drainAndDisconnect(int ms, bool acks);
  /// One last network step after the disconnect (let DISCONNECT leave).
  void finalLoop();
  /// Puts what is unacknowledged back at the journal's front and closes it.
  void closeJournal();

  /// An alarm state is waiting in the journal (replayed retained: no republish needed).
  bool journaledAlarm(const std::string& topic) const { return journaled_alarm_topics_.count(topic) > 0; }
  /// Forgets those after the republish; true if the journal dropped alarm
  /// transitions since the last call.
  bool takeJournalAlarmLoss();
  void clearJournaledAlarms() { journaled_alarm_topics_.clear(); }

  // ---- const views (bridge health) ----
  const Outbox& outbox() const { return outbox_; }
  const Journal* journal() const { return journal_.get(); }
  const JournalReport& journalReport() const { return journal_report_; }
  struct Counters {
    std::uint64_t connects = 0, disconnects = 0, connect_failures = 0, published = 0, publish_errors = 0;
    std::uint64_t journal_replayed = 0, journal_fallback = 0, journal_prepended = 0;
    std::uint64_t stale_marked = 0, stale_dropped = 0;
    std::uint64_t journal_refused = 0;  ///< records not replayed: not what the bridge would publish now
  };
  const Counters& counters() const { return n_; }
  std::size_t inflight() const { return inflight_.size(); }
  std::int64_t connectedSinceUtime() const { return connected_since_utime_; }
  const std::string& lastError() const { return last_error_; }

 private:
  void check(int rc, const char* what);
  void tryConnect();
  void failed(const std::string& why);
  void onConnected();
  void onAcknowledged(int mid);
  void store(OutMsg m);
  void openJournal();

  const BridgeConfig& cfg_;
  BrokerUrl broker_;
  std::string client_id_, status_topic_;
  Events& events_;
  SparkplugHooks sp_;
  bool sparkplug_ = false;
  ReplayCheck replay_check_;
  LogBudget& log_;

  struct mosquitto* mosq_ = nullptr;
  Conn conn_ = Conn::Disconnected;
  Clock::time_point next_attempt_{}, connecting_since_{};
  std::int64_t connected_since_utime_ = 0;
  double delay_ = 0.0;
  bool failing_ = false;  // the current series of attempts has been logged as failing
  std::string last_error_;
  // Set by libmosquitto's callbacks (called inside mosquitto_loop, this thread).
  bool cb_connack_ = false, cb_disconnected_ = false;
  int cb_connack_rc_ = 0, cb_disconnect_rc_ = 0;
  std::set<std::string> subscribed_;  // on the current connection

  bool session_ = false;
  Clock::time_point births_at_{};

  Outbox outbox_;
  // Store-and-forward: while the broker is away (or the socket congested, or
  // too many messages await their acknowledgement) messages go to the
  // journal, in order, replayed on reconnection before live data.  The QoS 1
  // messages handed to libmosquitto and not yet acknowledged are kept here;
  // at shutdown the ones still unacknowledged go back to the journal's front.
  static constexpr std::size_t kMaxInflight = 256;
  std::unique_ptr<Journal> journal_;
  JournalReport journal_report_;
  struct Inflight {
    int mid;
    OutMsg m;
  };
  std::deque<Inflight> inflight_;
  std::set<std::string> journaled_alarm_topics_;
  std::uint64_t journal_alarm_drops_seen_ = 0;
  Counters n_;
};

}  // namespace hoist::mqtt
