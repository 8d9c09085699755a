// OffsetKeeper (service/app/offset_keeper.hpp, issue 30): the accelerometer
// offset a live calibration taught the estimator is kept in the daemon's
// state directory and read back at the next start; the loop side only
// copies it into a mailbox (the writer thread does the file).
#include "offset_keeper.hpp"

#include <gtest/gtest.h>

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "hoist/service/twin/twin_core.hpp"

namespace fs = std::filesystem;
using namespace hoist;
using namespace hoist::service;

namespace {

constexpr std::int64_t kT0 = 1'700'000'000'000'000;
constexpr double kOffset = 0.0098;  // 1 mg

TwinConfig estimatorConfig() {
  TwinConfig c;
  c.shaft.n = 12;  // fast
  c.service.envelope_points = 101;
  c.service.shape_points = 21;
  c.estimator.enabled = true;
  c.estimator.settings.accel_offset_sigma = 0.005;  // an uncalibrated IMU
  return c;
}

/// A twin at rest whose IMU reads the configured load's static tilt 1 mg off.
struct RestingTwin {
  explicit RestingTwin(const TwinConfig& cfg) : core(cfg, ClockMode::Wall), g(cfg.shaft.g) {
    s.has_length = true;
    s.length = cfg.shaft.l0;
  }
  void tickTo(double w) {
    s.seq += 1;
    s.utime = kT0 + std::llround(w * 1e6);
    ASSERT_TRUE(core.onInput(s, w - 0.001).accepted);
    core.onCageImu(s.utime, g * theta + kOffset, 0.0, w, s.utime);
    core.tick(w, w);
    core.housekeeping(w);
    if (core.estimate()) theta = core.estimate()->theta_open;
  }
  TwinCore core;
  WinderSample s;
  double g, theta = 0.0;
};

std::shared_ptr<spdlog::logger> capture(std::ostringstream& out) {
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(out);
  return std::make_shared<spdlog::logger>("offset-keeper-test", sink);
}

fs::path freshDir(const char* name) {
  const fs::path d = fs::temp_directory_path() / (std::string("hoist-offset-keeper-") + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST(OffsetKeeper, ACalibrationIsKeptAndReadBackAtTheNextStart) {
  const TwinConfig cfg = estimatorConfig();
  const fs::path file = freshDir("kept") / "accel_offset";
  std::ostringstream log;
  double learned = 0.0, learned_sigma = 0.0;
  {
    RestingTwin t(cfg);
    OffsetKeeper keeper(file.string(), "", capture(log));
    EXPECT_FALSE(keeper.load().has_value()) << "nothing kept yet";
    keeper.start();
    t.tickTo(0.01);
    keeper.afterTick(t.core);
    ASSERT_TRUE(t.core.calibrate(cfg.shaft.Fa, cfg.shaft.b, 2.0));
    for (int k = 2; k <= 400; ++k) {  // 2 s of calibration, then 2 s more
      t.tickTo(0.01 * k);
      keeper.afterTick(t.core);
      if (t.core.calibrating()) {
        learned = t.core.estimate()->accel_offset;
        learned_sigma = t.core.estimate()->sigma_accel_offset;
      }
    }
    keeper.stop();
    EXPECT_EQ(keeper.written(), 1) << log.str();
  }
  ASSERT_TRUE(fs::exists(file)) << log.str();
  EXPECT_NE(log.str().find("the calibration learned"), std::string::npos) << log.str();
  const io::AccelOffsetRecord r = io::readAccelOffsetFile(file.string());
  EXPECT_GT(r.sigma, 0.0);
  EXPECT_LT(r.sigma, 0.001);
  EXPECT_NEAR(r.offset, kOffset, 3.0 * r.sigma) << "the truth inside the kept band";
  // What was kept is what the estimator had learned at the calibration's end.
  EXPECT_NEAR(r.offset, learned, 5.0 * learned_sigma);

  // The next start: the keeper reads it, the estimator starts from it.
  RestingTwin t2(cfg);
  std::ostringstream log2;
  OffsetKeeper keeper2(file.string(), "[north] ", capture(log2));
  const auto back = keeper2.load();
  ASSERT_TRUE(back.has_value()) << log2.str();
  EXPECT_DOUBLE_EQ(back->offset, r.offset);
  EXPECT_NE(log2.str().find("[north] accelerometer offset: "), std::string::npos) << log2.str();
  ASSERT_TRUE(t2.core.setAccelOffset(back->offset, back->sigma));
  t2.tickTo(0.01);
  ASSERT_NE(t2.core.estimate(), nullptr);
  // Started from it: one sample since moves it by a small part of its sigma
  // (it stays a state; a fresh start from the prior would be 0 +- 0.005).
  EXPECT_NEAR(t2.core.estimate()->accel_offset, r.offset, 0.1 * r.sigma);
  EXPECT_LE(t2.core.estimate()->sigma_accel_offset, r.sigma * (1.0 + 1e-9) + 1e-12);
}

TEST(OffsetKeeper, NoCalibrationWritesNothingAndADamagedFileIsIgnoredWithItsKey) {
  const TwinConfig cfg = estimatorConfig();
  const fs::path dir = freshDir("none");
  std::ostringstream log;
  {
    RestingTwin t(cfg);
    OffsetKeeper keeper((dir / "accel_offset").string(), "", capture(log));
    keeper.start();
    for (int k = 1; k <= 100; ++k) {
      t.tickTo(0.01 * k);
      keeper.afterTick(t.core);
    }
    keeper.stop();
    EXPECT_EQ(keeper.written(), 0);
  }
  EXPECT_FALSE(fs::exists(dir / "accel_offset"));

  std::ofstream(dir / "accel_offset") << "# hoist accelerometer offset\naccel_offset = lots\nsigma = 1e-5\n";
  OffsetKeeper damaged((dir / "accel_offset").string(), "", capture(log));
  EXPECT_FALSE(damaged.load().has_value());
  EXPECT_NE(log.str().find("is damaged and ignored"), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("accel_offset"), std::string::npos) << log.str();

  TwinConfig off = cfg;
  off.estimator.enabled = false;
  TwinCore plain(off, ClockMode::Wall);
  EXPECT_FALSE(plain.setAccelOffset(0.001, 1e-5)) << "no estimator, nothing to start";
}
