// OffsetKeeper: one shaft's learned accelerometer offset, kept across
// restarts (issue 30, docs/estimation.md "The accelerometer's offset").
//
// The operator's calibration (alarm_ack_t ACTION_CALIBRATE: the load is known
// for a while) teaches the load estimator the offset of the cage IMU's f_y.
// This room keeps what it learned in a small state file
// (hoist/io/accel_offset_file.hpp: the format hoist-estimate's --offset-in
// and --offset-out read and write) under the daemon's state directory:
//   - load(), at start-up before the loop, reads the file if there is one
//     (the caller applies it: TwinCore::setAccelOffset);
//   - afterTick(), on the loop thread after every tick, sees a calibration
//     end (TwinCore::calibrating() true -> false) and hands the learned
//     offset to the writer through a LatestMailbox: a copy, no allocation,
//     no lock, no I/O on the loop;
//   - a writer thread (started by start(), SCHED_OTHER nice 10 as the other
//     workers) writes the file atomically (temporary file, fsync, rename)
//     and logs it.  A write that fails is logged; the twin runs on.
//
// The config file is never written: the offset lives in the state file only.
// Lifetimes: owned by ShaftTwin; stop() (or the destructor) writes a handed
// offset not yet written, then joins the writer.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <spdlog/logger.h>

#include "hoist/io/accel_offset_file.hpp"
#include "hoist/rt/latest_mailbox.hpp"
#include "hoist/service/twin/twin_core.hpp"

namespace hoist::service::inline app {

class OffsetKeeper {
 public:
  /// `path`: the state file; `tag`: the shaft's log prefix ("[north] " or "").
  OffsetKeeper(std::string path, std::string tag, std::shared_ptr<spdlog::logger> log);
  ~OffsetKeeper();
  OffsetKeeper(const OffsetKeeper&) = delete;
  OffsetKeeper& operator=(const OffsetKeeper&) = delete;

  /// Start-up (not the loop): the kept offset, or nullopt when there is no
  /// file yet.  A damaged file is logged (naming file, line and key) and
  /// ignored: the estimator then starts from its prior.
  std::optional<io::AccelOffsetRecord> load() const;
  /// Loop thread, after each tick: a calibration that just ended hands its
  /// learned offset to the writer.  Allocation-free; never blocks.
  void afterTick(const TwinCore& core);
  /// Start the writer thread.
  void start();
  /// Write what is pending, join the writer.  Idempotent.
  void stop();

  const std::string& path() const { return path_; }
  /// Offsets written to the file (any thread).
  long written() const { return written_.load(std::memory_order_relaxed); }

 private:
  void writerMain();
  void writePending();

  std::string path_, tag_;
  std::shared_ptr<spdlog::logger> log_;
  rt::LatestMailbox<io::AccelOffsetRecord> box_{io::AccelOffsetRecord{}};
  bool was_calibrating_ = false;  // loop thread only
  std::atomic<long> written_{0};
  std::atomic<bool> quit_{false};
  std::thread writer_;
};

}  // namespace hoist::service::app
