// ShaftOutputs: the room of one shaft that owns every outgoing message --
// preallocated messages and encode buffers, the all-finite check, encoding,
// and publishing through the daemon's UdpmSender or LCM -- for HOIST_CAGE,
// HOIST_GUIDE_SHAPE, HOIST_ALARM, HOIST_HEALTH and HOIST_FORECAST.  What
// goes into HOIST_HEALTH is ShaftHealth's job; it fills health() before
// publishHealth().
//
// Real time: nothing here allocates after construction (the alarm text goes
// into a fixed buffer; the std::string fields of the messages are reserved).
#pragma once

#include <array>

#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "condition_text.hpp"
#include "forecast_pool.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/health_t.hpp"
#include "shaft_context.hpp"
#include "shaft_stats.hpp"
#include "hoist/bus/udpm_sender.hpp"

namespace hoist::service::inline app {

using bus::UdpmSender;

/// The operator command behind alarm events about to be published (their
/// text and alarm_t.user name it).
struct CommandCause {
  std::string_view user;          ///< "" for the twin itself
  double requested_shelve = 0.0;  ///< a shelve's requested duration [s]
};

/// What the alarm events' texts name besides the event: the latest
/// forecast's and the shaft's memory's causes (kept by ShaftOutputs, set
/// by the rooms that find them).
struct AlarmCause {
  const char* predicted_clearance_scenario = "";  ///< PREDICTED_CLEARANCE: the scenario that predicts it (static string)
  const char* predicted_slack_scenario = "";      ///< PREDICTED_SLACK: the scenario that predicts it (static string)
  double slack_threshold = 0.0;                   ///< PREDICTED_SLACK threshold of the latest forecast [N]
  ConditionText preload_text{};           ///< GUIDE_PRELOAD_LOW: the trip room's latest text
  ConditionText fingerprint_text{};       ///< SHAFT_FINGERPRINT: the trip room's latest text
  ConditionText preload_verdict_text{};   ///< MODEL_MISMATCH's trip-end preload test: its sentence
};

class ShaftOutputs {
 public:
  /// HOIST_ALARM.id the next alarm event will carry (every event this
  /// instance published has a smaller one: ShaftInputs tells forged events
  /// with a copied instance id by it).
  std::int64_t nextAlarmId() const { return alarm_id_; }
  /// Publishes through `out` unless setSender() gives the daemon's own
  /// publisher.  Writes `stats` (its own) and, through `core`, the shape
  /// evaluation and the taken alarm events; reads `inputs` (the sensors'
  /// latest sample times).  Every reference must outlive this room (all are
  /// ShaftTwin's, as this room is).
  ShaftOutputs(const ShaftContext& ctx, TwinCore& core, OutputStats& stats, const InputStats& inputs, ::lcm::LCM& out);
  ShaftOutputs(const ShaftOutputs&) = delete;
  ShaftOutputs& operator=(const ShaftOutputs&) = delete;

  /// The daemon's own udpm publisher (udpm_sender.hpp), used instead of
  /// LCM's publish when set (udpm output URLs).
  void setSender(UdpmSender* s) { sender_ = s; }
  /// --clock wall: publish HOIST_CAGE / HOIST_GUIDE_SHAPE on the ticks k
  /// with (k + phase) a multiple of their divider (the daemon staggers its
  /// shafts: shaft i has phase i, so their shapes spread over the divider's
  /// ticks instead of all going out on one).
  void setPhase(int phase) {
    cage_phase_ = phase % cage_div_;
    shape_phase_ = phase % shape_div_;
  }
  /// The LCM instance that publishes (the input one unless lcm_url_out is set).
  const ::lcm::LCM& lcm() const { return out_; }

  /// --clock wall, after the model stepped in tick k: HOIST_CAGE every
  /// cage_rate period and HOIST_GUIDE_SHAPE every shape_rate period, queued
  /// on the sender (sent at the daemon's next flush, in the same tick).
  void publishTick(std::int64_t k, std::int64_t utime);
  /// --clock input, after an input was stepped: HOIST_CAGE, and
  /// HOIST_GUIDE_SHAPE when a shape_rate period of model time has passed.
  void publishStep(std::int64_t utime);
  /// HOIST_CAGE now (e.g. the held state of a rejected input, flagged degraded).
  void publishCage(std::int64_t utime, bool batch = false);
  /// HOIST_ESTIMATE ([estimator] enabled), with every HOIST_CAGE.
  void publishEstimate(std::int64_t utime, bool batch = false);
  /// Publishes and logs the model's pending alarm events, then clears them.
  /// `by`: the operator command that caused them (none: the twin itself).
  void publishAlarmEvents(const CommandCause& by = {});
  /// What the next PREDICTED_* events name: the latest forecast's scenarios
  /// (static strings, "" for none) and its slack threshold [N]
  /// (ForecastScheduler, after each result).
  void setForecastCause(const char* clearance_scenario, const char* slack_scenario, double slack_threshold) {
    cause_.predicted_clearance_scenario = clearance_scenario;
    cause_.predicted_slack_scenario = slack_scenario;
    cause_.slack_threshold = slack_threshold;
  }
  /// What the next GUIDE_PRELOAD_LOW / SHAFT_FINGERPRINT events name: the
  /// trip room's latest texts (ShaftTwin::applyCondition; copies, no allocation).
  void setConditionTexts(const ConditionText& preload, const ConditionText& fingerprint) {
    cause_.preload_text = preload;
    cause_.fingerprint_text = fingerprint;
  }
  /// The last recorded trip's detectability, carried by every HOIST_ESTIMATE
  /// (ShaftTwin::applyCondition).
  void setDetectability(const TripDetectability& d) { detect_ = d; }
  /// What the next MODEL_MISMATCH event of the trip-end preload test names.
  void setPreloadVerdictText(const ConditionText& text) { cause_.preload_verdict_text = text; }
  /// HOIST_FORECAST from a forecast result.
  void publishForecast(const ForecastResult& r);
  /// The health message, for ShaftHealth to fill before publishHealth().
  hoist::health_t& health() { return health_msg_; }
  const hoist::health_t& health() const { return health_msg_; }
  void publishHealth();

