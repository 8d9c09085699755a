// hoist-twind's event loop: one Boost.Asio io_context, on one thread, that owns
//   * the LCM socket (::lcm::LCM::getFileno() watched by a stream_descriptor,
//     drained with handleTimeout(0): no polling, no extra thread of ours);
//   * one steady_timer per distinct step rate among the hosted shafts, each on
//     an absolute schedule deadline_k = start + k * period (a tick that starts
//     more than one period late is a deadline miss and the schedule skips the
//     missed periods: it never bunches up ticks to catch up);
//   * a signal_set for SIGINT/SIGTERM/SIGQUIT (clean stop, final health
//     report) and SIGHUP/SIGUSR1/SIGUSR2 (logged, never fatal: SIGHUP is a
//     documented no-op -- the log goes to stderr/the journal, nothing to
//     reopen --, SIGUSR1 publishes a health report at once); SIGPIPE,
//     SIGTTOU and SIGTTIN are ignored (main.cpp), so a dead log reader or a
//     closed stderr never stops the daemon (docs/service.md, Signals).
// It hosts one or more shafts (ShaftTwin: config, channels, model, alarms);
// all the math is in TwinCore (hoist_twin); this file only moves bytes and
// keeps time.  Rooms of their own that the Daemon owns: the miss record's
// writer (MissRecorder, miss_recorder.hpp), the systemd watchdog (Watchdog,
// watchdog.hpp) and the output-URL watch (OutputWatch, output_watch.hpp);
// the map is docs/architecture.md.
//
// Real time: every outgoing message and its encode buffer are allocated at
// start-up; log lines from the loop go through RtLog's preallocated ring to a
// writer thread.  Optional mlockall / SCHED_FIFO / CPU affinity for the loop
// thread (realtime.hpp) are applied in start() and reported.
#pragma once

#include <utility>  // before Asio: Boost 1.74 awaitable.hpp uses std::exchange

#include <atomic>
#include <boost/asio.hpp>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <spdlog/spdlog.h>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "forecast_pool.hpp"
#include "miss_recorder.hpp"
#include "output_watch.hpp"
#include "hoist/service/core/config.hpp"
#include "hoist/service/cfg/history_config.hpp"
#include "hoist/rt/realtime.hpp"
#include "hoist/rt/rt_log.hpp"
#include "shaft_twin.hpp"
#include "hoist/bus/subscriber.hpp"
#include "hoist/bus/udpm_sender.hpp"
#include "keeper_worker.hpp"
#include "watchdog.hpp"

namespace hoist::service::inline app {

using rt::applyRealtime;
using rt::parseCpuList;
using rt::RealtimeOutcome;
using rt::RealtimeRequest;

struct DaemonOptions {
  std::vector<TwinConfig> shafts;   ///< effective configuration of each shaft (command line applied)
  std::vector<std::string> labels;  ///< log-line label per shaft ("" when there is one shaft)
  /// [history] + [condition] per shaft (missing or disabled: no trip room).
  std::vector<TripHistoryConfig> history;
  std::string lcm_url;              ///< resolved URL ("" = LCM default)
  std::string lcm_url_out;          ///< outputs go here ("" = lcm_url)
  double duration = 0.0;            ///< stop after this many seconds (0 = run until signalled)
  RealtimeRequest realtime;         ///< optional mlockall / SCHED_FIFO / affinity
  std::string report_path;          ///< write the run report (JSON) here at stop ("" = none)
  /// The daemon's state directory (--state-dir, else systemd's
  /// $STATE_DIRECTORY): each shaft's learned accelerometer offset is kept
  /// there (offset_keeper.hpp; "" = not kept).
  std::string state_dir;
  std::string command_line;         ///< for the report
  TestHooks hooks;                  ///< test-only fault injection
  double test_stall_at = -1.0;      ///< test only: at this many seconds the loop thread hangs for good
};

class Daemon {
 public:
  using Clock = std::chrono::steady_clock;

  Daemon(DaemonOptions opt, std::shared_ptr<spdlog::logger> log);
  ~Daemon();

  /// start(), the loop until SIGINT/SIGTERM or --duration, finish(); returns
  /// the exit status (0 clean stop, 1 LCM unavailable or report not written).
  int run();

  // ---- the loop driven by hand (tests): start(); poll() ...; finish() ----
  /// Subscribe, apply the real-time settings, arm the timers; false if LCM
  /// cannot be opened.
  bool start();
  /// Run the handlers that are ready (LCM input, due ticks); never blocks.
  std::size_t poll() { return io_.poll(); }
  /// Stop the loop as SIGTERM would.
  void requestStop(const char* why) { stop(why); }
  bool stopped() const { return stopping_; }
  /// After the loop: flush the log, write the report; false if the report failed.
  bool finish();

  std::size_t shaftCount() const { return shafts_.size(); }
  const ShaftTwin& shaft(std::size_t i) const { return *shafts_[i]; }
  const RealtimeOutcome& realtimeOutcome() const { return rt_; }
  /// Ticks handled so far (all schedules); the systemd watchdog follows it.
  std::uint64_t loopProgress() const { return progress_.load(std::memory_order_relaxed); }
  std::int64_t instanceId() const { return instance_id_; }
  /// The miss record (miss_record.hpp): every deadline miss of the loop.
  const MissLog& misses() const { return misses_.log(); }
  /// The loop-time split so far (cumulative).
  const LoopSplit& loopSplit() const { return split_; }

