// hoist-timing-test (and its alias hoist-replay --timing-test) against a real hoist-twind through real LCM (UDP
// multicast on loopback, ttl=0, one port per test, 7790-7795):
//
//   * generous budgets: PASS (exit 0), the report shows deadline misses and
//     the end-to-end latency;
//   * an impossible budget: FAIL (exit 1), the report names the budget;
//   * no daemon: FAIL within ~7 s with the "is hoist-twind running" message;
//   * bad options: exit 2 naming the option (no LCM traffic needed);
//   * two shafts (two daemons, prefixes shaft1/ and shaft2/): per-shaft lines;
//   * Ctrl-C: a shortened run is still reported (exit 130).
// The verdict rules without LCM: timing_report_test.cpp.
#include <gtest/gtest.h>

#include <iostream>
#include <regex>

#include "lcm_fixtures.hpp"

using namespace hoist::test;
namespace fs = std::filesystem;

namespace {

std::string firstLine(const std::string& s) { return s.substr(0, s.find('\n')); }

class TimingTest : public LcmProcessTest {
 protected:

  /// A daemon on prefix `prefix`, up (its first HOIST_HEALTH heard).
  std::unique_ptr<Process> startDaemon(const std::string& prefix, const std::string& log_name) {
    listener_->subscribe(prefix + "HOIST_HEALTH");
    std::vector<std::string> argv{HOIST_TWIND, "--lcm-url", url_, "--log-level", "warn", "--rate", "100"};
    if (!prefix.empty()) {
      argv.push_back("--channel-prefix");
      argv.push_back(prefix);
    }
    return startDaemonAndWait(*listener_, argv, (dir_ / log_name).string(), prefix + "HOIST_HEALTH");
  }

  void stopDaemon(Process& p, const std::string& log_name) {
    EXPECT_TRUE(p.running()) << "hoist-twind died during the test:\n" << readFile((dir_ / log_name).string());
    stopDaemonCleanly(p, (dir_ / log_name).string());
  }

