// ShaftInputs: the room of one shaft that receives -- it subscribes to the
// shaft's input channels, decodes and validates every datagram, and acts on
// it: winder samples go to the model (TwinCore), operator alarm commands
// (HOIST_ALARM_ACK) are validated, budgeted and applied, trip plans are
// checked and handed to the ForecastScheduler, and our own HOIST_HEALTH
// seen from another instance raises DUPLICATE_PUBLISHER.
//
// Each input channel is one row of routes_ (channel, handler, name):
// subscribe() registers every row, on the daemon's receive path or on LCM,
// and every handler runs inside one try/catch (a throw is counted as
// "handler_exception" in HOIST_HEALTH and logged, rate-limited).
//
// Files: shaft_inputs.cpp (routes, winder samples, operator commands, trip
// plans, our own outputs from another publisher) and
// shaft_inputs_sensors.cpp (the load estimator's sensors).
//
// Real time: winder samples and trip plans decode into preallocated
// messages (no allocation); operator commands are rare and may allocate
// (their strings), bounded per tick (see handleAck).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "hoist/bus/udpm_receiver.hpp"
#include "hoist/cage_imu_t.hpp"
#include "hoist/service/core/plan_senders.hpp"
#include "hoist/rope_load_t.hpp"
#include "hoist/trip_plan_t.hpp"
#include "hoist/winder_t.hpp"
#include "shaft_context.hpp"
#include "shaft_outputs.hpp"
#include "shaft_stats.hpp"

namespace hoist::service::inline app {

class ForecastScheduler;

class ShaftInputs {
 public:
  /// `in` receives when the daemon has no own receive path; `forecast` is
  /// nullptr without [forecast] enabled (trip plans are then not subscribed).
  /// Writes `stats` (its own) and feeds `core` (samples, commands); hands
  /// work to `out`, `forecast` and the optional rooms in `peers` (read at
  /// each use: ShaftTwin sets them before the loop starts).  Every reference
  /// must outlive this room (all are ShaftTwin's, as this room is).
  ShaftInputs(const ShaftContext& ctx, TwinCore& core, InputStats& stats, const ShaftPeers& peers, ::lcm::LCM& in,
              ShaftOutputs& out, ForecastScheduler* forecast);
  ShaftInputs(const ShaftInputs&) = delete;
  ShaftInputs& operator=(const ShaftInputs&) = delete;

  /// Subscribe to the input channels (before the loop starts): through
  /// `router` (the daemon's own udpm receive path, exact names) when given,
  /// else through LCM (escaped, literal names).  `own_health`: also watch
  /// our own HOIST_HEALTH here (outputs go to the input URL).
  void subscribe(bus::InputRouter* router, bool own_health);
  /// Watch our own HOIST_HEALTH through `router` (the output URL's socket).
  void watchOwnOutputs(bus::InputRouter* router);
  /// Once per tick, at its start: new command and decode budgets.
  void beginTick() {
    commands_this_tick_ = 0;
    decodes_this_tick_ = 0;
    if (reannounce_pending_) serviceReannounce();
  }
  /// Re-announce requests (alarm_ack_t ACTION_REANNOUNCE) are honoured at
  /// most once per this many seconds of wall time; one arriving sooner is
  /// merged into a pending one, honoured when the interval is over (so a
  /// client that asked is never left without an answer).
  static constexpr double kReannounceInterval = 1.0;
  /// Command datagrams decoded per tick at most: this many per second...
  static constexpr double kDecodesPerSecond = 200000.0;
  /// ... but at least this many per tick.
  static constexpr int kMinDecodesPerTick = 256;
  /// Once per tick: the other publisher of our outputs is forgotten after
  /// three health periods without a word.
  void forgetSilentPublisher(double wall);

 private:
  using Handle = void (ShaftInputs::*)(const ::lcm::ReceiveBuffer*);
  /// One input channel: where it comes from and who handles it.
  struct Route {
    ShaftInputs* self = nullptr;       ///< the room
    const std::string* channel = nullptr;  ///< exact channel name (in ctx.ch)
    Handle handle = nullptr;           ///< the handler
    const char* name = "";             ///< for log lines: "HOIST_WINDER", ...
    /// The guarded entry point (LCM's callback signature).
    void onMessage(const ::lcm::ReceiveBuffer* rbuf, const std::string& channel);
  };
  enum RouteId { kWinder, kAck, kTripPlan, kOwnHealth, kOwnAlarm, kCageImu, kRopeLoad, kRoutes };