 private:
  struct RateGroup {
    double rate = 0.0;
    Clock::duration period{};
    std::int64_t k = 1;  ///< index of the next deadline
    std::vector<ShaftTwin*> shafts;
    std::vector<int> ids;  ///< the daemon's index of each shaft (shafts_[ids[j]] == shafts[j])
    std::unique_ptr<boost::asio::steady_timer> timer;
    int index = 0;         ///< in groups_
    /// Deferred starts per tick: the smallest [service] max_starts_per_tick
    /// of the group (0 there = no budget).
    int start_budget = 0;
    /// Exact guide-rope envelopes per tick: the smallest [service]
    /// max_exact_envelopes_per_tick of the group (0 there = no budget).
    int envelope_budget = 0;
    /// The miss record: the loop's split and the time when this schedule's
    /// previous tick began (miss_recorder.hpp).
    MissWindow window{};
  };

  // start(), step by step
  bool checkLcm();               ///< the LCM instances opened
  void applyRealtimeSettings();  ///< mlockall / SCHED_FIFO / affinity as asked, reported
  bool openInput();              ///< own udpm receive path (or LCM's); shafts subscribed
  void openOutput();             ///< own udpm publisher for udpm output URLs
  void startForecasts();         ///< the forecast pool's workers
  void startTrips();             ///< the preload keepers' worker; the trip pool's ([history] enabled)
  void unblockStopSignals();     ///< the stop signals, handled on the loop thread
  void startSchedules();         ///< the clock starts; shafts announce themselves; timers armed
  void logStarted();             ///< one start line per shaft

  void armLcm();
  void drainInput();  ///< the receive path: dispatch what is queued (timed)
  void flushOutputs();  ///< the own publisher: send what the tick queued (timed)
  void onLcmReadable(const boost::system::error_code& ec);
  void armTimer(RateGroup& g);
  void onTick(RateGroup& g, const boost::system::error_code& ec);
  void stop(const char* why);
  void armSignals();
  bool writeReport() const;

  DaemonOptions opt_;
  std::shared_ptr<spdlog::logger> out_;
  RtLog log_;
  boost::asio::io_context io_;
  ::lcm::LCM lcm_;
  bus::Subscriber input_{lcm_};  ///< the receive path: own for udpm URLs (hoist/bus/subscriber.hpp), else LCM's
  std::int64_t ignored_ = 0;     ///< the udpm receiver's ignored + malformed, mirrored for the health reports
  static constexpr std::size_t kDrainEvery = 16;  ///< shafts stepped between two drains within a tick
  // cost split (report): steady-clock ns in the ticks (without the drains
  // inside them) and in the drains; process CPU time at start
  std::int64_t ns_ticks_ = 0, ns_receive_ = 0, cpu0_ = 0;
  std::unique_ptr<UdpmSender> sender_;      ///< own publisher for udpm output URLs (udpm_sender.hpp); else LCM's
  std::int64_t ns_flush_ = 0;               ///< cost split: steady-clock ns in sender_->flush()
  std::unique_ptr<::lcm::LCM> lcm_out_;  ///< [service] lcm_url_out, publish only (never subscribed: no receive socket)
  std::int64_t instance_id_ = 0;       ///< random per process (HOIST_CAGE/HOIST_HEALTH.instance_id)
  boost::asio::posix::stream_descriptor lcm_fd_;
  /// lcm_url_out elsewhere: our own HOIST_HEALTH watched there (output_watch.hpp)
  OutputWatch out_watch_{io_, log_, out_};
  boost::asio::signal_set signals_;
  std::vector<std::unique_ptr<ShaftTwin>> shafts_;
  std::vector<std::unique_ptr<RateGroup>> groups_;
  LoopSplit split_;                        ///< the loop's time by phase, cumulative (miss_record.hpp)
  MissRecorder misses_{io_, log_, split_};  ///< every deadline miss and its log line (miss_recorder.hpp)
  /// The one forecast pool of the process: serves every shaft with
  /// [forecast] enabled and --clock wall.  Declared after shafts_ so that it
  /// stops (joins its workers) before the jobs it serves are destroyed.
  std::unique_ptr<ForecastPool> pool_;
  /// The trip rooms' workers ([history] enabled): a few threads for every
  /// shaft (trip_pool.hpp); after shafts_ for the same reason.
  std::unique_ptr<TripPool> trip_pool_;
  /// The shafts' preload keepers' one worker (keeper_worker.hpp); after
  /// shafts_ for the same reason.
  std::unique_ptr<KeeperWorker> keepers_;
  Clock::time_point start_{};
  Clock::time_point stop_time_{};
  RealtimeOutcome rt_;
  bool started_ = false, stopping_ = false;
  const char* stop_reason_ = "";

  // systemd (sd_notify): READY=1 once the loop is armed; WATCHDOG=1 from the
  // watchdog's thread (watchdog.hpp), only when the loop's tick counter moved
  // since the previous check.  The loop only bumps the counter (one relaxed
  // atomic add: no lock, no allocation, no system call).
  std::atomic<std::uint64_t> progress_{0};
  Watchdog watchdog_{progress_, out_};
};

}  // namespace hoist::service::app
