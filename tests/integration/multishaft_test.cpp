// hoist-twind hosting several shafts in one process (one io_context), through
// real LCM (loopback multicast, ttl=0, ports 7812-7815):
//   * each shaft follows its own winder channel and publishes on its own
//     prefix; an input for one shaft does not move the other;
//   * alarms are per shaft (small gaps on one shaft only);
//   * different step rates coexist (one schedule per rate);
//   * the run report lists every shaft with step/lateness histograms;
//   * conflicting configurations are refused naming the key (exit 2).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "lcm_fixtures.hpp"
#include "lcm_messages.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/winder_t.hpp"

using namespace hoist::test;
namespace fs = std::filesystem;

namespace {

std::string writeConfig(const fs::path& dir, const std::string& name, const std::string& body) {
  const auto path = (dir / name).string();
  std::ofstream(path) << body;
  return path;
}

int runTwind(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv{HOIST_TWIND};
  argv.insert(argv.end(), args.begin(), args.end());
  Process p(argv, log.string());
  return p.wait(10s);
}

std::int64_t nowUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

TEST(MultiShaft, ThreeShaftsOneProcessOwnChannelsAlarmsAndRates) {
  const std::string url = urlFor(7812);
  const fs::path dir = testDir("multishaft");
  std::string why;
  if (!loopbackMulticastWorks(url, why)) FAIL() << why << ".\n" << kMulticastHelp;
  // north: 100 Hz, normal gaps; south: 200 Hz, tiny gaps (alarms); east: 100 Hz, n = 20.
  const auto north = writeConfig(dir, "north.toml", "[service]\nchannel_prefix = \"north/\"\n");
  const auto south = writeConfig(dir, "south.toml",
                                 "[service]\nchannel_prefix = \"south/\"\nrate = 200.0\n"
                                 "[alarms]\ngap_pos_y = 1e-5\ngap_neg_y = 1e-5\nguide_rope_gap = 1e-5\n"
                                 "on_delay = 0.0\n");
  const auto east = writeConfig(dir, "east.toml", "[model]\nmodes = 20\n[service]\nchannel_prefix = \"east/\"\n");
  const auto report = (dir / "report.json").string();

  Listener listener(url);
  ASSERT_TRUE(listener.good());
  listener.subscribe(".*HOIST_(CAGE|HEALTH|ALARM)");
  Process d({HOIST_TWIND, "--lcm-url", url, "--config", north, "--config", south, "--config", east,
             "--report", report},
            (dir / "twind.log").string());
  ASSERT_TRUE(d.started());
  ASSERT_TRUE(listener.waitFor([&] {
    return listener.count("north/HOIST_HEALTH") && listener.count("south/HOIST_HEALTH") &&
           listener.count("east/HOIST_HEALTH");
  }, 10s)) << readFile((dir / "twind.log").string());
  listener.pump(200ms);

  // Feed south and east for 2 s at 100 Hz; south descends at 2 m/s from 100 m,
  // east holds at 150 m; north gets nothing.
  const std::int64_t u0 = nowUs();
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < 200; ++k) {
    const auto ms = winder(k, u0 + 10000 * k, 2.0, 100.0 + 0.02 * k);
    const auto me = winder(k, u0 + 10000 * k, 0.0, 150.0);
    listener.lcm().publish("south/HOIST_WINDER", &ms);
    listener.lcm().publish("east/HOIST_WINDER", &me);
    const auto due = t0 + std::chrono::milliseconds(10 * (k + 1));
    listener.waitFor([&] { return std::chrono::steady_clock::now() >= due; }, 20ms);
  }
  listener.pump(1500ms);
  d.signal(SIGTERM);
  ASSERT_EQ(d.wait(10s), 0) << readFile((dir / "twind.log").string());
  listener.pump(100ms);

