// ShaftTwin: one shaft hosted by hoist-twind -- its configuration, channels
// (prefix + HOIST_*), TwinCore (the model, input validation, alarms), every
// outgoing LCM message with its preallocated encode buffer, and its
// statistics.  The Daemon owns the io_context, the LCM instance and the
// schedule; it calls
//   * onWinder()/onAck() from LCM's dispatch (subscribed in subscribe()),
//   * tick() once per period of the shaft's rate group (absolute schedule),
// all on the one io_context thread.
//
// Real time: after start-up nothing here allocates, takes a lock that another
// thread can hold, or does I/O other than lcm::LCM::publish (a sendmsg on the
// UDP socket, under LCM's own transmit mutex which only this thread takes).
// Log lines go to the RtLog ring (hoist/rt/rt_log.hpp).  tests/service/
// daemon_no_alloc_test.cpp checks the whole loop with a counting allocator.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include <memory>

#include "forecast_pool.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/service/forecast_rules.hpp"
#include "hoist/trip_plan_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/bus/channels.hpp"
#include "hoist/service/config.hpp"
#include "hoist/service/health.hpp"
#include "hoist/service/twin_core.hpp"
#include "hoist/winder_t.hpp"
#include "hoist/rt/rt_log.hpp"
#include "hoist/bus/udpm_receiver.hpp"
#include "udpm_sender.hpp"

namespace hoist::svc {

using rt::RtLog;
using bus::InputRouter;
using bus::parseUdpmUrl;
using bus::RawHandler;
using bus::UdpmReceiver;
using bus::UdpmUrl;

/// Test-only fault injection (hidden command-line options, tests/hardening).
struct TestHooks {
  double inject_fault_at = -1.0;  ///< wall time [s] at which the model state is treated as non-finite once
  int fail_publish_every = 0;     ///< every N-th LCM publish is treated as failed (0 = never)
};

/// Whole-run figures of one shaft (for --report and the final health line).
struct ShaftRunStats {
  std::string label;
  std::int64_t ticks = 0, steps = 0, deadline_misses = 0;
  std::int64_t accepted = 0, rejected = 0, seq_gaps = 0;
  std::int64_t alarm_events = 0, model_faults = 0, publish_failures = 0, nonfinite_blocked = 0;
  std::int64_t forecasts = 0, forecasts_dropped = 0, forecasts_skipped = 0, plans_accepted = 0, plans_rejected = 0;
  const LatencyHistogram* forecast = nullptr;  ///< forecast compute time [us]
  const LatencyHistogram* step = nullptr;  ///< model step time [us]
  const LatencyHistogram* late = nullptr;  ///< tick lateness [us]
  // Cost split, whole run [ns of steady clock] (issue 13): the model
  // (core tick + housekeeping, the envelope included), of which the
  // deflection envelope; publishing (encode + sendmsg of every output); the
  // whole tick() call.
  std::int64_t ns_model = 0, ns_envelope = 0, ns_publish = 0, ns_tick = 0;
  std::int64_t envelope_exact = 0, envelope_bounded = 0;  ///< envelope evaluations
};

class ShaftTwin {
 public:
  using Clock = std::chrono::steady_clock;

  /// `label` names the shaft in log lines ("" for a daemon with one shaft).
  /// `lcm` receives (and publishes unless `lcm_out` is given: the
  /// [service] lcm_url_out instance); `instance_id` is this process's random
  /// id, published in HOIST_CAGE and HOIST_HEALTH.
  ShaftTwin(const TwinConfig& cfg, std::string label, lcm::LCM& lcm, RtLog& log, TestHooks hooks,
            std::int64_t instance_id = 0, lcm::LCM* lcm_out = nullptr);
  ~ShaftTwin();
  ShaftTwin(const ShaftTwin&) = delete;
  ShaftTwin& operator=(const ShaftTwin&) = delete;

