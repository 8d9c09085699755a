// Bad-input corpus for the files users hand us: the shaft configuration
// (TOML) and the hoist profile (CSV).  Every class must give a clear error
// naming the key or column (and the line when there is one), through the
// hoist_io API and through the tools' exit status 2 (hoist-sim, hoist-replay,
// hoist-twind for configurations).  CRLF line ends and a UTF-8 BOM must be
// accepted.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "hoist/io/config.hpp"
#include "process.hpp"
#include "hoist/io/profile.hpp"

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------
// Shaft configuration classes

struct ConfigCase {
  const char* name;
  std::string text;
  const char* key;  ///< expected ConfigError::key() ("" = syntax error, no key)
  int line;         ///< expected line (0 = do not check)
};

std::string bytes(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::string s(n, '\0');
  for (auto& c : s) c = static_cast<char>(rng());
  return s;
}

const std::vector<ConfigCase>& configCases() {
  static const std::vector<ConfigCase> c = {
      {"unknown_key_misspelt", "[cage]\nmas = 800.0\n", "cage.mas", 2},
      {"unknown_section", "[cagee]\nmass = 800.0\n", "cagee", 1},
      {"key_outside_section", "mass = 800.0\n", "mass", 1},
      {"string_for_number", "[cage]\nmass = \"800\"\n", "cage.mass", 2},
      {"bool_for_number", "[guide_ropes]\nlength = true\n", "guide_ropes.length", 2},
      {"float_for_integer_modes", "[model]\nmodes = 50.5\n", "model.modes", 2},
      {"table_for_number", "[load]\noffset = { x = 1 }\n", "load.offset", 2},
      {"preload_scalar", "[guide_ropes]\npreload = 30000.0\n", "guide_ropes.preload", 2},
      {"preload_three_elements", "[guide_ropes]\npreload = [1.0, 2.0, 3.0]\n", "guide_ropes.preload", 2},
      {"preload_string_element", "[guide_ropes]\npreload = [\"a\", 30000.0]\n", "guide_ropes.preload[0]", 2},
      {"nan_mass", "[cage]\nmass = nan\n", "cage.mass", 2},
      {"inf_stiffness", "[hoisting_rope]\naxial_stiffness = inf\n", "hoisting_rope.axial_stiffness", 2},
      {"negative_mass", "[cage]\nmass = -800.0\n", "cage.mass", 2},
      {"zero_mass", "[cage]\nmass = 0\n", "cage.mass", 2},
      {"zero_rope_mass", "[hoisting_rope]\nmass_per_length = 0.0\n", "hoisting_rope.mass_per_length", 2},
      {"negative_damping", "[guide_ropes]\ndamping = -0.3\n", "guide_ropes.damping", 2},
      {"zero_guide_length", "[guide_ropes]\nlength = 0.0\n", "guide_ropes.length", 2},
      {"cage_longer_than_rope", "[guide_ropes]\nlength = 100.0\n[cage]\nhalf_height = 60.0\n", "cage.half_height", 4},
      {"initial_length_out_of_shaft", "[hoisting_rope]\ninitial_length = 390.0\n", "hoisting_rope.initial_length", 2},
      {"preload_too_low_for_rope_weight", "[guide_ropes]\npreload = [50.0, 30000.0]\n", "guide_ropes.preload", 2},
      {"rope_too_soft_for_load", "[hoisting_rope]\naxial_stiffness = 1e4\n", "hoisting_rope.axial_stiffness", 2},
      {"modes_zero", "[model]\nmodes = 0\n", "model.modes", 2},
      {"modes_huge", "[model]\nmodes = 1000000000000\n", "model.modes", 2},
      {"modes_negative", "[model]\nmodes = -5\n", "model.modes", 2},
      {"initial_unknown", "[model]\ninitial = \"dynamic\"\n", "model.initial", 2},
      {"rho_inf_out_of_range", "[model]\nrho_inf = 1.5\n", "model.rho_inf", 2},
      {"static_correction_not_boolean", "[model]\nstatic_correction = \"yes\"\n", "model.static_correction", 2},
      {"negative_gravity", "[model]\ngravity = -9.81\n", "model.gravity", 2},
      {"offset_beyond_shaft", "[load]\noffset = 1e6\n", "load.offset", 2},
      {"toml_syntax_error", "[cage]\nmass = = 800\n", "", 2},
      {"toml_duplicate_key", "[cage]\nmass = 800.0\nmass = 900.0\n", "", 3},
      {"toml_unterminated_string", "[model]\ninitial = \"static\n", "", 2},
      {"binary_garbage", bytes(512, 7), "", 0},
      {"nul_bytes", std::string("[cage]\nmass = 8\0\0\n", 18), "", 0},
  };
  return c;
}

