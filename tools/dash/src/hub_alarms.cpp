// The hub's alarm side (Hub's members; docs/dashboard.md "Alarms"): the
// alarms' activations kept across re-announces, the re-announce requests to
// each daemon instance, the clearing of a gone instance's alarms, and the
// operator commands from the clients (validated, bound to the activation
// the page drew, published on LCM).  The rest of the hub is hub.cpp.
#include <cmath>
#include <cstdio>
#include <ctime>
#include <optional>

#include <spdlog/spdlog.h>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/contract/alarm_command.hpp"
#include "hoist/msg/codec.hpp"
#include "hub.hpp"

namespace hoist::dash {

void Hub::requestAlarmStates() { request_states_ = true; }

void Hub::maybeRequestAlarmStates(const std::string& prefix, const Json& health) {
  // Once per daemon instance of a shaft: its first health (a fixed prefix)
  // or its confirmation (a discovered one).  Into the void never (no daemon
  // yet), and a one-shot forged prefix costs no request.
  if (!request_states_) return;
  const std::int64_t instance = health.value("instance_id", std::int64_t{0});
  if (instance == 0) return;
  if (const auto d = disc_.find(prefix); d != disc_.end() && !d->second.confirmed) return;
  auto [it, fresh] = states_asked_.emplace(prefix, instance);
  if (!fresh && it->second == instance) return;
  it->second = instance;
  requestAlarmStates(prefix);
}

bool Hub::fromFollowedInstance(const std::string& prefix, const std::string& suffix, const Json& j) {
  if (!j.contains("instance_id")) return true;  // a type without a sender (trip plans, guide shape)
  const std::int64_t instance = j.value("instance_id", std::int64_t{0});
  const auto it = instance_.find(prefix);
  if (it != instance_.end() ? it->second == instance : suffix != bus::kChannelAlarm) return true;
  count(suffix + "_foreign_instance");
  if (logAllowed())
    spdlog::warn("shaft '{}': dropped {} of daemon instance {}: the dashboard follows instance {}",
                 msg::terminalSafe(shaftName(prefix), 64), suffix, instance,
                 it == instance_.end() ? std::string("(none heard yet)") : std::to_string(it->second));
  return false;
}

bool Hub::noteInstance(const std::string& prefix, const Json& health) {
  const std::int64_t instance = health.value("instance_id", std::int64_t{0});
  const std::uint64_t now = clock_();
  const auto followed = instance_.find(prefix);
  if (followed != instance_.end() && followed->second != instance &&
      static_cast<double>(now - std::min(now, instance_last_ns_[prefix])) * 1e-9 <= opt_.health_gap_s) {
    // The followed daemon still talks: a second instance under its prefix
    // costs itself, never the shaft's alarms (issue 33).
    count("health_impostor");
    if (logAllowed())
      spdlog::warn("shaft '{}': health of another daemon instance {} while instance {} is alive: an impostor, dropped",
                   msg::terminalSafe(shaftName(prefix), 64), instance, followed->second);
    return false;
  }
  if (instance == 0) return true;
  instance_last_ns_[prefix] = now;
  auto [it, fresh] = instance_.emplace(prefix, instance);
  if (fresh || it->second == instance) return true;
  const std::int64_t old = it->second;
  it->second = instance;
  // The new daemon's start on its own clock (the alarms' utimes are on it too).
  const double uptime = health.value("uptime", 0.0);
  const std::int64_t start = health.value("utime", std::int64_t{0}) -
                             static_cast<std::int64_t>(std::isfinite(uptime) && uptime > 0.0 ? uptime * 1e6 : 0.0);
  count("daemon_restarts");
  Channel* ch = channelFor(prefix + std::string(bus::kChannelAlarm));
  std::size_t cleared = 0;
  if (ch != nullptr) {
    for (auto a = ch->table.begin(); a != ch->table.end();) {
      Json j = Json::parse(*a->second, nullptr, false);
      if (!j.is_object() || j.value("utime", std::int64_t{0}) >= start) {
        ++a;
        continue;
      }
      // Inactive, acknowledged, not shelved: it leaves every alarm list.
      j["event_type"] = 2;  // EVENT_CLEAR
      j["active"] = j["shelved"] = j["latched"] = false;
      j["acked"] = true;
      j["shelved_for"] = 0.0;
      j["user"] = "hoist-dash";
      j["message"] = "cleared by hoist-dash: the daemon restarted (instance " + std::to_string(old) + " -> " +
                     std::to_string(instance) + ")";
      j["dash_restart_cleared"] = true;
      alarm_ids_.erase(prefix + "\n" + a->first);
      broadcast(*ch, std::make_shared<const std::string>(j.dump()));
      a = ch->table.erase(a);
      ++cleared;
    }
  }
  count("alarms_cleared_restart", cleared);
  spdlog::info("shaft '{}': new daemon instance {} (was {}): {} alarm state(s) from before its start cleared",
               shaftName(prefix), instance, old, cleared);
  return true;
}

void Hub::requestAlarmStates(const std::string& prefix) {
  // alarm_ack_t ACTION_REANNOUNCE changes nothing in the daemon (which
  // honours one a second): its answer is every alarm's current state, so an
  // alarm raised before this dashboard started, or before the shaft was
  // discovered, is in the alarm list at once.  Sent also with --read-only.
  alarm_ack_t m{};
  m.utime = static_cast<std::int64_t>(clock_() / 1000);
  m.kind = "*";
  m.action = alarm_ack_t::ACTION_REANNOUNCE;
  m.user = "hoist-dash";
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(m.getEncodedSize()));
  if (m.encode(buf.data(), 0, static_cast<int>(buf.size())) >= 0 && publish_(prefix + std::string(bus::kChannelAlarmAck), buf))
    count("alarm_state_requests");
  else
    count("alarm_state_requests_failed");
}

