// PreloadKeeper: one shaft's adopted guide-rope preload (issue 32,
// docs/condition.md "Adopting the identified preload").
//
// The shaft's memory identifies the preload trip by trip and raises
// GUIDE_PRELOAD_LOW; the live twin keeps the config's preload until a person
// decides otherwise.  An operator's command (alarm_ack_t
// ACTION_ADOPT_PRELOAD, preload_scale s) makes the twin run both guide-rope
// preloads times s:
//   - request(), on the loop: the validated command goes into a mailbox
//     (a copy; no allocation, no lock, no I/O);
//   - serve(), on a worker (the daemon's one keeper thread, SCHED_OTHER
//     nice 10): builds the TwinModel (hoist/service/twin/twin_model.hpp), keeps
//     the scale, the user and the time in the state file (atomically:
//     temporary file, fsync, rename), logs, and hands the model to the loop;
//     it also releases the models the loop retired;
//   - afterTick(), on the loop after each tick: a built model waiting and
//     the cage at rest (|v| and |a| <= [estimator] rest_speed, or no input
//     yet, or stale) -> TwinCore::adoptModel, logged with the user; the old
//     model goes back to the worker for release.  While the cage moves the
//     model waits (the adoption is logged as pending).
//   - loadKept(), at start-up: the scale kept by an earlier adoption, built.
// The config file is never written.  Until an adoption, MODEL_MISMATCH (the
// live check) and GUIDE_PRELOAD_LOW (the memory) say the model and the
// shaft differ; after it GUIDE_PRELOAD_LOW stays (the shaft's memory judges
// the shaft against the config's preload: the rope is still slack), while
// the live twin's forecasts, clearances and model check use the new model.
//
// Lifetimes: owned by ShaftTwin; the worker that calls serve() must stop
// before the keeper is destroyed (Daemon::stop joins it first).  `nominal`
// is copied.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include <spdlog/logger.h>

#include "hoist/rt/latest_mailbox.hpp"
#include "hoist/rt/rt_log.hpp"
#include "hoist/service/twin/twin_core.hpp"

namespace hoist::service::inline app {

class PreloadKeeper {
 public:
  /// `path`: the state file ("" = kept in memory only: no --state-dir);
  /// `tag`: the shaft's log prefix; `log`: the worker's logger; `rt_log`:
  /// the loop's log ring.
  PreloadKeeper(const TwinConfig& nominal, std::string path, std::string tag, std::shared_ptr<spdlog::logger> log,
                rt::RtLog& rt_log);
  ~PreloadKeeper();
  PreloadKeeper(const PreloadKeeper&) = delete;
  PreloadKeeper& operator=(const PreloadKeeper&) = delete;

  /// Start-up (not the loop): the model of the kept scale, or nullptr when
  /// none is kept (or it is 1).  A damaged file, or a scale outside the
  /// contract's bounds, is logged naming the file and ignored (the twin runs
  /// the config's preload, and says so).
  std::unique_ptr<TwinModel> loadKept();
  /// Loop: an operator adopts `scale` (validated by the contract).  false:
  /// an earlier adoption is still being built, waits for rest or for its
  /// old model's release (refused; the caller says so).  Allocation-free.
  bool request(double scale, const std::string& user, std::int64_t utime);
  /// Loop, after each tick: adopt a built model when the cage is at rest.
  /// Allocation-free; never blocks.
  void afterTick(TwinCore& core);
  /// Worker: build what was requested, keep it, release retired models.
  void serve();

  /// An adoption requested and not yet in use (any thread).
  bool pending() const { return busy_.load(std::memory_order_acquire); }
  const std::string& path() const { return path_; }
  long adopted() const { return adopted_.load(std::memory_order_relaxed); }

 private:
  struct Request {
    double scale = 1.0;
    std::int64_t utime = 0;
    std::array<char, 72> user{};
  };
  struct Built {
    std::unique_ptr<TwinModel> model;
    Request req;
  };
  TwinConfig nominal_;
  std::string path_, tag_;
  std::shared_ptr<spdlog::logger> log_;
  rt::RtLog& rt_log_;
  rt::LatestMailbox<Request> requests_{Request{}};
  std::atomic<Built*> ready_{nullptr};    // worker -> loop
  std::atomic<Built*> retired_{nullptr};  // loop -> worker: the shell, holding the model replaced
  /// An adoption's cycle: set by request() (loop), cleared by the worker when
  /// the build failed or the replaced model is released.
  std::atomic<bool> busy_{false};
  std::atomic<long> adopted_{0};
  bool waiting_logged_ = false;           // loop: "waits for rest" said once per adoption
};

}  // namespace hoist::service::app
