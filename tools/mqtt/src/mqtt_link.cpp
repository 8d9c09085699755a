// The bridge's MQTT link: see mqtt_link.hpp.
#include "mqtt_link.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "hoist/mqtt/command.hpp"
#include "hoist/mqtt/sparkplug.hpp"

namespace hoist::mqtt {

MqttLink::MqttLink(const BridgeConfig& cfg, const std::string& password, const std::string& client_id,
                   const std::string& status_topic, Events& events, SparkplugHooks sp, ReplayCheck replay_check,
                   LogBudget& log)
    : cfg_(cfg),
      broker_(parseBrokerUrl(cfg.url)),
      client_id_(client_id),
      status_topic_(status_topic),
      events_(events),
      sp_(std::move(sp)),
      sparkplug_(static_cast<bool>(sp_.next_will)),
      replay_check_(std::move(replay_check)),
      log_(log),
      outbox_(static_cast<std::size_t>(cfg.max_messages), static_cast<std::size_t>(cfg.max_alarm_events)) {
  mosq_ = mosquitto_new(client_id_.c_str(), /*clean_session=*/true, this);
  if (!mosq_) throw std::runtime_error("mosquitto_new failed: " + std::string(std::strerror(errno)));
  mosquitto_int_option(mosq_, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V311);
  if (!sparkplug_) {  // Sparkplug: the will (NDEATH) is set before each connection
    const std::string will = nlohmann::json{{"online", false},
                                            {"client_id", client_id_},
                                            {"reason", "connection lost (last will)"}}
                                 .dump();
    check(mosquitto_will_set(mosq_, status_topic_.c_str(), static_cast<int>(will.size()), will.data(), 1, true),
          "will");
  }
  if (!cfg_.username.empty())
    check(mosquitto_username_pw_set(mosq_, cfg_.username.c_str(), password.empty() ? nullptr : password.c_str()),
          "username/password");
  if (cfg_.wantsTls()) {
    check(mosquitto_tls_set(mosq_, cfg_.ca_file.empty() ? nullptr : cfg_.ca_file.c_str(),
                            cfg_.ca_path.empty() ? nullptr : cfg_.ca_path.c_str(),
                            cfg_.cert_file.empty() ? nullptr : cfg_.cert_file.c_str(),
                            cfg_.key_file.empty() ? nullptr : cfg_.key_file.c_str(), nullptr),
          "TLS files (tls.ca_file, tls.cert_file, tls.key_file)");
    check(mosquitto_tls_opts_set(mosq_, 1, cfg_.tls_version.empty() ? nullptr : cfg_.tls_version.c_str(), nullptr),
          "tls.version");
    if (cfg_.tls_insecure) check(mosquitto_tls_insecure_set(mosq_, true), "tls.insecure");
  }
  mosquitto_connect_callback_set(mosq_, [](struct mosquitto*, void* obj, int rc) {
    auto* self = static_cast<MqttLink*>(obj);
    self->cb_connack_ = true;
    self->cb_connack_rc_ = rc;
  });
  mosquitto_disconnect_callback_set(mosq_, [](struct mosquitto*, void* obj, int rc) {
    auto* self = static_cast<MqttLink*>(obj);
    self->cb_disconnected_ = true;
    self->cb_disconnect_rc_ = rc;
  });
  mosquitto_message_callback_set(mosq_, [](struct mosquitto*, void* obj, const struct mosquitto_message* m) {
    static_cast<MqttLink*>(obj)->events_.message(m);
  });
  mosquitto_publish_callback_set(mosq_, [](struct mosquitto*, void* obj, int mid) {
    static_cast<MqttLink*>(obj)->onAcknowledged(mid);
  });
  delay_ = cfg_.reconnect_min;
  if (!cfg_.journal_dir.empty()) openJournal();
}

MqttLink::~MqttLink() {
  if (mosq_) mosquitto_destroy(mosq_);
}

void MqttLink::check(int rc, const char* what) {
  if (rc != MOSQ_ERR_SUCCESS)
    throw std::runtime_error(std::string("libmosquitto refused ") + what + ": " + mosquitto_strerror(rc));
}

void MqttLink::openJournal() {
  journal_ = std::make_unique<Journal>();
  journal_report_ = journal_->open(cfg_.journal_dir, {cfg_.journal_max_bytes, cfg_.fsync_interval});
  spdlog::info("store-and-forward journal {}: {}{} messages to replay ({} bytes), max_bytes {}, fsync every {} s",
               journal_report_.path, journal_report_.created ? "new; " : "", journal_report_.recovered,
               journal_report_.recovered_bytes, cfg_.journal_max_bytes, cfg_.fsync_interval);
  if (!journal_report_.problem.empty())
    spdlog::error("store-and-forward journal {}: {}; {} bytes from there on skipped (the messages before it are "
                  "replayed; see journal.corrupt_bytes in the bridge's health)",
                  journal_report_.path, journal_report_.problem, journal_report_.skipped_bytes);
}

std::string MqttLink::brokerText() const {
  return std::string(broker_.tls ? "mqtts://" : "mqtt://") + broker_.host + ":" + std::to_string(broker_.port);
}

const char* MqttLink::stateText() const {
  return conn_ == Conn::Connected ? "connected" : conn_ == Conn::Connecting ? "connecting" : "disconnected";
}

// ---- connection ----------------------------------------------------------------

void MqttLink::tick(Clock::time_point now) {
  if (conn_ == Conn::Disconnected && now >= next_attempt_) tryConnect();
  if (conn_ == Conn::Connecting && now - connecting_since_ > std::chrono::duration<double>(cfg_.connect_timeout))
    failed("no answer (CONNACK) within " + fmt::format("{}", cfg_.connect_timeout) + " s");
}

int MqttLink::socket() const { return conn_ != Conn::Disconnected ? mosquitto_socket(mosq_) : -1; }

void MqttLink::tryConnect() {
  if (!failing_ && n_.connects == 0 && n_.connect_failures == 0)
    spdlog::info("connecting to the broker at {} as '{}'{}", brokerText(), client_id_, cfg_.wantsTls() ? " (TLS)" : "");
  if (sparkplug_) {  // NDEATH with the next bdSeq is this connection's will
    const OutMsg will = sp_.next_will();
    check(mosquitto_will_set(mosq_, will.topic.c_str(), static_cast<int>(will.payload.size()), will.payload.data(),
                             will.qos, will.retain),
          "will (NDEATH)");
  }
  errno = 0;
  const int rc = mosquitto_connect_async(mosq_, broker_.host.c_str(), broker_.port, cfg_.keepalive);
  if (rc == MOSQ_ERR_SUCCESS) {
    conn_ = Conn::Connecting;
    connecting_since_ = Clock::now();
    return;
  }
  failed(rc == MOSQ_ERR_ERRNO ? std::string(std::strerror(errno)) : std::string(mosquitto_strerror(rc)));
}

void MqttLink::failed(const std::string& why) {
  ++n_.connect_failures;
  last_error_ = why;
  conn_ = Conn::Disconnected;
  if (!failing_)
    spdlog::warn("cannot connect to the broker at {}: {}; retrying with backoff up to {} s "
                 "(logged again when the connection state changes)",
                 brokerText(), why, cfg_.reconnect_max);
  failing_ = true;
  next_attempt_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(delay_));
  delay_ = std::min(delay_ * 2.0, cfg_.reconnect_max);
}