  /// Subscribe to the input channels (before the loop starts): through
  /// `router` (the daemon's own udpm receive path, exact names) when given,
  /// else through LCM (escaped, literal names).
  void subscribe(InputRouter* router = nullptr);
  /// With [service] lcm_url_out on another URL: watch our own HOIST_HEALTH
  /// on the output group through `router` (a receive-only socket there), so
  /// that a second publisher is detected there too.
  void watchOwnOutputs(InputRouter* router);
  /// The daemon's own udpm publisher (udpm_sender.hpp), used instead of
  /// LCM's publish when set (udpm output URLs).
  void setSender(UdpmSender* s) { sender_ = s; }
  /// [forecast] enabled: this shaft's forecast job (nullptr when off).  The
  /// daemon adds it to its one ForecastPool (wall clock) and passes the pool
  /// here; with --clock input the shaft runs its forecasts itself.  `phase`
  /// in [0, 1): this shaft forecasts at published times (k + phase) / rate
  /// (the shafts of one daemon are staggered).
  ForecastJob* forecastJob() { return fjob_.get(); }
  void setForecastPool(ForecastPool* pool, double phase);
  /// Process-wide count of ignored datagrams, reported in HOIST_HEALTH.
  void setIgnoredCounter(const std::int64_t* n) { ignored_counter_ = n; }
  /// The loop starts: wall times are measured from `start`; publishes a
  /// first HOIST_HEALTH at once, the next ones `health_phase` s earlier than
  /// a full period later (the shafts of one daemon spread them out).
  void start(Clock::time_point start, double health_phase);
  /// One period of the schedule: deadline index k (model time k / rate with
  /// --clock wall), the deadline this tick was scheduled for (lateness is
  /// measured from it), and how many deadlines the schedule skipped just
  /// before k (missed ticks).
  void tick(std::int64_t k, Clock::time_point deadline, std::int64_t skipped);
  void publishHealth(bool final_report = false);
  /// The final health line and per-reason rejection counts, in the log.
  void logFinal();

  const TwinConfig& config() const { return cfg_; }
  const bus::Channels& channels() const { return ch_; }
  const std::string& label() const { return label_; }
  /// "[label] " for log lines, "" for a daemon with one shaft.
  const std::string& tag() const { return tag_; }
  ShaftRunStats runStats() const;

