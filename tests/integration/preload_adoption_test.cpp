// Adopting the identified guide-rope preload into the live twin (issue 32),
// end to end over real UDP multicast on loopback (port 8146): hoist-alarm-ack
// --adopt-preload sends the command, hoist-twind builds the model off its
// loop, swaps it in at rest, keeps it in its state directory and shows it in
// HOIST_HEALTH.preload_scale; a restart runs it from the first health
// message; an invalid scale is refused by the tool and by the daemon.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/winder_t.hpp"
#include "lcm_fixtures.hpp"

using namespace hoist::test;
using namespace std::chrono_literals;

namespace {

class PreloadAdoption : public LcmProcessTest {
 protected:
  /// The winder at rest at the initial length for `seconds` (100 Hz): the
  /// twin has a state, so its forecasts run (from the adopted model's solver
  /// after the swap).
  void winderAtRest(double seconds) {
    for (int k = 0; k < static_cast<int>(seconds * 100); ++k) {
      hoist::winder_t w{};
      w.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                    std::chrono::system_clock::now().time_since_epoch()).count();
      w.seq = seq_++;
      w.has_length = true;
      w.length = 50.0;
      listener_->lcm().publish("HOIST_WINDER", &w);
      listener_->waitFor([] { return false; }, 10ms);
    }
  }
  std::int64_t seq_ = 0;
  bool healthSays(double scale, std::chrono::milliseconds within) {
    return listener_->waitFor(
        [&] {
          const auto h = listener_->decoded<hoist::health_t>("HOIST_HEALTH");
          return !h.empty() && h.back().preload_scale == scale;
        },
        within);
  }
};

}  // namespace

TEST_F(PreloadAdoption, AnOperatorAdoptsAPreloadTheDaemonKeepsItAndRunsItAfterARestart) {
  start(8146, "PreloadAdoption", {"HOIST_HEALTH"});
  const std::string state = (dir_ / "state").string(), log = (dir_ / "twind.log").string();
  std::filesystem::create_directories(state);
  const std::vector<std::string> argv{HOIST_TWIND, "--lcm-url", url_, "--clock", "wall", "--state-dir", state};
  std::int64_t old_id = 0;
  {
    auto d = startDaemonAndWait(*listener_, argv, log);
    ASSERT_TRUE(healthSays(1.0, 5s)) << readFile(log);
    // The tool refuses a scale outside [0.3, 1.6] before sending anything.
    EXPECT_EQ(runProcess({HOIST_ACK, "--lcm-url", url_, "--adopt-preload", "2"}, (dir_ / "ack.log").string(), 20s), 2);
    EXPECT_NE(readFile((dir_ / "ack.log").string()).find("--adopt-preload"), std::string::npos);
    // The daemon refuses one sent by hand, and counts it.
    hoist::alarm_ack_t bad{};
    bad.action = hoist::alarm_ack_t::ACTION_ADOPT_PRELOAD;
    bad.preload_scale = 2.0;
    bad.user = "mallory";
    listener_->lcm().publish("HOIST_ALARM_ACK", &bad);
    EXPECT_TRUE(listener_->waitFor(
        [&] {
          const auto h = listener_->decoded<hoist::health_t>("HOIST_HEALTH");
          return !h.empty() && h.back().commands_invalid >= 1;
        },
        5s)) << readFile(log);
    EXPECT_EQ(runProcess({HOIST_ACK, "--lcm-url", url_, "--adopt-preload", "0.8", "--user", "alice"},
                         (dir_ / "ack.log").string(), 20s),
              0);
    EXPECT_NE(readFile((dir_ / "ack.log").string()).find("sent ADOPT_PRELOAD x0.8 user=alice"), std::string::npos);
    // The twin rests at its initial length: the model is swapped in at once.
    EXPECT_TRUE(healthSays(0.8, 5s)) << readFile(log);
    // The forecasts now start from the new solver and run the new model on
    // their worker (the scheduler used to keep the old solver's address).
    const std::int64_t forecasts0 = listener_->decoded<hoist::health_t>("HOIST_HEALTH").back().forecasts;
    winderAtRest(3.0);
    EXPECT_TRUE(listener_->waitFor(
        [&] {
          const auto h = listener_->decoded<hoist::health_t>("HOIST_HEALTH");
          return !h.empty() && h.back().forecasts >= forecasts0 + 2 && h.back().preload_scale == 0.8;
        },
        5s)) << readFile(log);
    old_id = listener_->decoded<hoist::health_t>("HOIST_HEALTH").back().instance_id;
    stopDaemonCleanly(*d, log);
  }
  const std::string text = readFile(log);
  EXPECT_NE(text.find("AUDIT operator 'alice': adopt the guide-rope preloads x0.8"), std::string::npos) << text;
  EXPECT_NE(text.find("AUDIT operator 'alice': the live twin now runs the guide-rope preloads x0.8 (Tb1 = 24000 N"),
            std::string::npos) << text;
  EXPECT_NE(text.find("preload_scale in [0.3, 1.6]"), std::string::npos) << "the refusal says the rule:\n" << text;
  EXPECT_EQ(text.find("mallory': adopt"), std::string::npos) << text;
  const std::string kept = readFile(state + "/preload");
  EXPECT_NE(kept.find("preload_scale = 0.8"), std::string::npos) << kept;
  EXPECT_NE(kept.find("adopted_by = alice"), std::string::npos) << kept;

  // The next start runs the kept preload from its first health message.
  listener_->clear();
  const std::string log2 = (dir_ / "twind2.log").string();
  auto d2 = startDaemonAndWait(*listener_, argv, log2);
  bool seen = false;
  for (const auto& h : listener_->decoded<hoist::health_t>("HOIST_HEALTH")) {
    if (h.instance_id == old_id) continue;  // the first daemon's last report, late
    EXPECT_EQ(h.preload_scale, 0.8) << "the new daemon's first health message";
    seen = true;
    break;
  }
  EXPECT_TRUE(seen);
  stopDaemonCleanly(*d2, log2);
  EXPECT_NE(readFile(log2).find("the twin runs the preloads x0.8 (Tb1 = 24000 N, Tb2 = 24000 N; the config says "
                                "30000 N and 30000 N), adopted by 'alice'"),
            std::string::npos) << readFile(log2);
}
