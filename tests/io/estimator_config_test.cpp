// [sensors]/[estimator] (hoist/io/estimator_config.hpp): every key of the
// table is read into its member, errors name file, line and key; the
// measurement CSV reader: columns, absent sensors, errors naming file, line
// and column, the row cap.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "hoist/io/config.hpp"
#include "hoist/io/estimator_config.hpp"

using hoist::EstimatorSettings;
using hoist::io::ConfigError;
using hoist::io::EstimatorConfig;
using hoist::io::kEstimatorFields;
using hoist::io::MeasurementError;

namespace {

EstimatorConfig fromText(const std::string& text) {
  return hoist::io::estimatorConfigFromToml(hoist::io::parseToml(text, "cfg.toml"), "cfg.toml");
}

std::string errorOf(const std::string& text) {
  try {
    fromText(text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

/// Every value the table reaches, by key.
std::vector<double> valuesOf(EstimatorSettings s) {
  std::vector<double> v;
  for (const auto& f : kEstimatorFields) v.push_back(f.real ? *f.real(s) : *f.integer(s));
  return v;
}

}  // namespace

TEST(EstimatorConfig, AbsentSectionsGiveTheDefaults) {
  const EstimatorConfig c = fromText("[load]\neccentric_force = 1000.0\n");
  EXPECT_FALSE(c.enabled);
  EXPECT_EQ(valuesOf(c.settings), valuesOf(EstimatorSettings{}));
}

TEST(EstimatorConfig, TheTableReachesEveryFieldOnce) {
  // Distinct members (no key aliases another) ...
  EstimatorSettings s;
  std::set<const void*> addresses;
  for (const auto& f : kEstimatorFields) {
    ASSERT_TRUE((f.real != nullptr) != (f.integer != nullptr)) << f.key;
    addresses.insert(f.real ? static_cast<const void*>(f.real(s)) : static_cast<const void*>(f.integer(s)));
  }
  EXPECT_EQ(addresses.size(), kEstimatorFields.size());
  // ... and all of them: a new EstimatorSettings member needs a key here
  // (3 noise doubles, 13 doubles, 2 ints each padded to 8 bytes).
  EXPECT_EQ(sizeof(EstimatorSettings), 248u) << "EstimatorSettings changed: add its key to hoist::io::kEstimatorFields";
}

TEST(EstimatorConfig, EveryKeyIsReadIntoItsMember) {
  const std::vector<double> defaults = valuesOf(EstimatorSettings{});
  for (std::size_t i = 0; i < kEstimatorFields.size(); ++i) {
    const auto& f = kEstimatorFields[i];
    // A valid value that differs from the default (every bound allows 0.9x / -1).
    std::ostringstream text;
    text << "[" << f.section << "]\n";
    double want;
    if (f.real) {
      want = defaults[i] * 0.9;
      text.precision(17);
      text << f.key << " = " << std::scientific << want << "\n";
    } else {
      want = defaults[i] - 1;
      text << f.key << " = " << static_cast<long long>(want) << "\n";
    }
    const EstimatorConfig c = fromText(text.str());
    const std::vector<double> got = valuesOf(c.settings);
    for (std::size_t j = 0; j < got.size(); ++j) {
      if (j == i) EXPECT_EQ(got[j], want) << f.key;
      else EXPECT_EQ(got[j], defaults[j]) << f.key << " changed " << kEstimatorFields[j].key;
    }
  }
}

TEST(EstimatorConfig, EnabledAndRoundTrip) {
  EstimatorConfig c = fromText("[estimator]\nenabled = true\nnis_window = 7.5\ngate_reset = 4\n"
                               "[sensors]\nrope_load_noise = 35\n");
  EXPECT_TRUE(c.enabled);
  EXPECT_EQ(c.settings.nis_window, 7.5);
  EXPECT_EQ(c.settings.gate_reset, 4);
  EXPECT_EQ(c.settings.noise.rope_load, 35.0);
  const EstimatorConfig back = fromText(hoist::io::toToml(c));
  EXPECT_TRUE(back.enabled);
  EXPECT_EQ(valuesOf(back.settings), valuesOf(c.settings));
}

TEST(EstimatorConfig, ErrorsNameFileLineAndKey) {
  EXPECT_NE(errorOf("[estimator]\nfa_wlak = 3.0\n").find("cfg.toml:2: estimator.fa_wlak: unknown key (did you mean 'fa_walk'?)"),
            std::string::npos)
      << errorOf("[estimator]\nfa_wlak = 3.0\n");
  EXPECT_NE(errorOf("[estimator]\nenabled = 1\n").find("cfg.toml:2: estimator.enabled: must be true or false"),
            std::string::npos);
  EXPECT_NE(errorOf("[sensors]\nimu_rate_noise = \"x\"\n").find("cfg.toml:2: sensors.imu_rate_noise: must be a number"),
            std::string::npos);
  EXPECT_NE(errorOf("[estimator]\ngate_reset = 2.5\n").find("cfg.toml:2: estimator.gate_reset: must be an integer"),
            std::string::npos);
  // Values validate() refuses, with the key's line.
  const std::string g = errorOf("[estimator]\nenabled = true\ngate_sigma = 1.0\n");
  EXPECT_NE(g.find("cfg.toml:3: estimator.gate_sigma: must be in [3, 1e6]"), std::string::npos) << g;
  const std::string n = errorOf("[sensors]\n\nimu_accel_noise = 0.0\n");
  EXPECT_NE(n.find("cfg.toml:3: sensors.imu_accel_noise:"), std::string::npos) << n;
  EXPECT_NE(errorOf("estimator = 3\n").find("cfg.toml:1: estimator: must be a table"), std::string::npos);
}

TEST(EstimatorConfig, DaemonConfigurationIsAcceptedByTheShaftReader) {
  const std::string text =
      "[load]\neccentric_force = 1500.0\n[service]\nmax_step = 0.001\n[alarms]\n[forecast]\n"
      "[sensors]\nimu_accel_noise = 0.003\nmax_clock_offset = 0.3\n[estimator]\nenabled = true\nclear_hold = 1.5\n";
  const toml::table tbl = hoist::io::parseToml(text, "d.toml");
  EXPECT_THROW(hoist::io::shaftParamsFromToml(tbl, "d.toml"), ConfigError);  // the shaft alone refuses them
  const hoist::ShaftParams p = hoist::io::shaftParamsFromToml(tbl, "d.toml", hoist::io::daemonSections());
  EXPECT_EQ(p.Fa, 1500.0);
  // The daemon's own keys (max_clock_offset, clear_hold) are no error for
  // the offline tools reading the same file, but still type-checked.
  EXPECT_EQ(hoist::io::estimatorConfigFromToml(tbl, "d.toml").settings.noise.imu_accel, 0.003);
  EXPECT_NE(errorOf("[estimator]\nclear_hold = \"long\"\n").find("cfg.toml:2: estimator.clear_hold: must be a number"),
            std::string::npos);
  EXPECT_EQ(hoist::io::serviceMaxStep(tbl, "d.toml", 0.0025), 0.001);
  EXPECT_EQ(hoist::io::serviceMaxStep(hoist::io::parseToml("[load]\n", "x"), "x", 0.0025), 0.0025);
  try {
    hoist::io::serviceMaxStep(hoist::io::parseToml("[service]\n\nmax_step = -1\n", "s.toml"), "s.toml", 0.0025);
    ADD_FAILURE() << "max_step = -1 accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("s.toml:3: service.max_step"), std::string::npos) << e.what();
  }
  // The shipped daemon configuration.
  const std::string example = std::string(HOIST_SOURCE_DIR) + "/service/config/example.toml";
  const toml::table ex = hoist::io::loadTomlFile(example);
  EXPECT_NO_THROW(hoist::io::shaftParamsFromToml(ex, example, hoist::io::daemonSections()));
  EXPECT_NO_THROW(hoist::io::estimatorConfigFromToml(ex, example));
}

// ---- measurement CSV -----------------------------------------------------------

namespace {

std::vector<hoist::MeasurementSample> read(const std::string& text, hoist::io::MeasurementColumns* info = nullptr,
                                           const hoist::io::ProfileLimits& lim = {}) {
  std::istringstream in(text);
  return hoist::io::readMeasurementsCsv(in, "m.csv", lim, info);
}

std::string csvError(const std::string& text, const hoist::io::ProfileLimits& lim = {}) {
  try {
    read(text, nullptr, lim);
  } catch (const MeasurementError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(MeasurementCsv, ColumnsAndAbsentSamples) {
  hoist::io::MeasurementColumns info;
  const auto s = read(
      "\xEF\xBB\xBF# recorded\r\n"
      "t, l, v, a, rope_load, f_y, note\r\n"
      "0, 50, 0, 0, 9810.5, 0.001, x\r\n"
      "\n"
      "0.01, 50.1, 0.5, 1, , -0.002, y\r\n"
      "0.02, 50.2, 1.0, 1, 9800, , z\r\n",
      &info);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(info.sensors, hoist::kSensorImuAccel | hoist::kSensorRopeLoad);
  ASSERT_EQ(info.ignored.size(), 1u);
  EXPECT_EQ(info.ignored[0], "note");
  EXPECT_EQ(s[0].present, hoist::kSensorImuAccel | hoist::kSensorRopeLoad);
  EXPECT_EQ(s[0].z.rope_load, 9810.5);
  EXPECT_EQ(s[1].present, unsigned(hoist::kSensorImuAccel));
  EXPECT_EQ(s[1].z.f_y, -0.002);
  EXPECT_EQ(s[1].k.l, 50.1);
  EXPECT_EQ(s[1].k.v, 0.5);
  EXPECT_EQ(s[1].k.a, 1.0);
  EXPECT_EQ(s[2].present, unsigned(hoist::kSensorRopeLoad));
  EXPECT_EQ(s[2].t, 0.02);
}

TEST(MeasurementCsv, WrittenRowsReadBack) {
  std::string text = std::string(hoist::io::kMeasurementHeader) + "\n";
  hoist::MeasurementSample m;
  m.k = {80.0, -2.5, 0.75};
  m.z = {1.0 / 3.0, -2e-5, 10234.125};
  for (int i = 0; i < 3; ++i) {
    m.t = 0.1 * i;
    m.present = i == 1 ? unsigned(hoist::kSensorImuRate) : 7u;
    hoist::io::appendMeasurementRow(text, m);
  }
  const auto s = read(text);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0].z.f_y, 1.0 / 3.0);
  EXPECT_EQ(s[0].z.omega, -2e-5);
  EXPECT_EQ(s[2].z.rope_load, 10234.125);
  EXPECT_EQ(s[1].present, unsigned(hoist::kSensorImuRate));
  EXPECT_EQ(s[1].z.omega, -2e-5);
}

TEST(MeasurementCsv, ErrorsNameFileLineAndColumn) {
  const std::string h = "t,l,v,a,f_y,omega,rope_load\n";
  const std::string ok = "0,50,0,0,0,0,9800\n";
  struct Case {
    std::string text, want;
  };
  const std::vector<Case> cases = {
      {"t,v,a,f_y\n0,0,0,0\n", "m.csv:1: l: required column missing"},
      {"0,50,0,0\n", "m.csv:1: t: required column missing (the first line must be a header"},
      {"t,l,v,a,l\n", "m.csv:1: l: column appears twice"},
      {h + ok + "0.01,50,0,0,abc,0,9800\n", "m.csv:3: f_y: not a number: 'abc'"},
      {h + ok + "0.01,50,0,0,0,nan,9800\n", "m.csv:3: omega: must be finite"},
      {h + ok + "0.01,50,0,0,0,0,inf\n", "m.csv:3: rope_load: must be finite"},
      {h + "# c\n" + ok + "0,50,0,0,0,0,9800\n", "m.csv:4: t: time must increase strictly"},
      {h + ok + "0.01,,0,0,0,0,9800\n", "m.csv:3: l: empty field (required column)"},
      {h + ok + "0.01,-1,0,0,0,0,9800\n", "m.csv:3: l: rope length must be > 0"},
      {h + ok + "0.01,50,99,0,0,0,9800\n", "m.csv:3: v: |v| = 99"},
      {h + ok + "0.01,50,0,0,0,0\n", "m.csv:3: expected 7 fields like the header, got 6"},
      {h + ok + "30,50,0,0,0,0,9800\n", "m.csv:3: t: gap of"},
      {h + ok, "m.csv:2: a measurement file needs at least two rows, got 1"},
      {"", "m.csv: empty file"},
      {h + "0,50,0\x01,0,0,0,1\n", "m.csv:2: binary data"},
  };
  for (const auto& c : cases) {
    const std::string e = csvError(c.text);
    EXPECT_EQ(e.rfind(c.want, 0), 0u) << "input:\n" << c.text << "\ngot: " << e << "\nwant: " << c.want;
  }
}

TEST(MeasurementCsv, RowCapIsCheckedBeforeTheRowIsStored) {
  hoist::io::ProfileLimits lim;
  lim.max_rows = 3;
  std::string text = "t,l,v,a\n";
  for (int i = 0; i < 3; ++i) text += std::to_string(i) + ",50,0,0\n";
  EXPECT_EQ(read(text, nullptr, lim).size(), 3u);
  text += "3,50,0,0\n";
  EXPECT_EQ(csvError(text, lim).rfind("m.csv:5: more than 3 rows", 0), 0u) << csvError(text, lim);
}

TEST(MeasurementCsv, MissingFileIsNamed) {
  try {
    hoist::io::readMeasurementsCsvFile("/nonexistent/m.csv");
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/m.csv"), std::string::npos);
  }
}

TEST(EstimatorConfig, ReadmeListsExactlyTheTablesKeysWithTheDefaults) {
  std::ifstream in(std::string(HOIST_SOURCE_DIR) + "/README.md");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string readme = ss.str();
  const auto at = readme.find("## Estimating the load (`hoist-estimate`)");
  ASSERT_NE(at, std::string::npos);
  const auto begin = readme.find("```toml\n", at);
  ASSERT_NE(begin, std::string::npos);
  const auto end = readme.find("```", begin + 8);
  const std::string block = readme.substr(begin + 8, end - begin - 8);
  const EstimatorConfig c = fromText(block);
  EXPECT_FALSE(c.enabled);
  EXPECT_EQ(valuesOf(c.settings), valuesOf(EstimatorSettings{})) << block;
  std::vector<std::string> listed, expected;
  std::istringstream lines(block);
  std::string line, section;
  while (std::getline(lines, line)) {
    if (line.rfind('[', 0) == 0) section = line.substr(1, line.find(']') - 1);
    else if (const auto eq = line.find(" = "); eq != std::string::npos) listed.push_back(section + "." + line.substr(0, eq));
  }
  for (const auto& f : kEstimatorFields) {
    if (f.section == "estimator" && expected.back().rfind("sensors.", 0) == 0) expected.push_back("estimator.enabled");
    expected.push_back(std::string(f.section) + "." + std::string(f.key));
  }
  EXPECT_EQ(listed, expected);
}
