// One shaft's learned accelerometer offset, kept across restarts: see offset_keeper.hpp.
#include "offset_keeper.hpp"

#include <chrono>
#include <filesystem>
#include <stdexcept>

#include "hoist/rt/realtime.hpp"

namespace hoist::service::inline app {

namespace {
constexpr auto kWriterPeriod = std::chrono::milliseconds(200);
constexpr int kNice = 10;
}  // namespace

OffsetKeeper::OffsetKeeper(std::string path, std::string tag, std::shared_ptr<spdlog::logger> log)
    : path_(std::move(path)), tag_(std::move(tag)), log_(std::move(log)) {}

OffsetKeeper::~OffsetKeeper() { stop(); }

std::optional<io::AccelOffsetRecord> OffsetKeeper::load() const {
  std::error_code ec;
  if (!std::filesystem::exists(path_, ec)) {
    log_->info("{}accelerometer offset: none kept yet in {} (a calibration will keep it there)", tag_, path_);
    return std::nullopt;
  }
  try {
    const io::AccelOffsetRecord r = io::readAccelOffsetFile(path_);
    log_->info("{}accelerometer offset: {:.6f} +- {:.6f} m/s^2 from {} (kept by an earlier calibration)", tag_,
               r.offset, r.sigma, path_);
    return r;
  } catch (const std::exception& e) {
    log_->error("{}accelerometer offset: {} is damaged and ignored ({}); the estimator starts from its prior "
                "([sensors] imu_accel_offset_sigma): calibrate again", tag_, path_, e.what());
    return std::nullopt;
  }
}

void OffsetKeeper::afterTick(const TwinCore& core) {
  const bool now = core.calibrating();
  if (was_calibrating_ && !now) {
    if (const LoadEstimate* e = core.estimate()) {
      io::AccelOffsetRecord& slot = box_.writeSlot();
      slot.offset = e->accel_offset;
      slot.sigma = e->sigma_accel_offset;
      box_.publish();
    }
  }
  was_calibrating_ = now;
}

void OffsetKeeper::start() {
  if (writer_.joinable()) return;
  quit_.store(false);
  writer_ = std::thread([this] { writerMain(); });
}

void OffsetKeeper::stop() {
  if (!writer_.joinable()) return;
  quit_.store(true, std::memory_order_release);
  writer_.join();
}

void OffsetKeeper::writerMain() {
  hoist::rt::yieldToRealtimeLoop(kNice);
  for (;;) {
    const bool quitting = quit_.load(std::memory_order_acquire);
    writePending();
    if (quitting) break;
    std::this_thread::sleep_for(kWriterPeriod);
  }
}

void OffsetKeeper::writePending() {
  const io::AccelOffsetRecord* r = box_.take();
  if (!r) return;
  try {
    io::writeAccelOffsetFile(path_, *r, "the accelerometer offset's state file");
    written_.fetch_add(1, std::memory_order_relaxed);
    log_->info("{}accelerometer offset: the calibration learned {:.6f} +- {:.6f} m/s^2, kept in {} (read at the "
               "next start)", tag_, r->offset, r->sigma, path_);
  } catch (const std::exception& e) {
    log_->error("{}accelerometer offset: the calibration's {:.6f} +- {:.6f} m/s^2 could not be kept: {}; it is "
                "used until the daemon stops", tag_, r->offset, r->sigma, e.what());
  }
}

}  // namespace hoist::service::app
