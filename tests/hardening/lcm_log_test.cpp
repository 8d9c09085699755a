// Hostile and damaged LCM log files.
//   * hoist::io::LcmLogReader: a header claiming datalen 0x7fffffff (or any
//     length beyond the file) allocates nothing and is skipped; a corrupted
//     event in the middle is skipped by resynchronising on the next sync
//     word, with the bytes skipped and events lost counted; a truncated tail;
//     garbage before the first event; sync words inside payloads.
//   * hoist-log2csv and hoist-replay --lcm-log on those files: alive, bounded
//     memory, exit 1 when anything was lost (0 with --lenient); the 70-byte
//     guide_shape_t event with a huge count (780 MB before); every output
//     file checked to the last byte (/dev/full -> exit 1, path, errno text).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "attack_bytes.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/forecast_t.hpp"
#include "hoist/trip_plan_t.hpp"
#include "hoist/io/lcm_log.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/winder_t.hpp"
#include "process.hpp"

namespace fs = std::filesystem;
namespace atk = hoist::test::attack;
using Bytes = std::vector<std::uint8_t>;
using hoist::test::runMeasured;

namespace {

fs::path workDir(const std::string& name) {
  const auto d = fs::path(HOIST_TEST_WORK_DIR) / "lcm_log" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeBytes(const fs::path& p, const Bytes& b) {
  std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

template <class M>
Bytes encode(const M& m) {
  Bytes b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

Bytes winderBytes(std::int64_t seq) {
  hoist::winder_t w{};
  w.utime = 1700000000000000 + seq * 10000;
  w.seq = seq;
  w.v = 1.0;
  w.has_length = 1;
  w.length = 100.0 + 0.01 * static_cast<double>(seq);
  return encode(w);
}

/// `n` winder events on HOIST_WINDER; offsets[i] = start of event i.
Bytes winderLog(int n, std::vector<std::size_t>* offsets = nullptr) {
  Bytes log;
  for (int i = 0; i < n; ++i) {
    if (offsets) offsets->push_back(log.size());
    const Bytes ev = atk::logEvent(i, 1000000 + i * 10000, "HOIST_WINDER", winderBytes(i));
    log.insert(log.end(), ev.begin(), ev.end());
  }
  return log;
}

struct ReadAll {
  std::vector<hoist::io::LcmLogEvent> events;
  hoist::io::LcmLogStats stats;
  bool ok = false;
};

ReadAll readAll(const fs::path& p) {
  hoist::io::LcmLogReader r(p.string());
  ReadAll out;
  hoist::io::LcmLogEvent ev;
  while (r.next(ev)) out.events.push_back(ev);
  out.stats = r.stats();
  out.ok = r.ok();
  return out;
}

int csvRows(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  int n = -1;  // header
  while (std::getline(in, line)) ++n;
  return n;
}

}  // namespace

TEST(LcmLogReader, CleanLogReadsEverything) {
  const auto d = workDir("clean");
  writeBytes(d / "a.lcmlog", winderLog(50));
  const auto r = readAll(d / "a.lcmlog");
  ASSERT_TRUE(r.ok);
  ASSERT_EQ(r.events.size(), 50u);
  EXPECT_FALSE(r.stats.lost());
  EXPECT_EQ(r.events[7].eventnum, 7);
  EXPECT_EQ(r.events[7].channel, "HOIST_WINDER");
  EXPECT_EQ(r.events[7].data, winderBytes(7));
  // An empty file: no events, nothing lost.
  writeBytes(d / "empty.lcmlog", {});
  const auto e = readAll(d / "empty.lcmlog");
  EXPECT_TRUE(e.ok);
  EXPECT_TRUE(e.events.empty());
  EXPECT_FALSE(e.stats.lost());
  // A missing file: an error naming it.
  hoist::io::LcmLogReader missing((d / "nope.lcmlog").string());
  EXPECT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("nope.lcmlog"), std::string::npos);
  EXPECT_NE(missing.error().find("No such file"), std::string::npos) << missing.error();
}

// The hostile event: datalen = 0x7fffffff (liblcm mallocs it and segfaults).
TEST(LcmLogReader, HugeDataLengthAllocatesNothingAndIsSkipped) {
  const auto d = workDir("huge");
  Bytes log = winderLog(10);
  const Bytes bad = atk::logEvent(10, 2000000, "HOIST_WINDER", winderBytes(10), 0x7fffffff);
  log.insert(log.end(), bad.begin(), bad.end());
  // then event 11 (event 10 is the bad one)
  for (int i = 11; i < 12; ++i) {
    const Bytes ev = atk::logEvent(i, 1000000 + i * 10000, "HOIST_WINDER", winderBytes(i));
    log.insert(log.end(), ev.begin(), ev.end());
  }
  writeBytes(d / "huge.lcmlog", log);
  const auto r = readAll(d / "huge.lcmlog");
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.events.size(), 11u);
  EXPECT_EQ(r.stats.regions, 1u);
  EXPECT_EQ(r.stats.events_lost, 1u);
  EXPECT_EQ(r.stats.bytes_skipped, bad.size());
  // Every length from the header variants: negative, past the end, over the cap.
  for (std::int64_t len : {0x80000000LL, 0xFFFFFFFFLL, 100000000LL, 1000LL}) {
    Bytes l2 = winderLog(3);
    const Bytes b2 = atk::logEvent(3, 0, "HOIST_WINDER", winderBytes(3), len);
    l2.insert(l2.end(), b2.begin(), b2.end());
    writeBytes(d / "len.lcmlog", l2);
    const auto r2 = readAll(d / "len.lcmlog");
    EXPECT_TRUE(r2.ok);
    EXPECT_EQ(r2.events.size(), 3u) << len;
    EXPECT_TRUE(r2.stats.lost()) << len;
  }
}

// A corrupted event in the middle: the rest of the log is still read.
TEST(LcmLogReader, CorruptedEventInTheMiddleResynchronises) {
  const auto d = workDir("middle");
  std::vector<std::size_t> off;
  Bytes log = winderLog(100, &off);
  const std::size_t ev_size = off[1] - off[0];
  // Event 50: channel length 0x7fff0000 (garbage header).
  log[off[50] + 20] = 0x7f;
  log[off[50] + 21] = 0xff;
  writeBytes(d / "mid.lcmlog", log);
  auto r = readAll(d / "mid.lcmlog");
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.events.size(), 99u);
  EXPECT_EQ(r.stats.events_lost, 1u);
  EXPECT_EQ(r.stats.bytes_skipped, ev_size);
  EXPECT_EQ(r.stats.first_bad_offset, off[50]);
  EXPECT_EQ(r.events[50].eventnum, 51);
  // Event 30's data length one byte short (it does not end at a sync word)
  // and 10 garbage bytes (with a false sync word) before event 70.
  log = winderLog(100, &off);
  log[off[30] + 27] -= 1;
  Bytes junk = {0xED, 0xA1, 0xDA, 0x01, 1, 2, 3, 4, 5, 6};
  log.insert(log.begin() + static_cast<long>(off[70]), junk.begin(), junk.end());
  writeBytes(d / "mid2.lcmlog", log);
  r = readAll(d / "mid2.lcmlog");
  EXPECT_EQ(r.events.size(), 99u);
  EXPECT_EQ(r.stats.regions, 2u);
  EXPECT_EQ(r.stats.bytes_skipped, ev_size + junk.size());
  // Truncated tail (logger killed mid-write) and garbage before the first event.
  log = winderLog(20, &off);
  log.resize(log.size() - 7);
  log.insert(log.begin(), {1, 2, 3});
  writeBytes(d / "tail.lcmlog", log);
  r = readAll(d / "tail.lcmlog");
  EXPECT_EQ(r.events.size(), 19u);
  EXPECT_EQ(r.stats.regions, 2u);
  EXPECT_EQ(r.stats.bytes_skipped, 3 + ev_size - 7);
}