 private:
  AlarmCause cause_;  ///< setForecastCause(), setConditionTexts()
  void publishShape(std::int64_t utime, bool batch);
  bool publishBytes(const std::string& channel, const std::vector<std::uint8_t>& buf, int len, bool batch);
  template <class Msg>
  bool encodeAndPublish(const std::string& channel, const Msg& msg, std::vector<std::uint8_t>& buf,
                        bool batch = false);

  const ShaftContext& ctx_;      ///< the shaft's shared, read-only state
  TwinCore& core_;               ///< the model: its outputs, shape and alarm events
  OutputStats& stats_;           ///< this room's statistics
  const InputStats& inputs_;     ///< the inputs' statistics (the sensors' latest sample times)
  TripDetectability detect_;     ///< setDetectability()
  ::lcm::LCM& out_;              ///< publishes (lcm_url_out, or the input instance) unless sender_ is set
  UdpmSender* sender_ = nullptr; ///< the daemon's own publisher, or nullptr
  int cage_div_ = 1;             ///< --clock wall: HOIST_CAGE every cage_div_ ticks
  int shape_div_ = 1;            ///< --clock wall: HOIST_GUIDE_SHAPE every shape_div_ ticks
  int cage_phase_ = 0;           ///< --clock wall: HOIST_CAGE on ticks with (k + cage_phase_) % cage_div_ == 0
  int shape_phase_ = 0;          ///< ... HOIST_GUIDE_SHAPE likewise with shape_div_
  double last_shape_t_ = -1e300; ///< --clock input: model time of the last shape message
  static constexpr int kLogPublish = 0;  ///< log limiter key: publish failures, withheld messages
  LogRateLimiter<1> log_limit_{5};       ///< rate limit of this room's error lines
  std::int64_t cage_seq_ = 0;     ///< HOIST_CAGE.seq of the next message
  std::int64_t alarm_id_ = 0;     ///< HOIST_ALARM.id of the next event
  std::int64_t forecast_seq_ = 0; ///< HOIST_FORECAST.seq of the next message
  hoist::cage_state_t cage_msg_;      ///< preallocated HOIST_CAGE
  hoist::estimate_t estimate_msg_;    ///< preallocated HOIST_ESTIMATE (flat)
  std::vector<std::uint8_t> estimate_buf_;  ///< encode buffer of estimate_msg_
  std::int64_t estimate_seq_ = 0;     ///< HOIST_ESTIMATE.seq of the next message
  std::int64_t gate_seen_ = 0;        ///< EstimateGate events logged so far
  /// Log the alarms' switches between the estimate and the open loop and
  /// the load changes (through the RtLog ring: off the real-time path).
  void logGateEvents();
  hoist::guide_shape_t shape_msg_;    ///< preallocated HOIST_GUIDE_SHAPE (sized to the shape's depths)
  hoist::alarm_t alarm_msg_;          ///< preallocated HOIST_ALARM (strings reserved)
  hoist::health_t health_msg_;        ///< preallocated HOIST_HEALTH (reason names set once)
  hoist::forecast_t forecast_msg_;    ///< preallocated HOIST_FORECAST (scenarios and series sized once)
  std::vector<std::uint8_t> cage_buf_;      ///< encode buffer of cage_msg_
  std::vector<std::uint8_t> shape_buf_;     ///< encode buffer of shape_msg_
  std::vector<std::uint8_t> alarm_buf_;     ///< encode buffer of alarm_msg_
  std::vector<std::uint8_t> health_buf_;    ///< encode buffer of health_msg_
  std::vector<std::uint8_t> forecast_buf_;  ///< encode buffer of forecast_msg_ (empty without forecasts)
  char text_[kConditionTextChars + 112];    ///< the alarm text being published (a ConditionText and its frame)
};

}  // namespace hoist::service::app
