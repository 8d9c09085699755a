// The programs and files that are not theirs (hoist::io::CheckedFile in
// use), hoist-log2csv's channel names, hoist-replay's timestamp gaps and
// hoist-study's allocation-sizing options -- run as a user runs them.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <lcm/lcm-cpp.hpp>

#include "hoist/winder_t.hpp"
#include "process.hpp"

namespace fs = std::filesystem;
using hoist::test::readFile;
using hoist::test::runCaptured;
using hoist::test::testDir;

namespace {

std::vector<std::uint8_t> winderBytes(std::int64_t seq, std::int64_t utime) {
  hoist::winder_t m{};
  m.utime = utime;
  m.seq = seq;
  m.v = 1.0;
  std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

struct LogWriter {
  explicit LogWriter(const std::string& path) : log(path, "w") {}
  void put(const std::string& channel, std::int64_t ts, const std::vector<std::uint8_t>& data) {
    ::lcm::LogEvent ev;
    ev.timestamp = ts;
    ev.channel = channel;
    ev.datalen = static_cast<int32_t>(data.size());
    ev.data = const_cast<std::uint8_t*>(data.data());
    log.writeEvent(&ev);
  }
  ::lcm::LogFile log;
};

bool contains(const std::string& s, const std::string& what) { return s.find(what) != std::string::npos; }

}  // namespace

// ---- hoist-twind --report --------------------------------------------------
TEST(FilesNotOurs, DaemonReportOnAFifoIsRefusedAtStartUp) {
  const fs::path d = testDir("report_fifo");
  const fs::path fifo = d / "report.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto r = runCaptured(HOIST_TWIND, {"--lcm-url", "memq://", "--duration", "30", "--report", fifo.string()});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--report " + fifo.string())) << r.output;
  EXPECT_TRUE(contains(r.output, "a FIFO")) << r.output;
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
}

TEST(FilesNotOurs, DaemonReportInAMissingDirectoryIsRefusedAtStartUp) {
  const fs::path d = testDir("report_missing");
  const fs::path p = d / "no_such_dir" / "report.json";
  const auto t0 = std::chrono::steady_clock::now();
  // --duration 30: a late check would only report it when the daemon stops.
  const auto r = runCaptured(HOIST_TWIND, {"--lcm-url", "memq://", "--duration", "30", "--report", p.string()});
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--report")) << r.output;
  EXPECT_TRUE(contains(r.output, (d / "no_such_dir").string())) << r.output;
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(25));
}

TEST(FilesNotOurs, DaemonReportDoesNotFollowAPlantedTemporarySymlink) {
  const fs::path d = testDir("report_planted");
  const fs::path victim = d / "victim.txt";
  { std::ofstream(victim) << "precious\n"; }
  const fs::path p = d / "report.json";
  fs::create_symlink(victim, d / "report.json.tmp");
  const auto r = runCaptured(HOIST_TWIND, {"--lcm-url", "memq://", "--duration", "0.3", "--report", p.string()});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(readFile(victim.string()), "precious\n");
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(p)));
  EXPECT_TRUE(contains(readFile(p.string()), "\"shafts\"")) << readFile(p.string());
}