  void handleWinder(const ::lcm::ReceiveBuffer* rbuf);
  void handleAck(const ::lcm::ReceiveBuffer* rbuf);
  void handleTripPlan(const ::lcm::ReceiveBuffer* rbuf);
  void handleOwnHealth(const ::lcm::ReceiveBuffer* rbuf);
  void handleOwnAlarm(const ::lcm::ReceiveBuffer* rbuf);  // alarm events of another instance on our HOIST_ALARM
  /// Instance `id` (utime `ut` [us]) published on our output `channel`:
  /// unless it is us, raise DUPLICATE_PUBLISHER and log the first message.
  /// `unpublished`: an alarm event with our own id that we never published
  /// (its event id not yet used): a forger who copied the id.
  void otherPublisher(std::int64_t id, std::uint64_t ut, const std::string& channel, bool unpublished = false);
  void handleCageImu(const ::lcm::ReceiveBuffer* rbuf);   // the load estimator's sensors ([estimator] enabled)
  void handleRopeLoad(const ::lcm::ReceiveBuffer* rbuf);
  void rejectSensor(const char* channel, const char* detail);
  template <class Msg>
  bool decodeSensor(const ::lcm::ReceiveBuffer* rbuf, Msg& m, const char* channel);  // checked decode, or reject
  bool sensorSeqNewer(std::int64_t seq, SensorSequence& sq, const char* channel);  // SensorSequence, or reject
  bool sensorTimeOk(SensorVerdict v, std::int64_t utime, const char* channel);     // TwinCore's time verdict, or reject
  void handlerFailed(const char* what, const char* channel);
  void logReject(RejectReason r, const char* detail);
  void rejectPlan(PlanReject r, const char* detail);
  void logJunk(const std::string& what);
  /// A valid calibration command: hand it to the model room, audit it.
  void calibrate(const AlarmCommand& cmd, const std::string& user);
  /// ACTION_ADOPT_PRELOAD: hands the scale to the shaft's PreloadKeeper
  /// (`utime`: when, on the daemon's clock).
  void adoptPreload(const AlarmCommand& cmd, const std::string& user, std::int64_t utime);
  /// A valid re-announce request: honour it now, or merge it into the pending one.
  void requestReannounce(std::optional<AlarmKind> kind, AlarmLevel level, const std::string& user);
  /// Honour the pending re-announce request if the interval allows.
  void serviceReannounce();
  void add(bus::InputRouter* router, Route& r);

  const ShaftContext& ctx_;         ///< the shaft's shared, read-only state
  TwinCore& core_;                  ///< the model: fed the samples and commands
  InputStats& stats_;               ///< this room's statistics
  const ShaftPeers& peers_;         ///< the optional rooms (offset and preload keepers, trip room)
  ::lcm::LCM& in_;                  ///< LCM's receive path (when the daemon has none of its own)
  ShaftOutputs& out_;               ///< publishes what an input causes (cage, shape, alarm events)
  ForecastScheduler* forecast_;     ///< the forecast room (nullptr without forecasts)
  std::array<Route, kRoutes> routes_{};  ///< the input channels and their handlers
  // Log rate limiter keys: one per RejectReason, then these.
  static constexpr int kLogJunkCommand = kRejectReasons;          ///< invalid/ineffective/dropped commands
  static constexpr int kLogHandlerException = kRejectReasons + 1; ///< exceptions caught in handlers
  static constexpr int kLogPlan = kRejectReasons + 2;             ///< rejected trip plans
  static constexpr int kLogSensor = kRejectReasons + 3;           ///< rejected sensor samples
  static constexpr int kLogReannounce = kRejectReasons + 4;       ///< honoured re-announce requests
  static constexpr int kLogKeys = kRejectReasons + 5;             ///< number of keys
  LogRateLimiter<kLogKeys> log_limit_{5};  ///< rate limit of this room's warning lines
  int commands_this_tick_ = 0;      ///< valid commands applied or dropped this tick
  int decodes_this_tick_ = 0;       ///< command datagrams decoded (or dropped undecoded) this tick
  int decode_budget_ = kMinDecodesPerTick;  ///< command datagrams decoded per tick at most
  bool reannounce_pending_ = false; ///< a re-announce request waits for its interval
  std::optional<AlarmKind> reannounce_kind_;  ///< what it asks for (merged requests: everything)
  AlarmLevel reannounce_level_ = AlarmLevel::None;
  double reannounce_wall_ = -1.0;   ///< wall time of the last honoured one (< 0: none yet)
  std::int64_t other_id_ = 0;       ///< another publisher's instance id
  double other_seen_wall_ = -1.0;   ///< when it was last seen (< 0: not seen)
  hoist::winder_t winder_in_;       ///< decode scratch of HOIST_WINDER
  hoist::trip_plan_t plan_in_;      ///< decode scratch of HOIST_TRIP_PLAN (flat: no allocation)
  hoist::cage_imu_t imu_in_;        ///< decode scratch of HOIST_CAGE_IMU (flat)
  hoist::rope_load_t rope_in_;      ///< decode scratch of HOIST_ROPE_LOAD (flat)
  MotionProfile plan_scratch_;      ///< checkPlan's workspace
  PlanSenders plan_senders_;        ///< the trip-plan sequence rule, per sender
  std::int64_t plan_sender_ = 0;    ///< sender of the last accepted plan
  char text_[256];                  ///< the text of a rejection being logged
};

}  // namespace hoist::service::app
