// ShaftTwin: one shaft hosted by hoist-twind.  A small class that wires the
// shaft's rooms together (ShaftContext, ShaftInputs, ShaftOutputs,
// ShaftHealth, ForecastScheduler); each room does one job.  The rooms, the
// arrows between them and where a new channel, message, job or alarm goes
// are in the one map, docs/architecture.md ("The daemon's rooms").
//
// The Daemon owns the io_context, the LCM instance and the schedule; it
// calls the input handlers from its receive path (subscribed in
// subscribe()) and tick() once per period of the shaft's rate group
// (absolute schedule), all on the one io_context thread.
//
// Real time: after start-up nothing here allocates, takes a lock that another
// thread can hold, or does I/O other than publishing (a sendmsg on the UDP
// socket).  Log lines go to the RtLog ring (hoist/rt/rt_log.hpp).
// tests/service/daemon_no_alloc_test.cpp checks the whole loop with a
// counting allocator.
#pragma once

#include <chrono>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>

#include "forecast_pool.hpp"
#include "forecast_scheduler.hpp"
#include "hoist/bus/udpm_receiver.hpp"
#include "shaft_context.hpp"
#include "offset_keeper.hpp"
#include "preload_keeper.hpp"
#include "shaft_health.hpp"
#include "shaft_inputs.hpp"
#include "shaft_outputs.hpp"
#include "trip_room.hpp"
#include "hoist/bus/udpm_sender.hpp"

namespace hoist::service::inline app {

using bus::InputRouter;
using bus::parseUdpmUrl;
using bus::RawHandler;
using bus::UdpmReceiver;
using bus::UdpmUrl;

/// What one tick of the daemon's schedule may still spend across its
/// shafts (each a count that the shafts take from in shaft order).
struct TickAllowance {
  int starts = 0;           ///< deferred starts ([service] max_starts_per_tick)
  int exact_envelopes = 0;  ///< exact guide-rope envelopes ([service] max_exact_envelopes_per_tick)
};

class ShaftTwin {
 public:
  using Clock = std::chrono::steady_clock;

  /// `label` names the shaft in log lines ("" for a daemon with one shaft).
  /// `lcm` receives (and publishes unless `lcm_out` is given: the
  /// [service] lcm_url_out instance); `instance_id` is this process's random
  /// id, published in HOIST_CAGE and HOIST_HEALTH.
  ShaftTwin(const TwinConfig& cfg, std::string label, ::lcm::LCM& lcm, RtLog& log, TestHooks hooks,
            std::int64_t instance_id = 0, ::lcm::LCM* lcm_out = nullptr);
  ShaftTwin(const ShaftTwin&) = delete;
  ShaftTwin& operator=(const ShaftTwin&) = delete;