  const auto south_cage = listener.decoded<hoist::cage_state_t>("south/HOIST_CAGE");
  const auto east_cage = listener.decoded<hoist::cage_state_t>("east/HOIST_CAGE");
  EXPECT_EQ(listener.count("north/HOIST_CAGE"), 0u) << "north had no input: no cage output";
  ASSERT_GT(south_cage.size(), 300u);  // 200 Hz for about 2 s
  ASSERT_GT(east_cage.size(), 150u);   // 100 Hz for about 2 s
  // The wall-clock twin extrapolates with v until the input is declared stale
  // (3 input periods: 0.06 m at 2 m/s), then holds.
  EXPECT_NEAR(south_cage.back().l, 100.0 + 0.02 * 199 + 0.03, 0.05);
  EXPECT_NEAR(east_cage.back().l, 150.0, 1e-9);
  // The 200 Hz shaft publishes about twice as often as the 100 Hz one.
  const double ratio = static_cast<double>(south_cage.size()) / static_cast<double>(east_cage.size());
  EXPECT_GT(ratio, 1.6);
  EXPECT_LT(ratio, 2.4);
  for (const auto& c : south_cage) EXPECT_TRUE(std::isfinite(c.y_c) && std::isfinite(c.min_clearance));

  // Alarms: clearance alarms only on south (north and east have the paper's
  // gaps; north is INPUT_STALE-free only if it never had input: it idles).
  auto clearanceAlarms = [&](const std::string& prefix) {
    int n = 0;
    for (const auto& a : listener.decoded<hoist::alarm_t>(prefix + "HOIST_ALARM"))
      if (a.kind == "CAGE_POS_Y" || a.kind == "CAGE_NEG_Y" || a.kind == "GUIDE_ROPE") ++n;
    return n;
  };
  EXPECT_GT(clearanceAlarms("south/"), 0);
  EXPECT_EQ(clearanceAlarms("east/"), 0);
  EXPECT_EQ(clearanceAlarms("north/"), 0);

  // Per-shaft health counts only that shaft's input.
  const auto hs = listener.decoded<hoist::health_t>("south/HOIST_HEALTH");
  const auto hn = listener.decoded<hoist::health_t>("north/HOIST_HEALTH");
  ASSERT_FALSE(hs.empty());
  ASSERT_FALSE(hn.empty());
  EXPECT_GE(hs.back().accepted, 190);
  EXPECT_EQ(hn.back().accepted, 0);
  EXPECT_DOUBLE_EQ(hs.back().rate, 200.0);

  // The run report names every shaft, with its whole-run histograms and its
  // final HOIST_HEALTH under health_t's names (one name per counter: the
  // report's own spellings of them are gone).
  const std::string r = readFile(report);
  for (const char* s : {"\"north/\"", "\"south/\"", "\"east/\"", "\"p999\"", "\"deadline_misses\"", "\"late_us\""})
    EXPECT_NE(r.find(s), std::string::npos) << s << " missing in\n" << r;
  for (const char* s : {"inputs_accepted", "nonfinite_withheld", "sequence_gaps", "rate_hz"})
    EXPECT_EQ(r.find(s), std::string::npos) << s << " in\n" << r;
  const auto j = nlohmann::json::parse(r);
  ASSERT_EQ(j["shafts"].size(), 3u) << r;
  std::map<std::string, nlohmann::json> by_label;
  for (const auto& s : j["shafts"]) by_label[s["label"].get<std::string>()] = s;
  ASSERT_EQ(by_label.count("south/"), 1u) << r;
  const auto& south_health = by_label["south/"]["health"];
  EXPECT_GE(south_health["accepted"].get<std::int64_t>(), hs.back().accepted) << "the final report counts every input";
  EXPECT_LE(south_health["accepted"].get<std::int64_t>(), 200);
  EXPECT_EQ(south_health["seq_gaps"].get<std::int64_t>(), hs.back().seq_gaps);
  EXPECT_DOUBLE_EQ(south_health["rate"].get<double>(), 200.0);
  EXPECT_EQ(south_health["reject_reason"].size(), static_cast<std::size_t>(hs.back().n_reasons));
  EXPECT_EQ(by_label["north/"]["health"]["accepted"].get<std::int64_t>(), 0);
  EXPECT_GE(by_label["south/"]["step_us"]["count"].get<std::int64_t>(), 190) << "whole-run histogram";
  const std::string log = readFile((dir / "twind.log").string());
  EXPECT_NE(log.find("3 shafts on one loop, 2 schedule(s)"), std::string::npos) << log;
  EXPECT_NE(log.find("[south/] final health"), std::string::npos) << log;
  EXPECT_NE(log.find("] [south/] hoist-twind shaft: clock=wall rate=200 Hz"), std::string::npos) << log;
}

