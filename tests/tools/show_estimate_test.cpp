// The load estimate where people look (hoist-monitor, hoist-log2csv): the
// tests publish or log estimate_t themselves (no daemon), with realistic
// values: Fa 1502 +- 3 N, b 0.60 +- 0.01 m, theta 6.5e-4 rad, theta open
// loop 8.3e-4 rad.  hoist-monitor over UDP multicast on loopback (port 7840).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"
#include "lcm_fixtures.hpp"
#include "process.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using namespace hoist::test;

namespace {

hoist::estimate_t realisticEstimate(std::int64_t seq) {
  hoist::estimate_t e{};
  e.utime = 1'700'000'000'000'000 + seq * 10'000;
  e.seq = seq;
  e.instance_id = 77;
  e.t = 12.0 + 0.01 * static_cast<double>(seq);
  e.l = 150.25;
  e.v = 4.5;
  e.a = 0.0;
  e.Fa = 1502.4;
  e.sigma_Fa = 3.1;
  e.b = 0.601;
  e.sigma_b = 0.0102;
  e.moment = e.Fa * e.b;
  e.sigma_moment = 16.0;
  e.x_c = 0.012;
  e.sigma_x_c = 1e-4;
  e.y_c = 2.5e-3;
  e.sigma_y_c = 1.5e-4;
  e.theta = 6.5e-4;
  e.sigma_theta = 1.0e-5;
  e.theta_open = 8.3e-4;
  for (int i = 0; i < 5; ++i) {
    e.lambdas[i] = i == 0 ? 31000.0 : 40.0 + 10.0 * i;
    e.sigma_lambdas[i] = i == 0 ? 5.0 : 1.5 + 0.25 * i;
  }
  e.nis = 2.1;
  e.nis_dof = 300;
  e.nis_window = 306.0;  // 1.02 per dof
  e.nis_lower = 253.9;
  e.nis_upper = 349.9;
  e.nis_bound = 372.0;  // 1.24 per dof
  e.drift = 0.4;
  e.sensors = 7;  // SENSOR_IMU_ACCEL, SENSOR_IMU_RATE, SENSOR_ROPE_LOAD
  e.imu_age = 0.004;
  e.rope_load_age = 0.009;
  e.fa_observed = 1;
  e.moment_observed = 1;
  e.accepted = 1200 + seq;
  e.gated = 2;
  e.load_changes = 0;
  e.implausible = 1;
  return e;
}

std::vector<std::uint8_t> bytesOf(const hoist::estimate_t& e) {
  std::vector<std::uint8_t> b(static_cast<std::size_t>(e.getEncodedSize()));
  e.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  return out;
}

bool contains(const std::string& s, const std::string& what) { return s.find(what) != std::string::npos; }

}  // namespace

// ---- hoist-log2csv ------------------------------------------------------------
TEST(ShowEstimate, Log2csvWritesEveryEstimateField) {
  const fs::path d = testDir("show_estimate_log2csv");
  const fs::path log = d / "estimate.lcmlog";
  {
    ::lcm::LogFile lf(log.string(), "w");
    for (int i = 0; i < 4; ++i) {
      auto e = realisticEstimate(i);
      if (i == 3) {  // the rope load cell dropped out: Fa and b not observed
        e.sigma_Fa = -1.0;
        e.sigma_b = -1.0;
        e.mismatch = 1;
        e.nis_exceeded = 1;
        e.sensors = 3;  // the IMU only
      }
      const auto b = bytesOf(e);
      ::lcm::LogEvent ev;
      ev.timestamp = e.utime;
      ev.channel = "north/HOIST_ESTIMATE";
      ev.datalen = static_cast<int32_t>(b.size());
      ev.data = const_cast<std::uint8_t*>(b.data());
      lf.writeEvent(&ev);
    }
  }
  const fs::path out = d / "csv";
  const auto r = runCaptured(HOIST_LOG2CSV, {log.string(), "--out-dir", out.string()});
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "4 rows of hoist.estimate_t")) << r.output;
  EXPECT_FALSE(contains(r.output, "unknown type")) << r.output;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(out)) files.push_back(e.path());
  ASSERT_EQ(files.size(), 1u) << r.output;
  std::istringstream lines(readFile(files[0].string()));
  std::string line;
  ASSERT_TRUE(std::getline(lines, line));
  const auto head = splitCsv(line);
  // Every member of msgs/estimate_t.lcm, fixed arrays as NAME_0..NAME_4.
  const std::vector<std::string> members = {
      "utime", "seq", "instance_id", "t", "l", "v", "a", "Fa", "sigma_Fa", "b", "sigma_b", "moment", "sigma_moment",
      "x_c", "sigma_x_c", "y_c", "sigma_y_c", "theta", "sigma_theta", "theta_open", "nis", "nis_window", "nis_dof", "nis_lower", "nis_upper", "nis_bound",
      "drift", "mismatch", "nis_exceeded", "drift_exceeded", "sensors", "imu_age", "rope_load_age", "fa_observed",
      "moment_observed", "accepted", "gated", "load_changes", "implausible"};
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < head.size(); ++i) col[head[i]] = i;
  for (const auto& m : members) EXPECT_TRUE(col.count(m)) << "no column " << m << " in " << line;
  // The arrays: NAME_0..NAME_4 (or, with `@csv lambdas lambda` in the .lcm as
  // hoist-estimate names them, lambda_0..; either way all five).
  auto arrayCol = [&](const std::string& name, const std::string& alt, int i) -> std::string {
    const std::string a = name + "_" + std::to_string(i), b = alt + "_" + std::to_string(i);
    return col.count(a) ? a : b;
  };
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(col.count(arrayCol("lambdas", "lambda", i))) << "no column lambdas_" << i << " in " << line;
    EXPECT_TRUE(col.count(arrayCol("sigma_lambdas", "sigma_lambda", i))) << "no column sigma_lambdas_" << i << " in " << line;
  }
  std::vector<std::vector<std::string>> rows;
  while (std::getline(lines, line)) rows.push_back(splitCsv(line));
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& row : rows) ASSERT_EQ(row.size(), head.size());
  // Values round-trip (17 significant digits).
  EXPECT_EQ(std::stod(rows[0][col["Fa"]]), 1502.4);
  EXPECT_EQ(std::stod(rows[0][col["sigma_b"]]), 0.0102);
  EXPECT_EQ(std::stod(rows[0][col["theta_open"]]), 8.3e-4);
  EXPECT_EQ(std::stod(rows[0][col[arrayCol("sigma_lambdas", "sigma_lambda", 4)]]), 2.5);
  EXPECT_EQ(std::stod(rows[0][col[arrayCol("lambdas", "lambda", 0)]]), 31000.0);
  EXPECT_EQ(std::stod(rows[2][col["t"]]), 12.02);
  EXPECT_EQ(std::stol(rows[0][col["nis_dof"]]), 300);
  EXPECT_EQ(std::stol(rows[2][col["accepted"]]), 1202);
  EXPECT_EQ(std::stol(rows[0][col["sensors"]]), 7);
  // The drop-out row: not observed (sigma < 0), MODEL_MISMATCH by NIS.
  EXPECT_LT(std::stod(rows[3][col["sigma_Fa"]]), 0.0);
  EXPECT_EQ(rows[3][col["mismatch"]], "1");
  EXPECT_EQ(rows[3][col["nis_exceeded"]], "1");
  EXPECT_EQ(rows[0][col["mismatch"]], "0");
  EXPECT_EQ(std::stol(rows[3][col["sensors"]]), 3);
}