  /// hoist-timing-test with `extra` (`alias`: as hoist-replay --timing-test);
  /// returns the exit status, the combined output in `out` and the wall time
  /// in `secs`.
  int timingTest(std::vector<std::string> extra, std::string& out, double& secs,
                 std::chrono::milliseconds timeout = 30s, bool alias = false) {
    std::vector<std::string> argv{HOIST_TIMING_TEST, "--lcm-url", url_, "-q"};
    if (alias) argv = {HOIST_REPLAY, "--timing-test", "--lcm-url", url_, "-q"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    const auto log = (dir_ / "replay.log").string();
    std::filesystem::remove(log);
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = runProcess(argv, log, timeout);
    secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    out = readFile(log);
    return rc;
  }

};

}  // namespace

TEST_F(TimingTest, GenerousBudgetsPass) {
  start(7790, "timing_pass");
  auto d = startDaemon("", "twind.log");
  const auto report = (dir_ / "timing.md").string();
  std::string out;
  double secs = 0;
  // Generous for a loaded 2-core CI machine; rejected inputs stay at 0.  Fed
  // at 25 Hz (a 40-ms period): a feeder woken 10-15 ms late by a busy machine
  // (seen under ASan) is still on time, so the verdict can be PASS.  The one
  // verdict that is not the daemon's is INCONCLUSIVE because this test's own
  // feeder was late (seen once under TSan on a loaded CI machine: two
  // wake-ups 55 ms late out of 99): that run is repeated, at most twice; any
  // other verdict is judged as it comes.
  int rc = 0;
  std::string r;
  for (int attempt = 1; attempt <= 3; ++attempt) {
    rc = timingTest({"--rate", "25", "--duration", "4", "--max-misses", "1000", "--max-late-p99-us", "1e6",
                     "--max-step-p99-us", "1e6", "--max-e2e-p99-us", "1e6", "--report", report},
                    out, secs);
    r = readFile(report);
    if (firstLine(r) != "VERDICT: INCONCLUSIVE" || r.find("The feeder itself was late") == std::string::npos) break;
    std::cerr << "attempt " << attempt << ": the feeder was late (a busy machine), so INCONCLUSIVE; again\n";
  }
  stopDaemon(*d, "twind.log");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(firstLine(r), "VERDICT: PASS") << r;
  EXPECT_NE(r.find("| deadline misses | "), std::string::npos) << r;
  EXPECT_NE(r.find("| rejected inputs | 0 | <= 0 | ok |"), std::string::npos) << r;
  // The end-to-end latency was measured (a number, not n/a) and is positive.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r, m, std::regex(R"(\| end-to-end latency p99 \[us\] \| ([0-9.]+) \| <= 1000000 \| ok \|)")))
      << r;
  EXPECT_GT(std::stod(m[1].str()), 0.0);
  EXPECT_NE(r.find("| end-to-end latency p99.9 [us] | "), std::string::npos);
  EXPECT_NE(r.find("| host | "), std::string::npos);
  EXPECT_NE(r.find("| rate | 25 Hz"), std::string::npos) << r;
  EXPECT_NE(r.find("| duration | 4 s"), std::string::npos);
  EXPECT_NE(r.find("hoist-timing-test --lcm-url"), std::string::npos) << "the command is in the report";
  EXPECT_NE(r.find("## Violated budgets\n\nnone"), std::string::npos) << r;
  // About 100 inputs sent (4 s at 25 Hz; the feeder may skip a period under load), nearly all accepted.
  ASSERT_TRUE(std::regex_search(r, m, std::regex(R"(\| inputs sent / accepted / lost \| (\d+) / (\d+) / (-?\d+) \|)")))
      << r;
  EXPECT_GE(std::stoi(m[1].str()), 97);
  EXPECT_LE(std::stoi(m[1].str()), 100);
  EXPECT_GE(std::stoi(m[2].str()), std::stoi(m[1].str()) - 5);
  // The summary is printed too.
  EXPECT_NE(out.find("VERDICT: PASS"), std::string::npos) << out;
  EXPECT_LT(secs, 10.0);
}

TEST_F(TimingTest, ImpossibleBudgetFails) {
  start(7791, "timing_fail");
  auto d = startDaemon("", "twind.log");
  const auto report = (dir_ / "timing.md").string();
  std::string out;
  double secs = 0;
  const int rc = timingTest({"--duration", "2", "--max-misses", "1000", "--max-step-p99-us", "0.001", "--report", report},
                            out, secs);
  stopDaemon(*d, "twind.log");
  const std::string r = readFile(report);
  EXPECT_EQ(rc, 1) << out;
  EXPECT_EQ(firstLine(r), "VERDICT: FAIL") << r;
  const auto violated = r.find("## Violated budgets");
  ASSERT_NE(violated, std::string::npos) << r;
  const std::string tail = r.substr(violated);
  EXPECT_NE(tail.find("- model step time p99, worst window (--max-step-p99-us): measured "), std::string::npos) << r;
  EXPECT_NE(tail.find("> allowed 0.001 us"), std::string::npos) << r;
  EXPECT_EQ(tail.find("--max-misses"), std::string::npos) << "only the violated budget is listed:\n" << r;
  EXPECT_NE(r.find("**FAIL**"), std::string::npos) << r;
  EXPECT_LT(secs, 10.0);
}

TEST_F(TimingTest, NoDaemonFailsWithinSevenSeconds) {
  // Through the alias hoist-replay --timing-test: the same run, the same report.
  start(7792, "timing_nodaemon");
  const auto report = (dir_ / "timing.md").string();
  std::string out;
  double secs = 0;
  const int rc = timingTest({"--duration", "4", "--report", report}, out, secs, 15s, true);
  EXPECT_EQ(rc, 1) << out;
  EXPECT_LT(secs, 7.0);
  EXPECT_GE(secs, 4.5);
  EXPECT_NE(out.find("no HOIST_HEALTH on HOIST_HEALTH within 5 s: is hoist-twind running with the same --lcm-url "
                     "and channel prefix?"),
            std::string::npos)
      << out;
  const std::string r = readFile(report);
  EXPECT_EQ(firstLine(r), "VERDICT: FAIL") << r;
  EXPECT_NE(r.find("no HOIST_HEALTH on HOIST_HEALTH within 5 s"), std::string::npos) << r;
  EXPECT_NE(r.find("hoist-replay --timing-test --lcm-url"), std::string::npos) << r;
}

TEST_F(TimingTest, BadOptionsExitTwoNamingTheOption) {
  url_ = urlFor(7793);
  dir_ = testDir("timing_badopts");
  struct Case {
    std::vector<std::string> args;
    std::string option;
  };
  const std::vector<Case> cases = {
      {{"--rate", "0"}, "--rate"},
      {{"--rate", "2000"}, "--rate"},
      {{"--max-misses", "-1"}, "--max-misses"},
      {{"--max-rejected", "-3"}, "--max-rejected"},
      {{"--max-late-p99-us", "-5"}, "--max-late-p99-us"},
      {{"--max-e2e-p99-us", "abc"}, "--max-e2e-p99-us"},
      {{"--duration", "0"}, "--duration"},
      {{"--shafts", "0"}, "--shafts"},
      {{"--shafts", "2", "--channel-prefix", "a/"}, "--channel-prefix"},
      {{"--profile", "paper"}, "--profile"},
      {{"--channel-prefix", "a/", "--channel-prefix", "a/"}, "--channel-prefix"},
      {{"--report", "/nonexistent-dir/x.md"}, "--report"},
  };
  for (const auto& c : cases) {
    std::string out;
    double secs = 0;
    EXPECT_EQ(timingTest(c.args, out, secs, 10s), 2) << c.args[0] << ": " << out;
    EXPECT_NE(out.find(c.option), std::string::npos) << c.args[0] << ": " << out;
    EXPECT_LT(secs, 3.0) << c.args[0];
    // The alias hoist-replay --timing-test takes the same options.
    EXPECT_EQ(timingTest(c.args, out, secs, 10s, true), 2) << "alias " << c.args[0] << ": " << out;
    EXPECT_NE(out.find(c.option), std::string::npos) << "alias " << c.args[0] << ": " << out;
  }
  // Budgets belong to the timing test.
  const auto log = (dir_ / "plain.log").string();
  EXPECT_EQ(runProcess({HOIST_REPLAY, "--lcm-url", url_, "--max-misses", "3"}, log, 10s), 2);
  EXPECT_NE(readFile(log).find("--max-misses requires --timing-test"), std::string::npos) << readFile(log);
}

TEST_F(TimingTest, TwoShaftsAreFedAndReportedPerShaft) {
  start(7794, "timing_shafts");
  auto d1 = startDaemon("shaft1/", "twind1.log");
  auto d2 = startDaemon("shaft2/", "twind2.log");
  const auto report = (dir_ / "timing.md").string();
  std::string out;
  double secs = 0;
  const int rc = timingTest({"--shafts", "2", "--duration", "2", "--max-misses", "1000", "--report", report}, out, secs);
  stopDaemon(*d1, "twind1.log");
  stopDaemon(*d2, "twind2.log");
  const std::string r = readFile(report);
  // PASS, or INCONCLUSIVE when (and only when) this loaded 2-core machine
  // made the test's own feeder late (ctest runs two tests at once; seen
  // once: feeder p99 11.9 ms at 100 Hz): the per-shaft report is still
  // checked.  A FAIL verdict, or INCONCLUSIVE for another reason, fails.
  if (firstLine(r) == "VERDICT: INCONCLUSIVE" && r.find("The feeder itself was late") != std::string::npos) {
    EXPECT_EQ(rc, 1) << out;
  } else {
    EXPECT_EQ(rc, 0) << out;
    EXPECT_EQ(firstLine(r), "VERDICT: PASS") << r;
  }
  EXPECT_NE(r.find("| inputs sent / accepted / lost |"), std::string::npos) << r;
  EXPECT_NE(r.find("## Per shaft"), std::string::npos) << r;
  EXPECT_NE(r.find("| \"shaft1/\" | "), std::string::npos) << r;
  EXPECT_NE(r.find("| \"shaft2/\" | "), std::string::npos) << r;
  EXPECT_NE(r.find("| shafts | 2: prefixes \"shaft1/\", \"shaft2/\" |"), std::string::npos) << r;
  EXPECT_LT(secs, 10.0);
}

TEST_F(TimingTest, InterruptedRunIsReportedAsShortened) {
  start(7795, "timing_sigint");
  auto d = startDaemon("", "twind.log");
  const auto report = (dir_ / "timing.md").string();
  const auto log = (dir_ / "replay.log").string();
  Process p({HOIST_REPLAY, "--timing-test", "--lcm-url", url_, "-q", "--duration", "30", "--max-misses", "1000",
             "--report", report},
            log);
  ASSERT_TRUE(p.started());
  std::this_thread::sleep_for(2500ms);
  p.signal(SIGINT);
  EXPECT_EQ(p.wait(5s), 130) << readFile(log);
  stopDaemon(*d, "twind.log");
  const std::string r = readFile(report);
  EXPECT_EQ(firstLine(r).rfind("VERDICT: PASS (shortened run: stopped after ", 0), 0u) << r;
  EXPECT_NE(r.find("Shortened run: stopped by signal 2"), std::string::npos) << r;
}