TEST(MultiShaft, ConflictingConfigurationsAreRefusedNamingTheKey) {
  const fs::path dir = testDir("multishaft_bad");
  const auto a = writeConfig(dir, "a.toml", "[service]\nchannel_prefix = \"A/\"\n");
  const auto a2 = writeConfig(dir, "a2.toml", "[service]\nchannel_prefix = \"A/\"\n");
  const auto b = writeConfig(dir, "b.toml",
                             "[service]\nchannel_prefix = \"B/\"\nlcm_url = \"udpm://239.255.76.67:7813?ttl=0\"\n");
  const auto log = dir / "out.log";
  EXPECT_EQ(runTwind({"--config", a, "--config", a2, "--print-config"}, log), 2);
  EXPECT_NE(readFile(log.string()).find("service.channel_prefix"), std::string::npos) << readFile(log.string());
  fs::remove(log);
  EXPECT_EQ(runTwind({"--config", a, "--config", b, "--print-config"}, log), 2);
  EXPECT_NE(readFile(log.string()).find("service.lcm_url"), std::string::npos) << readFile(log.string());
  fs::remove(log);
  EXPECT_EQ(runTwind({"--config", a, "--config", b, "--channel-prefix", "X/", "--print-config"}, log), 2);
  EXPECT_NE(readFile(log.string()).find("--channel-prefix"), std::string::npos) << readFile(log.string());
  fs::remove(log);
  EXPECT_EQ(runTwind({"--cpus", "99999", "--print-config"}, log), 2);
  EXPECT_NE(readFile(log.string()).find("--cpus"), std::string::npos) << readFile(log.string());
  fs::remove(log);
  // With --lcm-url the differing [service].lcm_url is overridden: accepted.
  EXPECT_EQ(runTwind({"--config", a, "--config", b, "--lcm-url", "udpm://239.255.76.67:7814?ttl=0", "--print-config"}, log), 0)
      << readFile(log.string());
}

TEST(MultiShaft, RealtimeSettingsAreReportedAndNeverFatal) {
  // Whatever this machine grants (root in a container, an unprivileged user),
  // the daemon starts, says what it got, and runs.
  const std::string url = urlFor(7815);
  const fs::path dir = testDir("multishaft_rt");
  std::string why;
  if (!loopbackMulticastWorks(url, why)) FAIL() << why << ".\n" << kMulticastHelp;
  const auto report = (dir / "report.json").string();
  const auto log = dir / "twind.log";
  std::vector<std::string> args{"--lcm-url", url, "--duration", "1", "--rt-priority", "10", "--cpus", "0",
                                 "--report", report};
#ifndef HOIST_SANITIZED
  // Not under the sanitizers: mlockall would try to lock their terabyte-sized
  // shadow mappings.
  args.push_back("--mlockall");
#endif
  EXPECT_EQ(runTwind(args, log), 0) << readFile(log.string());
  const std::string l = readFile(log.string());
  EXPECT_NE(l.find("real-time settings: memory lock: "), std::string::npos) << l;
  const std::string r = readFile(report);
  EXPECT_NE(r.find("\"memory_lock\""), std::string::npos) << r;
  EXPECT_NE(r.find("\"scheduling\""), std::string::npos) << r;
  EXPECT_NE(r.find("\"affinity\""), std::string::npos) << r;
}