void MqttLink::lost(const std::string& why) {
  if (conn_ != Conn::Connected) return;
  ++n_.disconnects;
  last_error_ = why;
  conn_ = Conn::Disconnected;
  session_ = false;
  subscribed_.clear();
  if (journal_)
    spdlog::warn("connection to the broker at {} lost: {}; reconnecting with backoff up to {} s, storing in the "
                 "journal {} (at most {} bytes)",
                 brokerText(), why, cfg_.reconnect_max, journal_->path(), cfg_.journal_max_bytes);
  else
    spdlog::warn("connection to the broker at {} lost: {}; reconnecting with backoff up to {} s, buffering at most "
                 "{} messages and {} alarm transitions",
                 brokerText(), why, cfg_.reconnect_max, cfg_.max_messages, cfg_.max_alarm_events);
  failing_ = true;  // further failed attempts are the same state
  delay_ = cfg_.reconnect_min;
  next_attempt_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(delay_));
  delay_ = std::min(delay_ * 2.0, cfg_.reconnect_max);
}

void MqttLink::reconnectNow() {
  cb_disconnected_ = false;  // our own disconnect: not a failure of the next attempt
  next_attempt_ = Clock::now();
}

void MqttLink::onConnected() {
  conn_ = Conn::Connected;
  ++n_.connects;
  failing_ = false;
  last_error_.clear();
  delay_ = cfg_.reconnect_min;
  connected_since_utime_ = hoist::bus::wallUtime();
  spdlog::info("connected to the broker at {} as '{}'{}", brokerText(), client_id_,
               outbox_.empty() ? std::string() : fmt::format("; sending {} buffered messages", outbox_.size()));
  events_.connected();
}

