// Adopting the identified guide-rope preload into the live twin (issue 32;
// service/twin TwinCore::adoptModel, service/app/preload_keeper.hpp).
//
// - A twin that adopted x0.7 at rest runs as a twin configured with x0.7
//   from the start: the same cage state, clearances, forces and load
//   estimate on every step of the trip that follows (an independent
//   formulation of "the swap is complete": solver, envelopes, bounds and the
//   estimator's solvers), and differs from the nominal twin.
// - The estimator's loads, their sigma and the offset carry over.
// - The keeper: built off the loop, used only at rest, kept in the state
//   file and read back at the next start; refused while one is in flight; a
//   damaged or out-of-range file is ignored with its key.
#include "preload_keeper.hpp"

#include <gtest/gtest.h>

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "hoist/io/preload_file.hpp"
#include "hoist/service/twin/twin_core.hpp"

namespace fs = std::filesystem;
using namespace hoist;
using namespace hoist::service;

namespace {

constexpr std::int64_t kT0 = 1'700'000'000'000'000;

TwinConfig smallConfig() {
  TwinConfig c;
  c.shaft.n = 12;  // fast
  c.service.envelope_points = 101;
  c.service.shape_points = 21;
  c.estimator.enabled = true;
  return c;
}

/// Feeds the same winder and sensor samples to a twin (input clock): at
/// rest, then a trip (1 m/s^2 to 3 m/s, 4 s at speed, back to rest), with an
/// IMU and a rope load cell that read a sway of their own.
struct Trip {
  static constexpr int kRest = 50, kSteps = 1200;
  static Kinematics at(int k) {
    const double t = 0.01 * (k - kRest);
    if (k <= kRest) return {0.0, 0.0, 0.0};
    if (t < 3.0) return {0.5 * t * t, t, 1.0};
    if (t < 7.0) return {4.5 + 3.0 * (t - 3.0), 3.0, 0.0};
    if (t < 10.0) {
      const double u = t - 7.0;
      return {16.5 + 3.0 * u - 0.5 * u * u, 3.0 - u, -1.0};
    }
    return {21.0, 0.0, 0.0};
  }
  static void feed(TwinCore& core, int k, double l0, bool sensors = true) {
    const Kinematics kin = at(k);
    WinderSample s;
    s.seq = k;
    s.utime = kT0 + 10'000LL * k;
    s.v = kin.v;
    s.a = kin.a;
    s.has_length = true;
    s.length = l0 + kin.l;
    ASSERT_TRUE(core.onInput(s, 0.01 * k).accepted) << k;
    if (!sensors) return;
    core.onCageImu(s.utime, 0.01 * std::sin(0.7 * k), 1e-4 * std::cos(0.3 * k), 0.01 * k, s.utime);
    core.onRopeLoad(s.utime, 9000.0 + 20.0 * std::sin(0.11 * k), 0.01 * k, s.utime);
  }
};

std::shared_ptr<spdlog::logger> capture(std::ostringstream& out) {
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(out);
  return std::make_shared<spdlog::logger>("preload-keeper-test", sink);
}

fs::path freshDir(const char* name) {
  const fs::path d = fs::temp_directory_path() / (std::string("hoist-preload-keeper-") + name + "-" +
                                                  std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

double rel(double a, double b) { return std::abs(a - b) / std::max(1e-12, std::max(std::abs(a), std::abs(b))); }

}  // namespace

TEST(TwinModel, ATwinThatAdoptedAPreloadAtRestRunsAsATwinConfiguredWithIt) {
  const TwinConfig nominal = smallConfig();
  TwinConfig slack = nominal;
  slack.shaft.Tb1 *= 0.7;
  slack.shaft.Tb2 *= 0.7;
  TwinCore adopted(nominal, ClockMode::Input), configured(slack, ClockMode::Input), plain(nominal, ClockMode::Input);
  // The first winder input starts the twins; the adoption drops sensor
  // samples queued before it (their predictions were the old model's), so
  // the sensors speak from the next step on, for all three.
  for (TwinCore* c : {&adopted, &configured, &plain}) Trip::feed(*c, 0, nominal.shaft.l0, false);
  auto m = buildTwinModel(nominal, 0.7);
  adopted.adoptModel(m);
  ASSERT_NE(m, nullptr) << "the old model comes back for release";
  EXPECT_EQ(m->preload_scale, 1.0);
  EXPECT_EQ(m->shaft.Tb1, nominal.shaft.Tb1);
  EXPECT_EQ(adopted.preloadScale(), 0.7);
  EXPECT_DOUBLE_EQ(adopted.config().shaft.Tb1, slack.shaft.Tb1);
  EXPECT_DOUBLE_EQ(adopted.solver().model().params().Tb2, slack.shaft.Tb2);
  EXPECT_EQ(adopted.modelResets(), 0) << "an adoption is not a reset";
  EXPECT_FALSE(adopted.degraded());

  double worst = 0.0, differs = 0.0;
  for (int k = 1; k <= Trip::kSteps; ++k) {
    for (TwinCore* c : {&adopted, &configured, &plain}) Trip::feed(*c, k, nominal.shaft.l0);
    const CageOutput &a = adopted.output(), &b = configured.output(), &p = plain.output();
    ASSERT_DOUBLE_EQ(a.kin.l, b.kin.l);
    for (const auto& [x, y, z] : {std::tuple{a.y_c, b.y_c, p.y_c}, std::tuple{a.theta, b.theta, p.theta},
                                 std::tuple{a.lambda[1], b.lambda[1], p.lambda[1]},
                                 std::tuple{a.clearance.guide_deflection, b.clearance.guide_deflection,
                                            p.clearance.guide_deflection}}) {
      worst = std::max(worst, rel(x, y));
      differs = std::max(differs, rel(y, z));
    }
    ASSERT_NE(adopted.estimate(), nullptr);
    ASSERT_NE(configured.estimate(), nullptr);
    worst = std::max(worst, rel(adopted.estimate()->moment, configured.estimate()->moment));
    worst = std::max(worst, rel(adopted.estimate()->sigma_moment, configured.estimate()->sigma_moment));
    worst = std::max(worst, rel(adopted.estimate()->Fa, configured.estimate()->Fa));
  }
  EXPECT_LT(worst, 1e-9) << "the adopted twin follows the twin configured with x0.7";
  EXPECT_GT(differs, 0.05) << "x0.7 is not the nominal twin (the comparison can fail)";
}

TEST(TwinModel, TheEstimatorsLoadsAndOffsetCarryOverAnAdoption) {
  TwinConfig cfg = smallConfig();
  cfg.estimator.settings.accel_offset_sigma = 0.005;
  TwinCore core(cfg, ClockMode::Input);
  for (int k = 0; k <= 40; ++k) Trip::feed(core, k, cfg.shaft.l0);  // at rest: the rope load teaches Fa
  ASSERT_NE(core.estimate(), nullptr);
  const LoadEstimate before = *core.estimate();
  ASSERT_GT(std::abs(before.Fa - cfg.shaft.Fa), 100.0) << "the rope load moved Fa off its prior";
  auto m = buildTwinModel(cfg, 0.8);
  core.adoptModel(m);
  Trip::feed(core, 41, cfg.shaft.l0);
  const LoadEstimate& after = *core.estimate();
  EXPECT_NEAR(after.Fa, before.Fa, 3.0 * before.sigma_Fa) << "the load is not forgotten";
  EXPECT_LT(after.sigma_Fa, 1.5 * before.sigma_Fa);
  EXPECT_NEAR(after.moment, before.moment, 3.0 * before.sigma_moment);
  EXPECT_LT(after.sigma_moment, 1.5 * before.sigma_moment + 1.0);
  EXPECT_NEAR(after.accel_offset, before.accel_offset, 3.0 * before.sigma_accel_offset + 1e-9);
  EXPECT_EQ(core.preloadScale(), 0.8);

  // Another n, or another method: refused, nothing changed.
  TwinConfig other = cfg;
  other.shaft.n = 10;
  auto wrong = buildTwinModel(other, 0.9);
  EXPECT_THROW(core.adoptModel(wrong), std::invalid_argument);
  EXPECT_EQ(core.preloadScale(), 0.8);
  EXPECT_EQ(wrong->preload_scale, 0.9);
}

// MODEL_MISMATCH's trip-end preload test (hoist/preload_verdict.hpp) in the
// twin: a verdict raises MODEL_MISMATCH at the next step, with |z| against
// its bound, and keeps the estimate out of the alarms; a consistent one
// clears it; an adoption drops it (it judged the old preload).
TEST(TwinModel, ATripEndPreloadVerdictRaisesModelMismatchUntilAnAdoption) {
  const TwinConfig cfg = smallConfig();
  TwinCore core(cfg, ClockMode::Input);
  for (int k = 0; k <= 20; ++k) Trip::feed(core, k, cfg.shaft.l0);
  auto mismatchEvent = [&core](AlarmEventType type) -> const AlarmEvent* {
    for (const AlarmEvent& e : core.events())
      if (e.kind == AlarmKind::ModelMismatch && e.type == type) return &e;
    return nullptr;
  };
  core.clearEvents();
  core.setPreloadVerdict(true, -5.8, 4.0);
  EXPECT_TRUE(core.preloadMismatch());
  Trip::feed(core, 21, cfg.shaft.l0);
  const AlarmEvent* raise = mismatchEvent(AlarmEventType::Raise);
  ASSERT_NE(raise, nullptr) << "MODEL_MISMATCH rises at the next step";
  EXPECT_DOUBLE_EQ(raise->value, 5.8);
  EXPECT_DOUBLE_EQ(raise->threshold, 4.0);
  EXPECT_FALSE(core.estimateInUse()) << "the estimate does not judge the alarms meanwhile";
  EXPECT_TRUE(core.estimateGate().notUsed() & kNotUsedMismatch);
  // Held from step to step (no clear while the verdict stands).
  core.clearEvents();
  for (int k = 22; k <= 30; ++k) Trip::feed(core, k, cfg.shaft.l0);
  EXPECT_EQ(mismatchEvent(AlarmEventType::Clear), nullptr);
  // A consistent trip clears it.
  core.setPreloadVerdict(false, -0.4, 4.0);
  Trip::feed(core, 31, cfg.shaft.l0);
  EXPECT_NE(mismatchEvent(AlarmEventType::Clear), nullptr);
  // An adoption drops a verdict in force.
  core.setPreloadVerdict(true, -5.8, 4.0);
  Trip::feed(core, 32, cfg.shaft.l0);
  core.clearEvents();
  auto m = buildTwinModel(cfg, 0.7);
  core.adoptModel(m);
  EXPECT_FALSE(core.preloadMismatch());
  Trip::feed(core, 33, cfg.shaft.l0);
  EXPECT_NE(mismatchEvent(AlarmEventType::Clear), nullptr) << "the adoption's model is judged by the next trip";
}

TEST(PreloadKeeper, AnAdoptionIsBuiltOffTheLoopUsedAtRestKeptAndReadBackAtTheNextStart) {
  const TwinConfig cfg = smallConfig();
  const fs::path file = freshDir("kept") / "preload";
  std::ostringstream log, rtout;  // the worker's logger; the loop's ring (its own thread)
  rt::RtLog rtlog(capture(rtout));
  {
    TwinCore core(cfg, ClockMode::Input);
    PreloadKeeper keeper(cfg, file.string(), "[north] ", capture(log), rtlog);
    EXPECT_EQ(keeper.loadKept(), nullptr) << "nothing kept yet";
    for (int k = 0; k <= Trip::kRest + 100; ++k) Trip::feed(core, k, cfg.shaft.l0);  // the cage moves
    ASSERT_GT(std::abs(core.output().kin.v), 0.5);
    ASSERT_TRUE(keeper.request(0.75, "alice", kT0 + 5));
    EXPECT_FALSE(keeper.request(0.9, "bob", kT0 + 6)) << "one adoption at a time";
    keeper.afterTick(core);
    EXPECT_EQ(core.preloadScale(), 1.0) << "not built yet: nothing on the loop";
    keeper.serve();  // the worker builds it and keeps it
    ASSERT_TRUE(fs::exists(file));
    keeper.afterTick(core);
    EXPECT_EQ(core.preloadScale(), 1.0) << "the cage moves: it waits";
    EXPECT_TRUE(keeper.pending());
    int k = Trip::kRest + 101;
    for (; Trip::at(k).v != 0.0 || Trip::at(k).a != 0.0; ++k) {
      Trip::feed(core, k, cfg.shaft.l0);
      keeper.afterTick(core);
      ASSERT_EQ(core.preloadScale(), 1.0) << "adopted while moving at step " << k;
    }
    Trip::feed(core, k, cfg.shaft.l0);
    keeper.afterTick(core);  // at rest
    EXPECT_EQ(core.preloadScale(), 0.75);
    EXPECT_EQ(keeper.adopted(), 1);
    EXPECT_TRUE(keeper.pending()) << "until the worker released the old model";
    EXPECT_FALSE(keeper.request(0.9, "bob", kT0 + 7));
    keeper.serve();
    EXPECT_FALSE(keeper.pending());
    // Back to the config's preload: an adoption like any other.
    ASSERT_TRUE(keeper.request(1.0, "bob", kT0 + 8));
    keeper.serve();
    keeper.afterTick(core);
    EXPECT_EQ(core.preloadScale(), 1.0);
    keeper.serve();
    ASSERT_TRUE(keeper.request(0.75, "alice", kT0 + 9));
    keeper.serve();
    keeper.afterTick(core);
    keeper.serve();
    EXPECT_EQ(core.preloadScale(), 0.75);
  }
  rtlog.flush();
  EXPECT_NE(log.str().find("[north] guide-rope preload: x0.75 by 'alice' kept in"), std::string::npos) << log.str();
  const std::string text = rtout.str();
  EXPECT_NE(text.find("waits for the cage to rest"), std::string::npos) << text;
  EXPECT_NE(text.find("[north] AUDIT operator 'alice': the live twin now runs the guide-rope preloads x0.75"),
            std::string::npos) << text;
  const io::PreloadRecord r = io::readPreloadFile(file.string());
  EXPECT_EQ(r.preload_scale, 0.75);
  EXPECT_EQ(r.adopted_by, "alice");
  EXPECT_EQ(r.adopted_utime, kT0 + 9);

  // The next start runs it from the first step.
  std::ostringstream log2;
  PreloadKeeper again(cfg, file.string(), "", capture(log2), rtlog);
  auto m = again.loadKept();
  ASSERT_NE(m, nullptr) << log2.str();
  EXPECT_EQ(m->preload_scale, 0.75);
  EXPECT_DOUBLE_EQ(m->shaft.Tb1, 0.75 * cfg.shaft.Tb1);
  EXPECT_NE(log2.str().find("the twin runs the preloads x0.75"), std::string::npos) << log2.str();
  EXPECT_NE(log2.str().find("adopted by 'alice'"), std::string::npos) << log2.str();
  TwinCore core2(cfg, ClockMode::Input);
  core2.adoptModel(m);
  EXPECT_EQ(core2.preloadScale(), 0.75);
}

TEST(PreloadKeeper, ADamagedOrOutOfRangeStateFileIsIgnoredNamingItsKey) {
  const TwinConfig cfg = smallConfig();
  const fs::path dir = freshDir("damaged");
  std::ostringstream log, rtout;
  rt::RtLog rtlog(capture(rtout));
  const auto tryFile = [&](const std::string& body) {
    std::ofstream(dir / "preload") << body;
    log.str("");
    PreloadKeeper k(cfg, (dir / "preload").string(), "", capture(log), rtlog);
    return k.loadKept();
  };
  EXPECT_EQ(tryFile("preload_scale = lots\nadopted_utime = 1\nadopted_by = a\n"), nullptr);
  EXPECT_NE(log.str().find("preload_scale"), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("is damaged and ignored"), std::string::npos) << log.str();
  EXPECT_EQ(tryFile("preload_scale = 0.8\nadopted_by = a\n"), nullptr);
  EXPECT_NE(log.str().find("adopted_utime"), std::string::npos) << log.str();
  EXPECT_EQ(tryFile("preload_scale = 0.8\nadopted_utime = 1\nadopted_by = a\x01\n"), nullptr);
  EXPECT_NE(log.str().find("adopted_by"), std::string::npos) << log.str();
  EXPECT_EQ(tryFile("preload_scale = 0.8\npreload_scale = 0.9\nadopted_utime = 1\nadopted_by = a\n"), nullptr);
  EXPECT_NE(log.str().find("given twice"), std::string::npos) << log.str();
  EXPECT_EQ(tryFile("preload_scale = 0.1\nadopted_utime = 1\nadopted_by = a\n"), nullptr);
  EXPECT_NE(log.str().find("outside [0.3, 1.6]"), std::string::npos) << log.str();
  EXPECT_EQ(tryFile(std::string(100000, 'x')), nullptr) << "a file without newlines is refused by its size";
  EXPECT_NE(log.str().find("larger than 64 KiB"), std::string::npos) << log.str();
  EXPECT_NE(tryFile("# ok\npreload_scale = 0.8\nadopted_utime = 1\nadopted_by = a b\n"), nullptr) << log.str();
  // Without a state directory the adoption works and says it is not kept.
  TwinCore core(cfg, ClockMode::Input);
  Trip::feed(core, 0, cfg.shaft.l0);
  PreloadKeeper mem(cfg, "", "", capture(log), rtlog);
  EXPECT_EQ(mem.loadKept(), nullptr);
  ASSERT_TRUE(mem.request(0.9, "carol", kT0));
  mem.serve();
  mem.afterTick(core);
  EXPECT_EQ(core.preloadScale(), 0.9);
  EXPECT_NE(log.str().find("is not kept across a restart"), std::string::npos) << log.str();
}