class BadConfig : public ::testing::TestWithParam<ConfigCase> {};

TEST_P(BadConfig, RejectedWithKeyAndLine) {
  const ConfigCase& c = GetParam();
  try {
    (void)hoist::io::shaftParamsFromToml(hoist::io::parseToml(c.text, "shaft.toml"), "shaft.toml");
    FAIL() << c.name << ": accepted";
  } catch (const hoist::io::ConfigError& e) {
    EXPECT_EQ(e.key(), c.key) << e.what();
    if (c.line > 0) { EXPECT_EQ(e.line(), c.line) << e.what(); }
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("shaft.toml", 0), 0u) << what;  // names the file
    if (*c.key) { EXPECT_NE(what.find(c.key), std::string::npos) << what; }
    if (c.line > 0) { EXPECT_NE(what.find("shaft.toml:" + std::to_string(c.line) + ":"), std::string::npos) << what; }
    EXPECT_GT(e.message().size(), 5u) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(Classes, BadConfig, ::testing::ValuesIn(configCases()),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(BadConfigExtra, MisspeltKeySuggestsTheRightOne) {
  try {
    (void)hoist::io::shaftParamsFromToml(hoist::io::parseToml("[cage]\nhalf_heigth = 8.0\n", "s"), "s");
    FAIL();
  } catch (const hoist::io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'half_height'"), std::string::npos) << e.what();
  }
}

TEST(BadConfigExtra, PhysicalChecksKeepThePaperValid) {
  // The new physical checks must not reject the paper's shaft or realistic ones.
  EXPECT_NO_THROW(hoist::paperBaseline().validate());
  hoist::ShaftParams p;
  p.L = 1200.0;
  p.l0 = 100.0;
  p.m = 20000.0;
  p.rho1 = 8.0;
  p.EA = 3.0e8;
  p.Tb1 = p.Tb2 = 1.0e5;
  EXPECT_NO_THROW(p.validate());
}

// ---------------------------------------------------------------------------
// Profile CSV classes

struct CsvCase {
  const char* name;
  std::string text;
  const char* key;  ///< expected column ("" = none)
  int line;         ///< expected line (0 = do not check)
};

const std::vector<CsvCase>& csvCases() {
  static const std::vector<CsvCase> c = {
      {"missing_column_a", "t,v\n0,0\n1,0\n", "a", 1},
      {"no_header", "0,0,0\n1,0,0\n", "t", 1},
      {"duplicate_column", "t,v,a,v\n0,0,0,0\n1,0,0,0\n", "v", 1},
      {"empty_column_name", "t,v,a,\n0,0,0,0\n", "", 1},
      {"non_numeric", "t,v,a\n0,0,0\n1,fast,0\n", "v", 3},
      {"trailing_junk_in_number", "t,v,a\n0,0,0\n1,1.5x,0\n", "v", 3},
      {"time_equal", "t,v,a\n0,0,0\n0,0,0\n", "t", 3},
      {"time_decreasing", "t,v,a\n0,0,0\n1,0,0\n0.5,0,0\n", "t", 4},
      {"huge_gap", "t,v,a\n0,0,0\n1000,0,0\n", "t", 3},
      {"nan_field", "t,v,a\n0,0,0\n1,nan,0\n", "v", 3},
      {"inf_field", "t,v,a\n0,0,0\n1,0,-inf\n", "a", 3},
      {"empty_file", "", "", 0},
      {"only_comments", "# nothing here\n\n# still nothing\n", "", 0},
      {"header_only", "t,v,a\n", "", 0},
      {"single_row", "t,v,a\n0,0,0\n", "", 2},
      {"wrong_field_count", "t,v,a\n0,0,0\n1,0\n", "", 3},
      {"speed_beyond_limit", "t,v,a\n0,0,0\n1,1e4,0\n", "v", 3},
      {"accel_beyond_limit", "t,v,a\n0,0,0\n1,0,1e4\n", "a", 3},
      {"negative_length", "t,v,a,l\n0,0,0,50\n1,0,0,-1\n", "l", 3},
      {"binary_garbage", bytes(300, 11), "", 1},
      {"nul_in_line", std::string("t,v,a\n0,0\0,0\n", 13), "", 2},
      {"line_too_long", "t,v,a\n" + std::string(5000, '1') + "\n", "", 2},
  };
  return c;
}

class BadProfile : public ::testing::TestWithParam<CsvCase> {};

TEST_P(BadProfile, RejectedWithColumnAndLine) {
  const CsvCase& c = GetParam();
  std::istringstream in(c.text);
  try {
    (void)hoist::io::readProfileCsv(in, "trip.csv", 50.0);
    FAIL() << c.name << ": accepted";
  } catch (const hoist::io::ProfileError& e) {
    EXPECT_EQ(e.key(), c.key) << e.what();
    if (c.line > 0) { EXPECT_EQ(e.line(), c.line) << e.what(); }
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("trip.csv", 0), 0u) << what;
    if (c.line > 0) { EXPECT_NE(what.find("trip.csv:" + std::to_string(c.line) + ":"), std::string::npos) << what; }
  }
}

INSTANTIATE_TEST_SUITE_P(Classes, BadProfile, ::testing::ValuesIn(csvCases()),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(ProfileCsv, LengthOutOfTheShaftIsRejectedWithTheTime) {
  std::istringstream in("t,v,a,l\n0,0,0,380\n1,0,0,390\n");
  const auto prof = hoist::io::readProfileCsv(in, "trip.csv", 50.0);
  try {
    hoist::io::checkProfileInShaft(prof, hoist::paperBaseline(), "trip.csv");
    FAIL();
  } catch (const hoist::io::ProfileError& e) {
    EXPECT_EQ(e.key(), "l") << e.what();
  }
}

TEST(ProfileCsv, CrlfAndBomAreAccepted) {
  const std::string body = "t,v,a,l\r\n# comment\r\n0,0,0,50\r\n0.5,1,2,50.25\r\n1,1,0,50.75\r\n";
  for (const std::string& text : {body, "\xEF\xBB\xBF" + body, std::string("\xEF\xBB\xBFt,v,a\n0,0,0\n1,0,0\n")}) {
    std::istringstream in(text);
    hoist::HoistProfile p;
    ASSERT_NO_THROW(p = hoist::io::readProfileCsv(in, "trip.csv", 50.0)) << text;
    EXPECT_DOUBLE_EQ(p.startTime(), 0.0);
    EXPECT_DOUBLE_EQ(p.endTime(), 1.0);
    EXPECT_TRUE(std::isfinite(p.at(0.7).l));
  }
}

// ---------------------------------------------------------------------------
// The same classes through the tools: exit status 2 and a message naming the key.

using ToolRun = hoist::test::CapturedRun;

ToolRun run(const std::string& exe, const std::vector<std::string>& args) {
  return hoist::test::runCaptured(exe, args);
}

fs::path workDir(const std::string& name) {
  const auto d = fs::path(HOIST_TEST_WORK_DIR) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string writeFile(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// hoist-replay opens LCM before reading its input: a private, host-local URL.
const std::string kUrl = "udpm://239.255.76.67:7739?ttl=0";

TEST(ToolsExitStatus, BadConfigsGiveStatus2NamingTheKey) {
  const auto dir = workDir("tools_config");
  int n = 0;
  for (const ConfigCase& c : configCases()) {
    const auto cfg = writeFile(dir / (std::string(c.name) + ".toml"), c.text);
    const std::string what = std::string(c.name) + ": ";
#ifdef HOIST_SIM
    const ToolRun sim = run(HOIST_SIM, {"--config", cfg, "--profile", "rest:t_end=0.1", "--out", (dir / "o.csv").string()});
    EXPECT_EQ(sim.status, 2) << what << sim.output;
    if (*c.key) { EXPECT_NE(sim.output.find(c.key), std::string::npos) << what << sim.output; }
#endif
    const ToolRun rep = run(HOIST_REPLAY, {"--config", cfg, "--profile", "rest:t_end=0.1", "--lcm-url", kUrl, "-q"});
    EXPECT_EQ(rep.status, 2) << what << rep.output;
    if (*c.key) { EXPECT_NE(rep.output.find(c.key), std::string::npos) << what << rep.output; }
    const ToolRun twind = run(HOIST_TWIND, {"--config", cfg, "--lcm-url", kUrl, "--duration", "0.1"});
    EXPECT_EQ(twind.status, 2) << what << twind.output;
    if (*c.key) { EXPECT_NE(twind.output.find(c.key), std::string::npos) << what << twind.output; }
    ++n;
  }
  EXPECT_GE(n, 25);
}

TEST(ToolsExitStatus, BadProfilesGiveStatus2NamingTheLine) {
  const auto dir = workDir("tools_profile");
  for (const CsvCase& c : csvCases()) {
    const auto csv = writeFile(dir / (std::string(c.name) + ".csv"), c.text);
    const std::string what = std::string(c.name) + ": ";
    const std::string where = c.line > 0 ? csv + ":" + std::to_string(c.line) + ":" : csv;
#ifdef HOIST_SIM
    const ToolRun sim = run(HOIST_SIM, {"--profile", csv, "--out", (dir / "o.csv").string(), "--modes", "4"});
    EXPECT_EQ(sim.status, 2) << what << sim.output;
    EXPECT_NE(sim.output.find(where), std::string::npos) << what << sim.output;
#endif
    const ToolRun rep = run(HOIST_REPLAY, {"--profile", csv, "--lcm-url", kUrl, "-q", "--speed", "0"});
    EXPECT_EQ(rep.status, 2) << what << rep.output;
    EXPECT_NE(rep.output.find(where), std::string::npos) << what << rep.output;
  }
}

#ifdef HOIST_SIM
TEST(ToolsExitStatus, SimProfileOutsideTheValidRangeIsRefusedUpFront) {
  // Before the fix: `hoist-sim --profile "rest:t_end=3,l0=1e-7"` wrote 1e282 m and exited 0.
  const auto dir = workDir("tools_implausible");
  const ToolRun sim = run(HOIST_SIM, {"--profile", "rest:t_end=3,l0=1e-7", "--out", (dir / "o.csv").string(), "-q"});
  // Rejected before it runs (bad input, exit 2): the profile leaves the model's
  // valid range, 0.05 m clear of both shaft ends; the message names the time and
  // the value.  (The run-time path, a state that leaves the plausible range:
  // exit 1 with the time and the quantity, SimCli.ImplausibleStateExitsOneNamingTimeAndQuantity.)
  EXPECT_EQ(sim.status, 2) << sim.output;
  EXPECT_NE(sim.output.find("at t = 0 s the rope length l = 1e-07 m"), std::string::npos) << sim.output;
  EXPECT_NE(sim.output.find("valid rope lengths are [0.05, 383.95] m"), std::string::npos) << sim.output;
  const ToolRun ok = run(HOIST_SIM, {"--profile", "rest:t_end=3,l0=0.05", "--out", (dir / "p.csv").string(), "-q"});
  EXPECT_EQ(ok.status, 0) << ok.output;
}
#endif

TEST(ToolsExitStatus, CrlfBomProfileIsAcceptedByTheTools) {
  const auto dir = workDir("tools_crlf");
  const auto csv = writeFile(dir / "crlf.csv", "\xEF\xBB\xBFt,v,a,l\r\n0,0,0,50\r\n0.05,0,0,50\r\n0.1,0,0,50\r\n");
#ifdef HOIST_SIM
  const ToolRun sim = run(HOIST_SIM, {"--profile", csv, "--out", (dir / "o.csv").string(), "--modes", "4"});
  EXPECT_EQ(sim.status, 0) << sim.output;
#endif
  const ToolRun rep = run(HOIST_REPLAY, {"--profile", csv, "--lcm-url", kUrl, "-q", "--speed", "0"});
  EXPECT_EQ(rep.status, 0) << rep.output;
}

// Every file hoist-study writes (a run's CSV, the
// summary, the shapes, a gnuplot script) is checked to its last byte; a full
// disk gives exit status 1 naming the file, never a silent short file.
TEST(ToolsExitStatus, StudyOnAFullDiskExitsOneNamingTheFile) {
  // The full disk: a file size limit (hoist::test::runCapturedWithFileSizeLimit),
  // since hoist-study refuses to write to /dev/full, a device node.  The
  // first file over the limit is run1.csv (1 s at --dt 1e-4: about 10 000 rows).
  {
    const auto dir = workDir("study_full_run1");
    const ToolRun st = hoist::test::runCapturedWithFileSizeLimit(
        HOIST_STUDY, {"response", "--out-dir", dir.string(), "--modes", "5", "--no-plots", "--profile",
                      "rest:t_end=1", "-j", "1", "--dt", "1e-4"}, 64);
    EXPECT_EQ(st.status, 1) << st.output;
    EXPECT_NE(st.output.find((dir / "response" / "runs" / "run1.csv").string()), std::string::npos) << st.output;
    EXPECT_NE(st.output.find("File too large"), std::string::npos) << st.output;
  }
  // A device node where a file goes is refused, never written (nor replaced).
  for (const char* file : {"runs/run1.csv", "summary.csv", "shapes.csv", "fig03_cage.gp"}) {
    if (!fs::exists("/dev/full")) break;
    const auto dir = workDir(std::string("study_full_") + fs::path(file).stem().string());
    fs::create_directories(dir / "response" / "runs");
    fs::create_symlink("/dev/full", dir / "response" / file);
    const ToolRun st = run(HOIST_STUDY, {"response", "--out-dir", dir.string(), "--modes", "5", "--no-plots",
                                         "--profile", "rest:t_end=1", "-j", "1"});
    EXPECT_EQ(st.status, 1) << file << ": " << st.output;
    EXPECT_NE(st.output.find((dir / "response" / file).string()), std::string::npos) << st.output;
    EXPECT_NE(st.output.find("a symbolic link"), std::string::npos) << st.output;
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir / "response" / file))) << file;
  }
  // The same command onto a disk with room succeeds (the test can fail).
  const auto ok = workDir("study_room");
  const ToolRun st = run(HOIST_STUDY, {"response", "--out-dir", ok.string(), "--modes", "5", "--no-plots",
                                       "--profile", "rest:t_end=1", "-j", "1"});
  EXPECT_EQ(st.status, 0) << st.output;
  EXPECT_GT(fs::file_size(ok / "response" / "runs" / "run1.csv"), 100u);
}

}  // namespace
