// hoist-replay --measurements over real UDP multicast on loopback (port
// 7880): every row gives one HOIST_WINDER (with l) and, where the row has
// the sensor values, one HOIST_CAGE_IMU and one HOIST_ROPE_LOAD, all with
// the channel prefix, the row's utime and each channel's own seq.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "hoist/bus/channels.hpp"
#include "hoist/cage_imu_t.hpp"
#include "hoist/rope_load_t.hpp"
#include "hoist/winder_t.hpp"
#include "lcm_fixtures.hpp"

using namespace hoist::test;

namespace {

class ReplayMeasurements : public LcmProcessTest {};

template <class T>
T decode(const Listener::Message& m) {
  T out{};
  EXPECT_GE(out.decode(m.data.data(), 0, static_cast<int>(m.data.size())), 0);
  return out;
}

}  // namespace

TEST_F(ReplayMeasurements, PublishesWinderAndSensorChannels) {
  start(7880, "ReplayMeasurements");
  listener_->subscribe("N_HOIST_.*");
  // 60 rows at 100 Hz; the IMU is absent in rows 10..19, the rope load cell in
  // every third row; row 30 has f_y only (no cage_imu_t: it carries both).
  const std::string path = (dir_ / "meas.csv").string();
  {
    std::ofstream out(path);
    out << "# test\nt,l,v,a,f_y,omega,rope_load\n";
    for (int k = 0; k < 60; ++k) {
      char line[200];
      const bool imu = !(k >= 10 && k < 20);
      const bool rope = k % 3 != 0;
      std::snprintf(line, sizeof line, "%.2f,%.3f,0.5,0.25,%s,%s,%s\n", 0.01 * k, 80.0 + 0.005 * k,
                    imu ? std::to_string(0.001 * k).c_str() : "", imu && k != 30 ? std::to_string(1e-5 * k).c_str() : "",
                    rope ? std::to_string(10000.0 + k).c_str() : "");
      out << line;
    }
  }
  Process p({HOIST_REPLAY, "--lcm-url", url_, "--measurements", path, "--channel-prefix", "N_", "--speed", "1"},
            (dir_ / "replay.log").string());
  listener_->waitFor([&] { return !p.running(); }, 20s);
  ASSERT_EQ(p.wait(1s), 0) << readFile((dir_ / "replay.log").string());
  listener_->waitFor([&] { return listener_->count("N_HOIST_WINDER") >= 60; }, 2s);
  const std::string log = readFile((dir_ / "replay.log").string());
  EXPECT_NE(log.find("1 row(s)"), std::string::npos) << log;  // the f_y-only row is reported

  ASSERT_EQ(listener_->count("N_HOIST_WINDER"), 60u);
  ASSERT_EQ(listener_->count("N_HOIST_CAGE_IMU"), 49u);   // 60 - 10 absent - 1 half
  ASSERT_EQ(listener_->count("N_HOIST_ROPE_LOAD"), 40u);  // k % 3 != 0
  EXPECT_EQ(listener_->count("HOIST_WINDER"), 0u);

  const auto& w = listener_->messages("N_HOIST_WINDER");
  const auto w0 = decode<hoist::winder_t>(w[0]);
  for (std::size_t k = 0; k < w.size(); ++k) {
    const auto m = decode<hoist::winder_t>(w[k]);
    EXPECT_EQ(m.seq, static_cast<std::int64_t>(k));
    EXPECT_TRUE(m.has_length);
    EXPECT_NEAR(m.length, 80.0 + 0.005 * k, 1e-9);
    EXPECT_EQ(m.v, 0.5);
    EXPECT_EQ(m.a, 0.25);
    EXPECT_EQ(m.utime - w0.utime, static_cast<std::int64_t>(10000 * k));
  }
  const auto& imu = listener_->messages("N_HOIST_CAGE_IMU");
  for (std::size_t i = 0; i < imu.size(); ++i) {
    const auto m = decode<hoist::cage_imu_t>(imu[i]);
    EXPECT_EQ(m.seq, static_cast<std::int64_t>(i));
    const long k = std::lround((m.utime - w0.utime) / 10000.0);
    EXPECT_FALSE(k >= 10 && k < 20) << k;
    EXPECT_NE(k, 30);
    EXPECT_NEAR(m.f_y, 0.001 * k, 1e-12);
    EXPECT_NEAR(m.omega, 1e-5 * k, 1e-12);
  }
  const auto& rope = listener_->messages("N_HOIST_ROPE_LOAD");
  for (std::size_t i = 0; i < rope.size(); ++i) {
    const auto m = decode<hoist::rope_load_t>(rope[i]);
    EXPECT_EQ(m.seq, static_cast<std::int64_t>(i));
    const long k = std::lround((m.utime - w0.utime) / 10000.0);
    EXPECT_NE(k % 3, 0);
    EXPECT_NEAR(m.force, 10000.0 + k, 1e-9);
  }
}

TEST(SensorChannels, NamesAndPrefix) {
  const hoist::bus::Channels ch("N_");
  EXPECT_EQ(ch.cage_imu, "N_HOIST_CAGE_IMU");
  EXPECT_EQ(ch.rope_load, "N_HOIST_ROPE_LOAD");
  EXPECT_EQ(ch.estimate, "N_HOIST_ESTIMATE");
  EXPECT_EQ(hoist::bus::Channels().estimate, "HOIST_ESTIMATE");
}

TEST_F(ReplayMeasurements, BadFileExitsTwoBeforePublishing) {
  start(7881, "ReplayMeasurementsBad");
  listener_->subscribe("HOIST_.*");
  const std::string path = (dir_ / "bad.csv").string();
  std::ofstream(path) << "t,l,v,a,rope_load\n0,80,0,0,1\n0.01,80,0,0,oops\n";
  const CapturedRun r = runCaptured(HOIST_REPLAY, {"--lcm-url", url_, "--measurements", path, "--speed", "0"});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("bad.csv:3: rope_load: not a number"), std::string::npos) << r.output;
  listener_->pump(200ms);
  EXPECT_EQ(listener_->count("HOIST_WINDER"), 0u);
  const CapturedRun both = runCaptured(HOIST_REPLAY, {"--lcm-url", url_, "--measurements", path, "--profile", "paper"});
  EXPECT_EQ(both.status, 2) << both.output;
}