// ---- hoist-monitor --------------------------------------------------------------
TEST(ShowEstimate, MonitorPrintsTheEstimateLine) {
  const std::string url = urlFor(7840);
  std::string why;
  if (!loopbackMulticastWorks(url, why)) FAIL() << why << ".\n" << kMulticastHelp;
  Listener pub(url);
  ASSERT_TRUE(pub.good()) << kMulticastHelp;
  const fs::path d = testDir("show_estimate_monitor");
  const std::string out = (d / "monitor.out").string();
  Process mon({HOIST_MONITOR, "--lcm-url", url, "--channel-prefix", "north/", "--period", "0.25", "--duration", "4",
               "--stale", "30"},
              out);
  ASSERT_TRUE(mon.started());
  pub.pump(700ms);  // let it subscribe
  hoist::cage_state_t cage{};
  cage.t = 12.0;
  cage.l = 150.25;
  cage.min_clearance = 0.05;
  pub.lcm().publish("north/HOIST_CAGE", &cage);
  auto e = realisticEstimate(1);
  pub.lcm().publish("north/HOIST_ESTIMATE", &e);
  pub.pump(1000ms);
  // Then the mismatch, with the rope load cell gone: Fa and b not observed.
  e = realisticEstimate(2);
  e.sigma_Fa = -1.0;
  e.sigma_b = -1.0;
  e.nis_window = 450.0;  // 1.50 per dof
  e.mismatch = 1;
  e.nis_exceeded = 1;
  e.sensors = 3;  // the IMU only
  pub.lcm().publish("north/HOIST_ESTIMATE", &e);
  pub.pump(1000ms);
  // MODEL_MISMATCH by the trip-end preload test: neither of the estimator's
  // own tests (estimate_t.mismatch alone).
  auto v = realisticEstimate(3);
  v.mismatch = 1;
  pub.lcm().publish("north/HOIST_ESTIMATE", &v);
  // Another shaft's estimate never reaches a north/ monitor.
  auto other = realisticEstimate(3);
  other.Fa = 9999.0;
  pub.lcm().publish("south/HOIST_ESTIMATE", &other);
  const int st = mon.wait(15s);
  const std::string text = readFile(out);
  EXPECT_EQ(st, 0) << text;
  EXPECT_TRUE(contains(text, "estimate: Fa 1502+-3 N b 0.60+-0.01 m theta 6.5e-04 (open 8.3e-04) "
                             "NIS 1.02/dof (bound 1.24) sensors imu+rope"))
      << text;
  EXPECT_TRUE(contains(text, "estimate: Fa n/a b n/a theta 6.5e-04 (open 8.3e-04) NIS 1.50/dof (bound 1.24) "
                             "sensors imu [MISMATCH: NIS]"))
      << text;
  EXPECT_TRUE(contains(text, "[MISMATCH: the trip's preload fit]")) << text;
  EXPECT_FALSE(contains(text, "9999")) << text;
  // No MISMATCH on the lines of the estimate whose model matched.
  const auto first = text.find("estimate: Fa 1502");
  ASSERT_NE(first, std::string::npos);
  const std::string first_line = text.substr(first, text.find('\n', first) - first);
  EXPECT_FALSE(contains(first_line, "MISMATCH")) << first_line;
}