void Hub::annotateAlarm(const std::string& prefix, Json& j) {
  const std::string key = prefix + "\n" + j.value("kind", std::string()) + "/" + std::to_string(j.value("level", 0));
  const int event = j.value("event_type", 0);
  const std::int64_t utime = j.value("utime", std::int64_t{0});
  auto it = alarm_ids_.find(key);
  if (it == alarm_ids_.end()) {
    if (alarm_ids_.size() >= 64 * std::max<std::size_t>(opt_.max_prefixes, 1)) {
      count("alarm_identities_full");
      return;
    }
    it = alarm_ids_.emplace(key, AlarmIdentity{utime, 0, j.value("t", 0.0), event == 1}).first;
  } else if (event == 1) {  // EVENT_RAISE: a new activation
    it->second = AlarmIdentity{utime, 0, j.value("t", 0.0), true};
  }
  if (event == 6) it->second.reannounce_utime = utime;  // EVENT_REANNOUNCE
  AlarmIdentity& a = it->second;
  j["dash_activation_utime"] = a.activation_utime;
  j["dash_activation_t"] = a.activation_t;
  j["dash_activation_known"] = a.known;
  j["dash_reannounce_utime"] = a.reannounce_utime;
  // Back to normal (inactive, acknowledged, not shelved): the next raise is a new activation.
  if (!j.value("active", false) && j.value("acked", false) && !j.value("shelved", false)) alarm_ids_.erase(it);
}

namespace {
// "HH:MM:SS UTC" of a utime (us since the epoch), for messages to operators.
std::string utcClock(std::int64_t utime) {
  const std::time_t t = static_cast<std::time_t>(utime / 1'000'000);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%02d:%02d:%02d UTC", tm.tm_hour, tm.tm_min, tm.tm_sec);
  return buf;
}
}  // namespace