  /// Subscribe to the input channels (before the loop starts): through
  /// `router` (the daemon's own udpm receive path, exact names) when given,
  /// else through LCM (escaped, literal names).
  void subscribe(InputRouter* router = nullptr);
  /// With [service] lcm_url_out on another URL: watch our own HOIST_HEALTH
  /// on the output group through `router` (a receive-only socket there), so
  /// that a second publisher is detected there too.
  void watchOwnOutputs(InputRouter* router) { inputs_.watchOwnOutputs(router); }
  /// The daemon's own udpm publisher (udpm_sender.hpp), used instead of
  /// LCM's publish when set (udpm output URLs).
  void setSender(UdpmSender* s) { outputs_.setSender(s); }
  /// [forecast] enabled: this shaft's forecast job (nullptr when off).  The
  /// daemon adds it to its one ForecastPool (wall clock) and passes the pool
  /// here; with --clock input the shaft runs its forecasts itself.  `phase`
  /// in [0, 1): this shaft forecasts at published times (k + phase) / rate
  /// (the shafts of one daemon are staggered).
  ForecastJob* forecastJob() { return forecast_ ? forecast_->job() : nullptr; }
  void setForecastPool(ForecastPool* pool, double phase);
  /// Process-wide count of ignored datagrams, reported in HOIST_HEALTH.
  void setIgnoredCounter(const std::int64_t* n) { health_.setIgnoredCounter(n); }
  /// The loop starts: wall times are measured from `start`; publishes a
  /// first HOIST_HEALTH at once, the next ones `health_phase` s earlier than
  /// a full period later (the shafts of one daemon spread them out).
  void start(Clock::time_point start, double health_phase);
  /// Wall times are measured from `start` from now on (the daemon's schedule
  /// starts after the shafts announced themselves).
  void rebase(Clock::time_point start) { ctx_.clock.start(start); }
  /// The daemon's loop-time split and miss record (miss_record.hpp), and
  /// this shaft's publication phase: with shape_rate (cage_rate) below the
  /// step rate, HOIST_GUIDE_SHAPE (HOIST_CAGE) goes out on the ticks k with
  /// (k + phase) a multiple of the divider, so that the shafts of one
  /// daemon do not all publish their shapes on the same tick.
  void attachLoop(LoopSplit* split, const MissLog* misses, int phase);
  /// One period of the schedule: deadline index k (model time k / rate with
  /// --clock wall), the deadline this tick was scheduled for (lateness is
  /// measured from it), and how many deadlines the schedule skipped just
  /// before k (missed ticks).  `left`: what the tick may still spend across
  /// the schedule's shafts; a pending start (TwinCore::startPending) takes
  /// one start or waits, and each exact guide-rope envelope takes one of
  /// exact_envelopes (TwinCore::tick's envelope_budget).
  void tick(std::int64_t k, Clock::time_point deadline, std::int64_t skipped, TickAllowance& left);
  /// The twin's start waits for the start budget (HOIST_HEALTH.starting).
  bool starting() const { return ctx_.core.startPending(); }
  /// This shaft took part in miss record `seq`, `late_us` late.
  void noteMiss(std::int64_t seq, double late_us) { tick_stats_.noteMiss(seq, late_us); }
  /// The latest tick's lateness [us].
  double lastLateUs() const { return tick_stats_.last_late_us; }
  /// Ticks run, and the tick count / wall time of the latest deferred start (-1: none).
  std::int64_t ticks() const { return tick_stats_.ticks; }
  std::int64_t startTick() const { return tick_stats_.start_tick; }
  double startWall() const { return tick_stats_.start_wall; }
  void publishHealth(bool final_report = false);
  /// The final health line and per-reason rejection counts, in the log.
  void logFinal() const { health_.logFinal(); }
  /// Keep the estimator's learned accelerometer offset in `path` across
  /// restarts (offset_keeper.hpp): applies a kept one now; before start().
  /// Nothing without [estimator] enabled.  `log`: the daemon's logger (the
  /// keeper's writer thread logs through it, not through the loop's RtLog).
  void keepAccelOffset(const std::string& path, std::shared_ptr<spdlog::logger> log);
  /// Write a pending offset and join the keeper's writer.
  void stopOffsetKeeper();
  /// Take operators' preload adoptions (preload_keeper.hpp), kept in `path`
  /// across restarts ("" = not kept); applies a kept one now.  Before
  /// start().  `log`: the daemon's logger (for the worker's lines).
  void keepPreload(const std::string& path, std::shared_ptr<spdlog::logger> log);
  /// Worker (the daemon's keeper thread): build and keep a requested preload,
  /// release a replaced model.  Nothing before keepPreload().
  void servePreload() {
    if (preload_) preload_->serve();
  }
  /// Preload adoptions in use since start (any thread).
  long preloadAdoptions() const { return preload_ ? preload_->adopted() : 0; }
  /// [history] enabled: record every trip (trip_room.hpp); before start().
  /// Throws std::invalid_argument for bad [condition] settings.
  void enableTrips(const TripHistoryConfig& hist);
  /// [history] enabled: the daemon's TripPool serves this shaft's trip room
  /// (before the pool starts).
  void setTripPool(TripPool* pool);
  /// After TripPool::stop(): one log line of the trip room's figures.
  void stopTrips();
  /// Loop: the trip room's newest condition verdict into the alarms
  /// (GUIDE_PRELOAD_LOW, SHAFT_FINGERPRINT); nothing when none is new.
  void applyCondition();
  const TripRoom* trips() const { return trips_.get(); }