void MqttLink::loop() {
  if (conn_ == Conn::Disconnected) return;
  const int rc = mosquitto_loop(mosq_, 0, 1);
  if (cb_connack_) {
    cb_connack_ = false;
    if (cb_connack_rc_ == 0) onConnected();
    else failed(std::string("refused by the broker: ") + mosquitto_connack_string(cb_connack_rc_));
  }
  if (cb_disconnected_) {
    cb_disconnected_ = false;
    const std::string why = cb_disconnect_rc_ == 0 ? "disconnected" : std::string(mosquitto_strerror(cb_disconnect_rc_));
    if (conn_ == Conn::Connected) lost(why);
    else if (conn_ == Conn::Connecting) failed(why);
  }
  if (rc != MOSQ_ERR_SUCCESS) {
    const std::string why = rc == MOSQ_ERR_ERRNO ? std::string(std::strerror(errno)) : mosquitto_strerror(rc);
    if (conn_ == Conn::Connected) lost(why);
    else if (conn_ == Conn::Connecting) failed(why);
  }
}

void MqttLink::subscribe(const std::string& topic) {
  if (subscribed_.count(topic)) return;
  const int rc = mosquitto_subscribe(mosq_, nullptr, topic.c_str(), 1);
  if (rc == MOSQ_ERR_SUCCESS) subscribed_.insert(topic);
  else spdlog::warn("cannot subscribe to {}: {}", topic, mosquitto_strerror(rc));
}

void MqttLink::unsubscribe(const std::string& topic) {
  if (conn_ != Conn::Connected || !subscribed_.count(topic)) return;
  mosquitto_unsubscribe(mosq_, nullptr, topic.c_str());
  subscribed_.erase(topic);
}

void MqttLink::drainAndDisconnect(int ms, bool acks) {
  const auto end = Clock::now() + std::chrono::milliseconds(ms);
  while (Clock::now() < end && (mosquitto_want_write(mosq_) || (acks && !inflight_.empty())) &&
         mosquitto_loop(mosq_, 10, 1) == MOSQ_ERR_SUCCESS) {
  }
  mosquitto_disconnect(mosq_);
}

void MqttLink::finalLoop() { mosquitto_loop(mosq_, 10, 1); }

// ---- the way out ------------------------------------------------------------------

void MqttLink::openSession(Clock::time_point births_at) {
  births_at_ = births_at;
  session_ = true;
}

void MqttLink::publish(OutMsg m) {
  if (journal_) {
    // Store-and-forward needs the broker's acknowledgement to know what
    // arrived: JSON messages go at QoS 1 (Sparkplug keeps its own QoS).
    if (!m.sparkplug && m.qos < 1) m.qos = 1;
    if (liveReady() && journal_->empty() && outbox_.empty() && !mosquitto_want_write(mosq_) &&
        inflight_.size() < kMaxInflight && sendOne(m, false))
      return;
    return store(std::move(m));
  }
  if (liveReady() && outbox_.empty() && !mosquitto_want_write(mosq_)) {
    if (sendOne(m, false)) return;
  }
  outbox_.push(std::move(m));
}

void MqttLink::store(OutMsg m) {
  if (m.queued == Clock::time_point{}) m.queued = Clock::now();
  if (journal_->append(m)) {
    if (m.cls == MsgClass::Alarm && m.retain) journaled_alarm_topics_.insert(m.topic);
    return;
  }
  if (n_.journal_fallback++ == 0)
    spdlog::error("store-and-forward journal: cannot store a message ({}); buffering in memory (counted: "
                  "journal.fallback)",
                  journal_->lastError().empty() ? "larger than a record may be" : journal_->lastError());
  outbox_.push(std::move(m));
}