 private:
  // LCM callbacks: no exception escapes them (a throw is counted as
  // "handler_exception" in HOIST_HEALTH and logged, rate-limited).
  void onWinder(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void onAck(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void onTripPlan(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void handleTripPlan(const lcm::ReceiveBuffer* rbuf);
  void rejectPlan(PlanReject r, const char* detail);
  /// After a model step: at a forecast instant, hand a snapshot over (wall
  /// clock) or forecast now (input clock).
  void maybeForecast(std::int64_t utime);
  /// A result came back: publish forecast_t, feed PREDICTED_* alarms.
  void onForecastResult(const ForecastResult& r);
  void publishForecast(const ForecastResult& r);
  void handleWinder(const lcm::ReceiveBuffer* rbuf);
  void handleAck(const lcm::ReceiveBuffer* rbuf);
  void handlerFailed(const char* what, const char* channel);
  void onOwnHealth(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void logJunk(const std::string& what);
  std::int64_t rssKb() const;
  double wallNow() const;
  // batch: queued on the daemon's UdpmSender (sent at its next flush, in the
  // same tick); only for the tick's cage and shape, whose buffers are not
  // touched again before then.
  void publishCage(std::int64_t utime, bool batch = false);
  void publishShape(std::int64_t utime, bool batch = false);
  void drainAlarmEvents();
  bool publishBytes(const std::string& channel, const std::vector<std::uint8_t>& buf, int len, bool batch = false);
  template <class Msg>
  bool encodeAndPublish(const std::string& channel, const Msg& msg, std::vector<std::uint8_t>& buf,
                        bool batch = false);
  void logReject(RejectReason r, const char* detail);

  TwinConfig cfg_;
  std::string label_;  ///< as given ("" for a daemon with one shaft)
  std::string tag_;    ///< log-line prefix: "[label] " or ""
  lcm::LCM& lcm_;
  lcm::LCM& out_;  ///< publishes (lcm_url_out, or lcm_) unless sender_ is set
  UdpmSender* sender_ = nullptr;
  std::int64_t instance_id_ = 0;
  RtLog& log_;
  TestHooks hooks_;
  bus::Channels ch_;
  TwinCore core_;

  Clock::time_point start_{};
  /// --clock input: wall time spent in synchronous forecasts, not counted as
  /// time passing for this shaft's staleness and health windows (the inputs
  /// wait in the socket meanwhile; they are not late).
  Clock::duration sync_pause_{};
  int cage_div_ = 1, shape_div_ = 1;
  double last_shape_t_ = -1e300;  ///< input clock: model time of the last shape message
  double last_health_wall_ = 0.0;
  std::int64_t ticks_ = 0, deadline_misses_ = 0;
  std::int64_t ns_model_ = 0, ns_publish_ = 0, ns_tick_ = 0;  ///< cost split (ShaftRunStats)

  // statistics
  LatencyHistogram step_hist_, late_hist_;    // this health window
  LatencyHistogram step_total_, late_total_;  // whole run (final report): the windows merged at each health report
  std::int64_t publish_failures_ = 0, nonfinite_blocked_ = 0, alarm_events_ = 0;
  // Extra HOIST_HEALTH reasons after the winder reasons (not in rejected_total,
  // which counts winder inputs): undecodable alarm commands, and exceptions
  // caught in an LCM callback.
  static constexpr int kExtraReasons = 2 + kPlanRejectReasons;
  std::int64_t command_decode_rejects_ = 0, handler_exceptions_ = 0;
  std::int64_t publish_attempts_ = 0;
  bool fault_injected_ = false;
  std::int64_t cage_seq_ = 0, alarm_id_ = 0;
  // Log rate limiter keys: one per RejectReason, then these.
  static constexpr int kLogPublish = kRejectReasons;          ///< publish failures, withheld messages
  static constexpr int kLogJunkCommand = kRejectReasons + 1;  ///< invalid/ineffective/dropped commands
  static constexpr int kLogCatchup = kRejectReasons + 2;      ///< limited catch-up
  static constexpr int kLogHandlerException = kRejectReasons + 3;  ///< exceptions caught in LCM handlers
  static constexpr int kLogPlan = kRejectReasons + 4;  ///< rejected trip plans, unusable plans
  static constexpr int kLogKeys = kRejectReasons + 5;
  LogRateLimiter<kLogKeys> reject_log_{5};
  static constexpr std::size_t kUserMax = 64;  ///< operator names are cut to this (printable) length
  int commands_this_tick_ = 0;
  std::int64_t commands_dropped_ = 0, commands_invalid_ = 0;
  std::string cmd_user_;               ///< user of the command whose events are being drained
  double cmd_requested_shelve_ = 0.0;  ///< its requested shelve duration [s]
  std::int64_t other_id_ = 0;          ///< another publisher's instance id
  double other_seen_wall_ = -1.0;      ///< when it was last seen (< 0: not seen)
  int statm_fd_ = -1;
  const std::int64_t* ignored_counter_ = nullptr;

  // look-ahead forecasts (issue 17)
  std::unique_ptr<ForecastJob> fjob_;
  ForecastPool* pool_ = nullptr;
  double forecast_phase_ = 0.0;
  double next_forecast_t_ = 0.0;      ///< published time of the next forecast instant
  const FastSolver* fast_ = nullptr;  ///< the twin's solver, for saveState
  double slack_threshold_ = 0.0;      ///< PREDICTED_SLACK [N]
  const char* pred_clearance_scenario_ = "";
  const char* pred_slack_scenario_ = "";
  std::int64_t forecasts_ = 0, forecasts_dropped_ = 0, forecasts_skipped_ = 0, forecast_failures_ = 0;
  std::int64_t forecast_seq_ = 0, plan_unusable_ = 0;
  LatencyHistogram forecast_hist_, forecast_total_;  ///< compute time [us]: window, whole run
  // trip plans: the latest accepted one
  bool have_plan_ = false;
  TripPlan plan_;
  std::int64_t plan_seq_ = -1;
  std::int64_t plans_accepted_ = 0;
  std::array<std::int64_t, kPlanRejectReasons> plan_rejects_{};
  MotionProfile plan_scratch_;
  hoist::trip_plan_t plan_in_;

  // preallocated messages and encode buffers
  hoist::winder_t winder_in_;
  hoist::cage_state_t cage_msg_;
  hoist::guide_shape_t shape_msg_;
  hoist::alarm_t alarm_msg_;
  hoist::health_t health_msg_;
  hoist::forecast_t forecast_msg_;
  std::vector<std::uint8_t> cage_buf_, shape_buf_, alarm_buf_, health_buf_, forecast_buf_;
  char text_[256];
};

}  // namespace hoist::svc