// fuzz_lcmlog's finding: event numbers are the file's, any int64.  A jump
// from INT64_MIN + 1 to 5 across a corrupted region overflowed the signed
// gap (undefined behaviour; UBSan in the sanitizer pass); now one event lost.
TEST(LcmLogReader, ExtremeEventNumbersAcrossACorruptedRegion) {
  const auto d = workDir("eventnum");
  for (const auto& [a, b] : std::vector<std::pair<std::int64_t, std::int64_t>>{
           {INT64_MIN + 1, 5}, {-5, INT64_MAX}, {INT64_MIN, INT64_MAX}, {INT64_MAX - 1, INT64_MAX}}) {
    Bytes log = atk::logEvent(a, 1000000, "HOIST_WINDER", winderBytes(0));
    // A corrupted event between them (its data length points past the file).
    const Bytes junk = atk::logEvent(7, 1005000, "HOIST_WINDER", winderBytes(7), 0x7fffffff);
    log.insert(log.end(), junk.begin(), junk.end());
    const Bytes ev = atk::logEvent(b, 1010000, "HOIST_WINDER", winderBytes(1));
    log.insert(log.end(), ev.begin(), ev.end());
    writeBytes(d / "n.lcmlog", log);
    const auto r = readAll(d / "n.lcmlog");
    ASSERT_TRUE(r.ok) << a << " " << b;
    ASSERT_EQ(r.events.size(), 2u) << a << " " << b;
    EXPECT_EQ(r.events[0].eventnum, a);
    EXPECT_EQ(r.events[1].eventnum, b);
    EXPECT_EQ(r.stats.regions, 1u);
    EXPECT_EQ(r.stats.bytes_skipped, junk.size());
    // A gap of numbers that the skipped bytes cannot hold (or none): one event lost.
    EXPECT_EQ(r.stats.events_lost, 1u) << a << " " << b;
  }
}