void MqttLink::flushJournal() {
  while (journal_ && !journal_->empty() && liveReady() && !mosquitto_want_write(mosq_) &&
         inflight_.size() < kMaxInflight) {
    auto m = journal_->peek();
    if (!m) {  // unreadable now: counted by the journal, skipped
      journal_->pop();
      continue;
    }
    if (std::string why = replay_check_ ? replay_check_(*m) : ""; !why.empty()) {
      ++n_.journal_refused;
      journal_->pop();
      std::int64_t suppressed = 0;
      if (log_.allow(LogBudget::kLcm, Clock::now(), suppressed))
        spdlog::error("store-and-forward journal {}: a record for {} (retain {}) not replayed: {}; {} refused so far "
                      "(journal.replay_refused) [{} similar lines suppressed]",
                      journal_->path(), printable(m->topic, 120), m->retain ? "true" : "false", why,
                      n_.journal_refused, suppressed);
      continue;
    }
    if (!sendOne(*m, /*historical=*/true)) return;
    journal_->pop();
    ++n_.journal_replayed;
  }
}

bool MqttLink::sendOne(const OutMsg& m, bool historical) {
  std::string stamped;
  if (m.sparkplug) stamped = sparkplug::stamp(m.payload, sp_.next_seq ? sp_.next_seq() : 0, historical);
  const std::string& payload = m.sparkplug ? stamped : m.payload;
  int mid = 0;
  const int rc = mosquitto_publish(mosq_, &mid, m.topic.c_str(), static_cast<int>(payload.size()), payload.data(),
                                   m.qos, m.retain);
  if (rc == MOSQ_ERR_SUCCESS) {
    ++n_.published;
    if (journal_ && m.qos > 0 && m.topic != status_topic_) inflight_.push_back({mid, m});
    return true;
  }
  ++n_.publish_errors;
  if (rc == MOSQ_ERR_NO_CONN || rc == MOSQ_ERR_CONN_LOST) lost(std::string("publish: ") + mosquitto_strerror(rc));
  return false;
}

void MqttLink::sendRaw(const std::string& topic, const void* payload, int len, int qos, bool retain) {
  mosquitto_publish(mosq_, nullptr, topic.c_str(), len, payload, qos, retain);
}

void MqttLink::flushOutbox() {
  const auto now = Clock::now();
  while (liveReady() && !outbox_.empty() && !mosquitto_want_write(mosq_)) {
    const OutMsg& m = outbox_.front();
    if (m.sparkplug) {  // queued before this session's births: history
      if (!sendOne(m, m.queued < births_at_)) return;
      outbox_.pop();
      continue;
    }
    if (m.cls == MsgClass::Cage && seconds(now - m.queued) > cfg_.stale_after) {
      if (cfg_.drop_stale) {
        ++n_.stale_dropped;
        outbox_.pop();
        continue;
      }
      OutMsg marked = m;
      if (!marked.payload.empty() && marked.payload.back() == '}') {
        marked.payload.pop_back();
        marked.payload += fmt::format(",\"stale\":true,\"stale_age\":{:.3f}}}", seconds(now - m.queued));
      }
      if (!sendOne(marked, false)) return;
      ++n_.stale_marked;
      outbox_.pop();
      continue;
    }
    if (!sendOne(m, false)) return;
    outbox_.pop();
  }
}

void MqttLink::onAcknowledged(int mid) {
  for (auto it = inflight_.begin(); it != inflight_.end(); ++it)
    if (it->mid == mid) {
      inflight_.erase(it);
      return;
    }
}

bool MqttLink::takeJournalAlarmLoss() {
  if (!journal_) return false;
  const bool lost_alarms = journal_->droppedAlarm() != journal_alarm_drops_seen_;
  journal_alarm_drops_seen_ = journal_->droppedAlarm();
  return lost_alarms;
}

void MqttLink::closeJournal() {
  if (!journal_) return;
  // What the broker has not acknowledged goes back to the journal's front
  // (it is older than everything in it): sent again after a restart.
  std::vector<OutMsg> unacked;
  for (auto& f : inflight_) unacked.push_back(std::move(f.m));
  inflight_.clear();
  if (!unacked.empty()) {
    if (journal_->prepend(unacked)) n_.journal_prepended += unacked.size();
    else
      spdlog::error("store-and-forward journal: {} unacknowledged messages lost: {}", unacked.size(),
                    journal_->lastError());
  }
  spdlog::info("store-and-forward journal: {} messages kept for the next start", journal_->size());
  journal_->close();
}

}  // namespace hoist::mqtt