  const TwinConfig& config() const { return ctx_.cfg; }
  const bus::Channels& channels() const { return ctx_.ch; }
  const std::string& label() const { return ctx_.label; }
  /// "[label] " for log lines, "" for a daemon with one shaft.
  const std::string& tag() const { return ctx_.tag; }
  /// "label" in the run report: the label, else the channel prefix, else "default".
  std::string reportLabel() const {
    if (!ctx_.label.empty()) return ctx_.label;
    return ctx_.cfg.service.channel_prefix.empty() ? "default" : ctx_.cfg.service.channel_prefix;
  }
  /// Read-only views for the run report and tests, valid while this
  /// ShaftTwin lives; read them on the loop's thread, or after it stopped.
  /// The statistics the rooms keep (the run-only figures: cost split,
  /// whole-run histograms, counters HOIST_HEALTH does not carry):
  ShaftStatsView stats() const { return {tick_stats_, input_stats_, output_stats_, forecast_stats_}; }
  /// The model and its counters (inputs, envelope evaluations):
  const TwinCore& core() const { return ctx_.core; }
  /// The latest HOIST_HEALTH filled (after stop(): the final report's,
  /// filled even if its publish failed):
  const hoist::health_t& lastHealth() const { return outputs_.health(); }

 private:
  ShaftContext ctx_;                             ///< what the rooms share, read-only (declared first: built first)
  // Each room's statistics (shaft_stats.hpp): declared before the rooms,
  // which hold references to them; each slice has one writer.
  TickStats tick_stats_;                         ///< this class's: the tick
  InputStats input_stats_;                       ///< ShaftInputs'
  OutputStats output_stats_;                     ///< ShaftOutputs'
  ForecastStats forecast_stats_;                 ///< ForecastScheduler's (zero without forecasts)
  ShaftPeers peers_;                             ///< the optional rooms below, for the rooms that call them
  LoopSplit* split_ = nullptr;                   ///< the daemon's loop-time split (attachLoop; nullptr: none)
  ::lcm::LCM& in_;                               ///< receives (LCM's path) and, without lcm_out, publishes
  ShaftOutputs outputs_;                         ///< every outgoing message
  std::unique_ptr<ForecastScheduler> forecast_;  ///< look-ahead forecasts (nullptr without [forecast] enabled)
  std::unique_ptr<OffsetKeeper> offsets_;        ///< the kept accelerometer offset (nullptr: not kept)
  std::unique_ptr<PreloadKeeper> preload_;       ///< the adopted guide-rope preload (nullptr: keepPreload not called)
  ShaftInputs inputs_;                           ///< every input channel
  ShaftHealth health_;                           ///< statistics into HOIST_HEALTH, the report's figures
  std::unique_ptr<TripRoom> trips_;              ///< the shaft's memory (nullptr: [history] off)
  static constexpr int kLogCatchup = 0;          ///< log limiter key: limited catch-up
  LogRateLimiter<1> log_limit_{5};               ///< rate limit of the tick's warning lines
  bool fault_injected_ = false;                  ///< TestHooks::inject_fault_at has fired
  bool slow_tick_done_ = false;                  ///< TestHooks::slow_tick_at has fired
  std::int64_t verdict_applied_ = 0;             ///< ConditionState::verdict_trip last applied
  /// A pending start within the tick's budget (model time t of the tick).
  void startWithinBudget(double t, double wall, int& starts_left, int* envelope_budget);
  bool envelope_budget_ = false;  ///< [service] max_exact_envelopes_per_tick applies (wall clock, > 0)
  void slowTickHook(double wall);                ///< TestHooks::slow_tick_at
};

}  // namespace hoist::service::app