// A sync word inside a payload is not taken for an event.
TEST(LcmLogReader, SyncWordInsidePayload) {
  const auto d = workDir("syncdata");
  Bytes log;
  Bytes payload = {0xED, 0xA1, 0xDA, 0x01, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 'X', 'Y'};
  for (int i = 0; i < 3; ++i) {
    const Bytes ev = atk::logEvent(i, i, "RAW", payload);
    log.insert(log.end(), ev.begin(), ev.end());
  }
  writeBytes(d / "s.lcmlog", log);
  const auto r = readAll(d / "s.lcmlog");
  EXPECT_EQ(r.events.size(), 3u);
  EXPECT_FALSE(r.stats.lost());
  EXPECT_EQ(r.events[2].data, payload);
}

// hoist-log2csv on the hostile files: alive, bounded memory, exit status.
TEST(Log2Csv, HostileLogsExitNonZeroWithBoundedMemory) {
  const auto d = workDir("log2csv");
  // (a) datalen 0x7fffffff in the middle.
  std::vector<std::size_t> off;
  Bytes log = winderLog(40, &off);
  const Bytes bad = atk::logEvent(40, 0, "HOIST_WINDER", winderBytes(40), 0x7fffffff);
  log.insert(log.begin() + static_cast<long>(off[20]), bad.begin(), bad.end());
  writeBytes(d / "huge.lcmlog", log);
  auto res = runMeasured({HOIST_LOG2CSV, (d / "huge.lcmlog").string(), "--out-dir", (d / "out1").string()},
                         (d / "huge.log").string());
  EXPECT_EQ(res.status, 1) << slurp(d / "huge.log");
  EXPECT_LT(res.max_rss_kb, 64 * 1024);
  EXPECT_EQ(csvRows(d / "out1" / "HOIST_WINDER.csv"), 40);
  EXPECT_NE(slurp(d / "huge.log").find("1 corrupt region"), std::string::npos) << slurp(d / "huge.log");
  res = runMeasured({HOIST_LOG2CSV, (d / "huge.lcmlog").string(), "--out-dir", (d / "out1l").string(), "--lenient"},
                    (d / "huge_l.log").string());
  EXPECT_EQ(res.status, 0) << slurp(d / "huge_l.log");

  // (b) the 70-byte guide_shape_t event with count 0x7fffffff (and -1).
  Bytes shape_log;
  for (std::int32_t n : {0x7fffffff, -1, 100001}) {
    const Bytes ev = atk::logEvent(0, 0, "HOIST_GUIDE_SHAPE", atk::guideShapeCount(n));
    ASSERT_EQ(ev.size(), 28u + 17u + 44u);  // header, "HOIST_GUIDE_SHAPE", the 44-byte payload
    shape_log.insert(shape_log.end(), ev.begin(), ev.end());
  }
  const Bytes h = atk::logEvent(1, 0, "HOIST_HEALTH", atk::healthCount(0x7fffffff));
  shape_log.insert(shape_log.end(), h.begin(), h.end());
  writeBytes(d / "shape.lcmlog", shape_log);
  res = runMeasured({HOIST_LOG2CSV, (d / "shape.lcmlog").string(), "--out-dir", (d / "out2").string()},
                    (d / "shape.log").string());
  EXPECT_EQ(res.status, 1) << slurp(d / "shape.log");
  EXPECT_LT(res.max_rss_kb, 64 * 1024) << "was 780 MB before the checked decoder";
  EXPECT_NE(slurp(d / "shape.log").find("bad_count"), std::string::npos) << slurp(d / "shape.log");

  // (c) a clean log: exit 0.
  writeBytes(d / "clean.lcmlog", winderLog(5));
  res = runMeasured({HOIST_LOG2CSV, (d / "clean.lcmlog").string(), "--out-dir", (d / "out3").string()},
                    (d / "clean.log").string());
  EXPECT_EQ(res.status, 0) << slurp(d / "clean.log");
  EXPECT_EQ(csvRows(d / "out3" / "HOIST_WINDER.csv"), 5);
}