void Hub::handleClientMessage(Client& c, std::uint32_t chan, std::string_view payload) {
  if (opt_.read_only) {
    count("commands_rejected_read_only");
    status(c, 2, "rejected: hoist-dash runs --read-only; operator commands are disabled");
    return;
  }
  const auto it = c.published_.find(chan);
  if (it == c.published_.end()) {
    count("commands_rejected_unadvertised");
    status(c, 2, "rejected: client channel " + std::to_string(chan) + " was not advertised");
    return;
  }
  // The client's command rate, before anything is parsed (clock_ is wall
  // time: a step back counts as no time passed).
  if (!c.commands_) c.commands_.emplace(opt_.command_rate, opt_.command_burst);
  if (!c.commands_->take(static_cast<double>(clock_()) * 1e-9)) {
    count("commands_rejected_rate");
    char text[160];
    std::snprintf(text, sizeof text,
                  "rejected: more than %g commands a second (bursts of %g) from this client; nothing was sent -- "
                  "wait a moment and send again",
                  opt_.command_rate, opt_.command_burst);
    status(c, 2, text);
    return;
  }
  Json j = Json::parse(payload.begin(), payload.end(), nullptr, false);
  alarm_ack_t ack{};
  std::string err;
  if (j.is_discarded() || !j.is_object()) {
    count("commands_rejected_invalid");
    status(c, 2, "rejected command: payload is not a JSON object");
    return;
  }
  // Optional fields (as in hoist-mqtt): utime is the server's anyway, and
  // shelve_duration matters only for SHELVE (where validation requires it).
  if (!j.contains("utime")) j["utime"] = 0;
  if (!j.contains("shelve_duration")) j["shelve_duration"] = 0.0;
  // The calibration's fields (alarm_ack_t.ACTION_CALIBRATE only): absent in
  // every alarm command.
  for (const char* k : {"known_fa", "known_b", "calibrate_duration", "preload_scale"})
    if (!j.contains(k)) j[k] = 0.0;
  // The alarm the page drew (its activation): a command for an alarm that
  // was cleared and raised again since, or is gone, is refused.
  std::optional<std::int64_t> expect_activation;
  if (const auto ea = j.find("activation_utime"); ea != j.end()) {
    if (!ea->is_number_integer()) {
      count("commands_rejected_invalid");
      status(c, 2, "rejected command: activation_utime must be an integer (us since the epoch)");
      return;
    }
    expect_activation = ea->get<std::int64_t>();
    j.erase("activation_utime");
  }
  bool parsed = false;
  try {
    parsed = msg::fromJson(j, ack, err);
  } catch (const std::exception& e) {
    err = e.what();
  }
  if (!parsed) {
    count("commands_rejected_invalid");
    status(c, 2, "rejected command: " + err);
    return;
  }
  if (ack.action == alarm_ack_t::ACTION_CALIBRATE) return sendCalibration(c, it->second, ack, expect_activation.has_value());
  if (const std::string why = validateAckFields(ack.kind, ack.level, ack.action, ack.shelve_duration, ack.user);
      !why.empty()) {
    count("commands_rejected_invalid");
    status(c, 2, "rejected command: " + why);
    return;
  }
  static const char* level_names[] = {"(both levels)", "WARNING", "CRITICAL"};
  const std::string alarm_name = ack.kind + " " + level_names[ack.level];
  std::string since;
  if (expect_activation) {
    const std::string prefix = it->second.substr(0, it->second.size() - std::string(bus::kChannelAlarmAck).size());
    const auto id = alarm_ids_.find(prefix + "\n" + ack.kind + "/" + std::to_string(ack.level));
    if (ack.level == 0 || ack.kind == "*" || ack.kind.empty() || id == alarm_ids_.end() ||
        id->second.activation_utime != *expect_activation) {
      count("commands_refused_stale");
      const std::string now = id == alarm_ids_.end() || ack.level == 0
                                  ? "it is no longer in the list"
                                  : "it was raised again at " + utcClock(id->second.activation_utime);
      status(c, 2, "refused: " + alarm_name + " changed since your page drew it (" + now +
                       "); nothing was sent -- check the alarm list and try again");
      return;
    }
    since = " (active since " + utcClock(*expect_activation) + ")";
  }
  ack.utime = static_cast<std::int64_t>(clock_() / 1000);  // the command's time is the server's
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(ack.getEncodedSize()));
  if (ack.encode(buf.data(), 0, static_cast<int>(buf.size())) < 0 || !publish_(it->second, buf)) {
    count("commands_publish_failed");
    status(c, 2, "command not sent: LCM publish failed");
    return;
  }
  count("commands_published");
  static const char* actions[] = {"", "acknowledge", "shelve", "unshelve"};
  status(c, 0, std::string("sent ") + actions[ack.action] + " " + alarm_name + since + " by " + ack.user + " on " +
                   it->second);
}

void Hub::sendCalibration(Client& c, const std::string& channel, alarm_ack_t& ack, bool names_an_alarm) {
  // The load estimator's live calibration (docs/service.md "The live
  // calibration command"): the daemon's own rule (hoist::contract, the
  // 8-argument form), the user's as for the alarm commands.
  contract::AlarmCommand cmd;
  std::string why;
  if (names_an_alarm) why = "a calibration names no alarm (no activation_utime)";
  else if (contract::validateAlarmCommand(ack.kind, ack.level, ack.action, ack.shelve_duration, ack.known_fa,
                                          ack.known_b, ack.calibrate_duration, cmd) != contract::CommandError::None)
    why = contract::kCalibrationRule;
  else
    why = validateCommandUser(ack.user);
  if (!why.empty()) {
    count("commands_rejected_invalid");
    status(c, 2, "rejected command: " + why);
    return;
  }
  ack.kind = "";
  ack.level = 0;
  ack.utime = static_cast<std::int64_t>(clock_() / 1000);  // the command's time is the server's
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(ack.getEncodedSize()));
  if (ack.encode(buf.data(), 0, static_cast<int>(buf.size())) < 0 || !publish_(channel, buf)) {
    count("commands_publish_failed");
    status(c, 2, "command not sent: LCM publish failed");
    return;
  }
  count("commands_published");
  char text[200];
  std::snprintf(text, sizeof text, "sent calibrate: the load is known, Fa = %g N at b = %g m for %g s, by ",
                ack.known_fa, ack.known_b, ack.calibrate_duration);
  status(c, 0, text + ack.user + " on " + channel);
}

}  // namespace hoist::dash