TEST(FilesNotOurs, SimAndLog2csvRefuseSpecialTargets) {
  const fs::path d = testDir("sim_fifo");
  const fs::path fifo = d / "out.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto r = runCaptured(HOIST_SIM, {"--profile", "paper", "--t-end", "1", "--out", fifo.string()});
  EXPECT_NE(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, fifo.string()) && contains(r.output, "a FIFO")) << r.output;
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  // hoist-log2csv: a symlink where a channel's CSV goes stays a symlink.
  const fs::path log = d / "one.lcmlog";
  {
    LogWriter w(log.string());
    w.put("HOIST_WINDER", 1'000'000, winderBytes(0, 1'700'000'000'000'000));
  }
  const fs::path out = d / "csv";
  fs::create_directories(out);
  const fs::path victim = d / "victim.txt";
  { std::ofstream(victim) << "precious\n"; }
  fs::create_symlink(victim, out / "HOIST_WINDER.csv");
  const auto c = runCaptured(HOIST_LOG2CSV, {log.string(), "--out-dir", out.string()});
  EXPECT_EQ(c.status, 1) << c.output;
  EXPECT_TRUE(contains(c.output, "a symbolic link")) << c.output;
  EXPECT_EQ(readFile(victim.string()), "precious\n");
}

// ---- hoist-log2csv: channels never merge ------------------------------------
TEST(Log2csv, ChannelsWhoseNamesSanitizeAlikeGetDistinctFiles) {
  const fs::path d = testDir("log2csv_merge");
  const fs::path log = d / "two.lcmlog";
  {
    LogWriter w(log.string());
    std::int64_t ts = 1'000'000;
    for (int i = 0; i < 3; ++i) w.put("a/HOIST_WINDER", ts += 10000, winderBytes(i, 1'700'000'000'000'000 + i));
    for (int i = 0; i < 5; ++i) w.put("a_HOIST_WINDER", ts += 10000, winderBytes(100 + i, 1'800'000'000'000'000 + i));
  }
  const fs::path out = d / "csv";
  const auto r = runCaptured(HOIST_LOG2CSV, {log.string(), "--out-dir", out.string()});
  EXPECT_EQ(r.status, 0) << r.output;
  // Both channels are named, each with its own file.
  EXPECT_TRUE(contains(r.output, "a/HOIST_WINDER") && contains(r.output, "a_HOIST_WINDER")) << r.output;
  std::vector<std::string> files;
  long rows = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    files.push_back(e.path().filename().string());
    const std::string text = readFile(e.path().string());
    std::istringstream lines(text);
    std::string line;
    std::getline(lines, line);
    EXPECT_EQ(line.rfind("utime,seq,", 0), 0u) << e.path() << ": " << line;
    long n = 0, low = 0;
    while (std::getline(lines, line)) {  // utime,seq,...: one channel per file, its seqs all < 100 or all >= 100
      const auto c1 = line.find(','), c2 = line.find(',', c1 + 1);
      low += std::stol(line.substr(c1 + 1, c2 - c1 - 1)) < 100 ? 1 : 0;
      ++n;
    }
    EXPECT_TRUE(low == 0 || low == n) << e.path() << ":\n" << text;
    EXPECT_EQ(n, low ? 3 : 5) << e.path();
    rows += n;
  }
  EXPECT_EQ(files.size(), 2u) << r.output;
  EXPECT_EQ(rows, 8);
}

// ---- hoist-replay: timestamp gaps -------------------------------------------
TEST(Replay, TimestampGapsAreReportedAndShortenedByMaxGap) {
  const fs::path d = testDir("replay_gaps");
  const fs::path log = d / "gaps.lcmlog";
  {
    LogWriter w(log.string());
    std::int64_t ts = 1'000'000, utime = 1'700'000'000'000'000, seq = 0;
    auto burst = [&] {
      for (int i = 0; i < 3; ++i) w.put("HOIST_WINDER", ts += 10000, winderBytes(seq++, utime += 10000));
    };
    burst();
    ts += 33'000'000;  // the gaps a corrupted log left: 33 s, 67 s, 10^15 us
    burst();
    ts += 67'000'000;
    burst();
    ts += 1'000'000'000'000'000;
    burst();
  }
  // At real-time speed: would sleep 31.7 years; --max-gap 0.05 plays each gap as 50 ms.
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = runCaptured(HOIST_REPLAY, {"--lcm-log", log.string(), "--lcm-url", "memq://", "--max-gap", "0.05"});
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(20));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "gap of 33.01 s")) << r.output;
  EXPECT_TRUE(contains(r.output, "gap of 67.01 s")) << r.output;
  EXPECT_TRUE(contains(r.output, "gap of 1e+09 s")) << r.output;
  EXPECT_TRUE(contains(r.output, "--max-gap 0.05")) << r.output;
  EXPECT_TRUE(contains(r.output, "published 12 messages")) << r.output;
  // The default (10 s) is said too, even as fast as possible.
  const auto q = runCaptured(HOIST_REPLAY, {"--lcm-log", log.string(), "--lcm-url", "memq://", "--speed", "0"});
  EXPECT_EQ(q.status, 0) << q.output;
  EXPECT_TRUE(contains(q.output, "gap of 33.01 s") && contains(q.output, "--max-gap 10")) << q.output;
  // A bad --max-gap is bad input.
  const auto b = runCaptured(HOIST_REPLAY, {"--lcm-log", log.string(), "--lcm-url", "memq://", "--max-gap", "-1"});
  EXPECT_EQ(b.status, 2) << b.output;
  EXPECT_TRUE(contains(b.output, "--max-gap")) << b.output;
}

// ---- hoist-study: options that size an allocation ---------------------------
TEST(Study, OptionsThatSizeAnAllocationAreBoundedAndNamed) {
  const fs::path d = testDir("study_dt");
  struct Case {
    std::vector<std::string> args;
    std::string names;
  };
  const std::vector<Case> cases = {
      {{"sweep", "--param", "cage.mass", "--values", "1000,1200", "--dt", "1e-9"}, "--dt"},
      {{"response", "--dt", "1e-9"}, "--dt"},
      {{"response", "--dt", "1e300"}, "--dt"},
      {{"advise", "--clearance", "0.01", "--dt", "1e-9"}, "--dt"},
      // In range, but 100 runs of 1e-5 s steps would hold 6e8 rows in memory.
      {{"sweep", "--param", "cage.mass", "--values", "1000:2000:100", "--dt", "1e-5"}, "--dt"},
      {{"sweep", "--param", "cage.mass", "--values", "1000:2000:100000"}, "--values"},
      {{"advise", "--clearance", "0.01", "--samples", "100000000"}, "--samples"},
      {{"response", "--modes", "100000000"}, "--modes"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = c.args;
    args.insert(args.end(), {"--out-dir", d.string(), "--no-plots"});
    const auto r = runCaptured(HOIST_STUDY, args);
    std::string cmd;
    for (const auto& a : c.args) cmd += a + " ";
    EXPECT_EQ(r.status, 2) << cmd << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, c.names)) << cmd << "\n" << r.output;
    EXPECT_FALSE(contains(r.output, "bad_alloc")) << cmd << "\n" << r.output;
  }
}