// A full disk: every file is checked to its last byte.
TEST(Log2Csv, FullDiskIsAnErrorNamingTheFile) {
  // The full disk: a 16 KiB file size limit (600 rows are about 40 kB);
  // hoist-log2csv refuses to write to /dev/full itself (a device node).
  const auto d = workDir("full");
  writeBytes(d / "a.lcmlog", winderLog(600));
  fs::create_directories(d / "out");
  const auto res = hoist::test::runCapturedWithFileSizeLimit(
      HOIST_LOG2CSV, {(d / "a.lcmlog").string(), "--out-dir", (d / "out").string()}, 16);
  const std::string& out = res.output;
  EXPECT_EQ(res.status, 1) << out;
  EXPECT_NE(out.find("HOIST_WINDER.csv"), std::string::npos) << out;
  EXPECT_NE(out.find("File too large"), std::string::npos) << out;
  EXPECT_EQ(out.find("600 rows"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(d / "out" / "HOIST_WINDER.csv")) << "a short file left behind";
  if (fs::exists("/dev/full")) {
    fs::create_symlink("/dev/full", d / "out" / "HOIST_WINDER.csv");
    const auto dev = hoist::test::runCaptured(HOIST_LOG2CSV, {(d / "a.lcmlog").string(), "--out-dir", (d / "out").string()});
    EXPECT_EQ(dev.status, 1) << dev.output;
    EXPECT_NE(dev.output.find("a symbolic link"), std::string::npos) << dev.output;
  }
}

// HOIST_FORECAST (nested forecast_scenario_t) to CSV -- one row
// per scenario in HOIST_FORECAST.csv, the series in HOIST_FORECAST.series.csv;
// HOIST_TRIP_PLAN; HOIST_CAGE's appended threshold columns; a forecast with a
// lying nested count is rejected by the checked decoder (exit 1, bad_count).
TEST(Log2Csv, ForecastOneRowPerScenarioAndTheSeries) {
  const auto d = workDir("forecast");
  hoist::forecast_t f{};
  f.utime = 1700000000000000;
  f.seq = 3;
  f.instance_id = 77;
  f.t_start = 20.0;
  f.l = 150.0;
  f.v = 5.0;
  f.plan_seq = 9;
  f.compute_time = 0.012;
  f.num_scenarios = 2;
  f.scenarios.resize(2);
  const char* names[] = {"estop", "con,\"tinue\""};
  for (int k = 0; k < 2; ++k) {
    auto& sc = f.scenarios[static_cast<std::size_t>(k)];
    sc.name = names[k];
    sc.horizon = sc.t_reached = 20.0;
    sc.min_clearance = 0.05 - 0.01 * k;
    sc.t_min_clearance = 4.0 + k;
    sc.t_warning = k == 0 ? -1.0 : 2.5;
    sc.t_critical = -1.0;
    sc.peak_lambdas[3] = 31.25;
    sc.lambda0_min = 2400.0;
    sc.lambda0_max = 15000.0;
    sc.num_points = static_cast<std::int16_t>(k == 0 ? 3 : 2);
    for (int i = 0; i < sc.num_points; ++i) {
      sc.series_t.push_back(i + 1.0);
      sc.series_min_clearance.push_back(0.05);
      sc.series_lambda0_min.push_back(8000.0);
      sc.series_lambda0_max.push_back(9000.0 + i);
    }
  }
  hoist::trip_plan_t plan{};
  plan.utime = 5;
  plan.seq = 9;
  plan.target_length = 300.0;
  plan.vmax = 5.0;
  plan.amax = 1.0;
  plan.jerk = 0.5;
  plan.sender_id = 42;
  hoist::cage_state_t cage{};
  cage.rope_slack_threshold = 4424.0;
  cage.rope_overload_threshold = 13272.0;
  Bytes log;
  auto add = [&](const Bytes& ev) { log.insert(log.end(), ev.begin(), ev.end()); };
  add(atk::logEvent(0, 1000000, "HOIST_FORECAST", encode(f)));
  add(atk::logEvent(1, 1000001, "HOIST_TRIP_PLAN", encode(plan)));
  add(atk::logEvent(2, 1000002, "HOIST_CAGE", encode(cage)));
  f.seq = 4;
  add(atk::logEvent(3, 1000003, "HOIST_FORECAST", encode(f)));
  writeBytes(d / "f.lcmlog", log);
  auto res = runMeasured({HOIST_LOG2CSV, (d / "f.lcmlog").string(), "--out-dir", (d / "out").string()},
                         (d / "f.log").string());
  ASSERT_EQ(res.status, 0) << slurp(d / "f.log");
  const std::string csv = slurp(d / "out" / "HOIST_FORECAST.csv");
  EXPECT_EQ(csvRows(d / "out" / "HOIST_FORECAST.csv"), 4) << csv;  // 2 messages x 2 scenarios
  EXPECT_EQ(csv.rfind("utime,seq,instance_id,t_start,l,v,a,plan_seq,compute_time,scenario,from_estimate,Fa,moment,name,status,horizon,"
                      "t_reached,min_clearance,t_min_clearance,t_warning,t_critical,peak_y_c,peak_theta,"
                      "peak_lambda_1,peak_lambda_2,peak_lambda_3,peak_lambda_4,lambda0_min,lambda0_max,num_points\n",
                      0),
            0u)
      << csv;
  EXPECT_NE(csv.find("1700000000000000,3,77,20,150,5,0,9,0.012,0,0,0,0,\"estop\",0,20,20,0.050000000000000003,4,-1,-1,0,0,"
                     "0,0,0,31.25,2400,15000,3\n"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find(",1,0,0,0,\"con,\"\"tinue\"\"\",0,20,20,"), std::string::npos) << csv;  // quoted name
  const std::string series = slurp(d / "out" / "HOIST_FORECAST.series.csv");
  EXPECT_EQ(csvRows(d / "out" / "HOIST_FORECAST.series.csv"), 10) << series;  // 2 x (3 + 2)
  EXPECT_NE(series.find("utime,seq,scenario,name,i,t,min_clearance,lambda0_min,lambda0_max\n"), std::string::npos);
  EXPECT_NE(series.find("1700000000000000,4,1,\"con,\"\"tinue\"\"\",1,2,0.050000000000000003,8000,9001\n"),
            std::string::npos)
      << series;
  EXPECT_NE(slurp(d / "out" / "HOIST_TRIP_PLAN.csv").find("5,9,300,5,1,0.5,42\n"), std::string::npos);
  const std::string c = slurp(d / "out" / "HOIST_CAGE.csv");
  EXPECT_NE(c.find(",alarm_level,degraded,rope_slack_threshold,rope_overload_threshold\n"), std::string::npos) << c;
  EXPECT_NE(c.find(",0,0,4424,13272\n"), std::string::npos) << c;

  // A forecast whose second scenario claims 30000 points: bad_count, no row, exit 1.
  Bytes b = encode(f);
  const std::size_t np2 = 8 + 9 * 8 + 1 + (4 + 6 + 1 + 112 + 2 + 3 * 32) + 4 + 12 + 1 + 112;
  ASSERT_EQ(b[np2 + 1], 2);
  b[np2] = 0x75;
  b[np2 + 1] = 0x30;
  writeBytes(d / "bad.lcmlog", atk::logEvent(0, 0, "HOIST_FORECAST", b));
  res = runMeasured({HOIST_LOG2CSV, (d / "bad.lcmlog").string(), "--out-dir", (d / "out2").string()},
                    (d / "bad.log").string());
  EXPECT_EQ(res.status, 1) << slurp(d / "bad.log");
  EXPECT_NE(slurp(d / "bad.log").find("bad_count"), std::string::npos) << slurp(d / "bad.log");
  EXPECT_FALSE(fs::exists(d / "out2" / "HOIST_FORECAST.csv"));
}

// hoist-replay --lcm-log: the same log classes (publishing to memq://).
TEST(ReplayLcmLog, HostileLogsExitNonZeroWithBoundedMemory) {
  const auto d = workDir("replay");
  std::vector<std::size_t> off;
  Bytes log = winderLog(30, &off);
  const Bytes bad = atk::logEvent(30, 0, "HOIST_WINDER", winderBytes(30), 0x7fffffff);
  log.insert(log.begin() + static_cast<long>(off[10]), bad.begin(), bad.end());
  writeBytes(d / "huge.lcmlog", log);
  auto res = runMeasured({HOIST_REPLAY, "--lcm-log", (d / "huge.lcmlog").string(), "--lcm-url", "memq://",
                          "--speed", "0", "-q"},
                         (d / "huge.log").string());
  EXPECT_EQ(res.status, 1) << slurp(d / "huge.log");
  EXPECT_LT(res.max_rss_kb, 64 * 1024);
  EXPECT_NE(slurp(d / "huge.log").find("corrupt region"), std::string::npos) << slurp(d / "huge.log");
  res = runMeasured({HOIST_REPLAY, "--lcm-log", (d / "huge.lcmlog").string(), "--lcm-url", "memq://", "--speed",
                     "0", "-q", "--lenient"},
                    (d / "huge_l.log").string());
  EXPECT_EQ(res.status, 0) << slurp(d / "huge_l.log");
  // An undecodable payload on HOIST_WINDER (a 37-byte alarm_ack_t) is not sent.
  Bytes l2 = winderLog(3);
  const Bytes ack = atk::logEvent(3, 0, "HOIST_WINDER", atk::alarmAckStringLen(0));
  l2.insert(l2.end(), ack.begin(), ack.end());
  writeBytes(d / "ack.lcmlog", l2);
  res = runMeasured({HOIST_REPLAY, "--lcm-log", (d / "ack.lcmlog").string(), "--lcm-url", "memq://", "--speed",
                     "0"},
                    (d / "ack.log").string());
  EXPECT_EQ(res.status, 1) << slurp(d / "ack.log");
  EXPECT_NE(slurp(d / "ack.log").find("bad_fingerprint"), std::string::npos) << slurp(d / "ack.log");
  EXPECT_NE(slurp(d / "ack.log").find("published 3 messages"), std::string::npos) << slurp(d / "ack.log");
}
