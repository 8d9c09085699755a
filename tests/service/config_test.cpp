// [service] and [alarms] parsing: defaults, errors naming file:line and key.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "hoist/bus/channels.hpp"
#include "hoist/service/cfg/config_file.hpp"

using namespace hoist::service;

namespace {

TwinConfig parse(const std::string& text) {
  TwinConfig cfg;
  parseServiceSections(toml::parse(text), "test.toml", cfg);
  return cfg;
}

std::string errorOf(const std::string& text) {
  try {
    parse(text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(ServiceConfig, DefaultsWhenAbsent) {
  const TwinConfig c = parse("");
  EXPECT_EQ(c.service.rate, 100.0);
  EXPECT_EQ(c.service.clock, ClockMode::Wall);
  EXPECT_EQ(c.alarms.gap_pos_y, 0.30);
  EXPECT_TRUE(c.alarms.latch_critical);
}

TEST(ServiceConfig, ReadsEveryKey) {
  const TwinConfig c = parse(R"(
[service]
rate = 200
cage_rate = 50.0
shape_rate = 2.0
health_rate = 2.0
channel_prefix = "SITE1_"
lcm_url = "udpm://239.255.76.67:7700?ttl=0"
clock = "input"
max_speed = 12.0
max_accel = 3.0
max_length_jump = 0.25
max_time_step = 0.5
stale_timeout = 0.3
max_step = 0.005
shape_points = 51
envelope_points = 201
log_rate_limit = 2
fault_hold = 2.0

[alarms]
gap_pos_y = 0.2
gap_neg_y = 0.25
guide_rope_gap = 0.4
warning_fraction = 0.4
critical_fraction = 0.7
deadband = 0.05
on_delay = 0.2
off_delay = 2.0
reannounce = 0
latch_critical = false
max_shelve = 600
slack_fraction = 0.3
overload_fraction = 2.0
force_deadband = 0.1
)");
  EXPECT_EQ(c.service.rate, 200.0);
  EXPECT_EQ(c.service.cage_rate, 50.0);
  EXPECT_EQ(c.service.channel_prefix, "SITE1_");
  EXPECT_EQ(c.service.clock, ClockMode::Input);
  EXPECT_EQ(c.service.shape_points, 51);
  EXPECT_EQ(c.service.max_step, 0.005);
  EXPECT_EQ(c.alarms.gap_neg_y, 0.25);
  EXPECT_EQ(c.alarms.reannounce, 0.0);
  EXPECT_FALSE(c.alarms.latch_critical);
  EXPECT_EQ(c.alarms.slack_fraction, 0.3);
  EXPECT_EQ(c.alarms.overload_fraction, 2.0);
  EXPECT_EQ(c.alarms.force_deadband, 0.1);
  EXPECT_EQ(c.alarms.max_shelve, 600.0);
}

TEST(ServiceConfig, UnknownKeyNamesFileLineAndKey) {
  const std::string e = errorOf("[service]\nrate = 100\nbogus = 1\n");
  EXPECT_NE(e.find("test.toml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("service.bogus"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
}

TEST(ServiceConfig, WrongTypeAndRange) {
  std::string e = errorOf("[alarms]\ngap_pos_y = \"wide\"\n");
  EXPECT_NE(e.find("test.toml:2: alarms.gap_pos_y: must be a number"), std::string::npos) << e;
  e = errorOf("[service]\n\nrate = 5000\n");
  EXPECT_NE(e.find("test.toml:3: service.rate"), std::string::npos) << e;
  e = errorOf("[service]\nclock = \"sundial\"\n");
  EXPECT_NE(e.find("service.clock"), std::string::npos) << e;
  e = errorOf("[alarms]\nwarning_fraction = 0.9\ncritical_fraction = 0.8\n");
  EXPECT_NE(e.find("alarms.warning_fraction"), std::string::npos) << e;
  e = errorOf("[alarms]\ngap_neg_y = nan\n");
  EXPECT_NE(e.find("alarms.gap_neg_y"), std::string::npos) << e;
  e = errorOf("service = 3\n");
  EXPECT_NE(e.find("service"), std::string::npos) << e;
  e = errorOf("[service]\nshape_points = 1.5\n");
  EXPECT_NE(e.find("service.shape_points: must be an integer"), std::string::npos) << e;
  e = errorOf("[service]\nchannel_prefix = \"a b\"\n");
  EXPECT_NE(e.find("service.channel_prefix"), std::string::npos) << e;
}

TEST(ServiceConfig, PrintedConfigParsesBack) {
  TwinConfig c;
  c.service.rate = 250.0;
  c.service.channel_prefix = "X_";
  c.alarms.deadband = 0.03;
  c.alarms.slack_fraction = 0.25;
  c.alarms.overload_fraction = 1.75;
  c.alarms.force_deadband = 0.02;
  const std::string text = toToml(c);
  const TwinConfig d = parse(text);
  EXPECT_EQ(d.alarms.slack_fraction, 0.25);
  EXPECT_EQ(d.alarms.overload_fraction, 1.75);
  EXPECT_EQ(d.alarms.force_deadband, 0.02);
  EXPECT_EQ(d.service.rate, 250.0);
  EXPECT_EQ(d.service.channel_prefix, "X_");
  EXPECT_EQ(d.alarms.deadband, 0.03);
}

TEST(Channels, Prefix) {
  const hoist::bus::Channels ch("A_");
  EXPECT_EQ(ch.winder, "A_HOIST_WINDER");
  EXPECT_EQ(ch.cage, "A_HOIST_CAGE");
  EXPECT_EQ(ch.guide_shape, "A_HOIST_GUIDE_SHAPE");
  EXPECT_EQ(ch.alarm, "A_HOIST_ALARM");
  EXPECT_EQ(ch.alarm_ack, "A_HOIST_ALARM_ACK");
  EXPECT_EQ(ch.health, "A_HOIST_HEALTH");
  EXPECT_EQ(hoist::bus::channel("north/", hoist::bus::kChannelCage), "north/HOIST_CAGE");
  EXPECT_EQ(hoist::bus::Channels().winder, "HOIST_WINDER");
}

TEST(ServiceConfig, DaemonReadsTheStaticCorrection) {
  // [model] static_correction reaches the daemon's model through the shaft
  // parameters (default on); the printed configuration keeps it.
  const std::string path = ::testing::TempDir() + "/static_correction.toml";
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("[model]\nmodes = 12\nstatic_correction = false\n[service]\nrate = 50\n", f);
    std::fclose(f);
  }
  const TwinConfig c = loadTwinConfig(path);
  EXPECT_FALSE(c.shaft.static_correction);
  EXPECT_NE(toToml(c).find("static_correction = false"), std::string::npos);
  EXPECT_TRUE(TwinConfig{}.shaft.static_correction);
}

TEST(ForecastConfig, DefaultsReadAndPrinted) {
  TwinConfig c = parse("");
  // On by default, economical (the exact forecast on request).
  EXPECT_TRUE(c.forecast.enabled);
  EXPECT_FALSE(c.forecast.exact);
  EXPECT_EQ(c.forecast.modes, 10);
  EXPECT_EQ(c.forecast.rate, 1.0);
  EXPECT_EQ(c.forecast.horizon, 20.0);
  EXPECT_EQ(c.forecast.workers, 1);
  c = parse("[forecast]\nenabled = false\nrate = 0.5\nhorizon = 12.5\nestop_decel = 2.5\nestop_jerk = 8\n"
            "vmax = 12\namax = 0.8\nworkers = 2\nseries_points = 40\nexact = true\nmodes = 7\n");
  EXPECT_FALSE(c.forecast.enabled);
  EXPECT_TRUE(c.forecast.exact);
  EXPECT_EQ(c.forecast.modes, 7);
  EXPECT_EQ(c.forecast.rate, 0.5);
  EXPECT_EQ(c.forecast.horizon, 12.5);
  EXPECT_EQ(c.forecast.estop_decel, 2.5);
  EXPECT_EQ(c.forecast.estop_jerk, 8.0);
  EXPECT_EQ(c.forecast.vmax, 12.0);
  EXPECT_EQ(c.forecast.amax, 0.8);
  EXPECT_EQ(c.forecast.workers, 2);
  EXPECT_EQ(c.forecast.series_points, 40);
  const TwinConfig d = parse(toToml(c));
  EXPECT_FALSE(d.forecast.enabled);
  EXPECT_TRUE(d.forecast.exact);
  EXPECT_EQ(d.forecast.modes, 7);
  EXPECT_EQ(d.forecast.horizon, 12.5);
  EXPECT_EQ(d.forecast.amax, 0.8);
  EXPECT_EQ(d.forecast.series_points, 40);
}

TEST(ForecastConfig, BadValuesNameTheKeyAndLine) {
  auto expectKey = [](const std::string& text, const std::string& what) {
    const std::string e = errorOf(text);
    EXPECT_NE(e.find(what), std::string::npos) << text << " -> " << e;
  };
  expectKey("[forecast]\nenabled = 1\n", "test.toml:2: forecast.enabled");
  expectKey("[forecast]\nrate = 0\n", "test.toml:2: forecast.rate");
  expectKey("[forecast]\nrate = nan\n", "forecast.rate");
  expectKey("[service]\nrate = 5\n[forecast]\nrate = 8\n", "forecast.rate: must be <= service.rate");
  expectKey("[forecast]\n\nhorizon = -1\n", "test.toml:3: forecast.horizon");
  expectKey("[forecast]\nhorizon = 0.001\n", "forecast.horizon: must be at least one step");
  expectKey("[forecast]\nhorizon = inf\n", "forecast.horizon");
  expectKey("[forecast]\nestop_decel = 0\n", "forecast.estop_decel");
  expectKey("[forecast]\nestop_jerk = -3\n", "forecast.estop_jerk");
  expectKey("[forecast]\nvmax = 0\n", "forecast.vmax");
  expectKey("[forecast]\namax = \"fast\"\n", "forecast.amax: must be a number");
  expectKey("[forecast]\nworkers = 0\n", "forecast.workers");
  expectKey("[forecast]\nworkers = 1.5\n", "forecast.workers: must be an integer");
  expectKey("[forecast]\nseries_points = 65\n", "forecast.series_points");
  expectKey("[forecast]\nhorizn = 20\n", "forecast.horizn");
  expectKey("[forecast]\nexact = \"yes\"\n", "test.toml:2: forecast.exact");
  expectKey("[forecast]\nmodes = 0\n", "test.toml:2: forecast.modes");
  expectKey("[forecast]\nmodes = 1001\n", "forecast.modes");
  expectKey("[forecast]\nmodes = 2.5\n", "forecast.modes: must be an integer");
}

// The rope-force alarm keys are validated like every key; the
// error names file:line and the key.
TEST(ServiceConfig, RopeForceAlarmKeysAreValidated) {
  const TwinConfig d = parse("");
  EXPECT_EQ(d.alarms.slack_fraction, 0.5);
  EXPECT_EQ(d.alarms.overload_fraction, 1.5);
  EXPECT_EQ(d.alarms.force_deadband, 0.05);
  struct Case {
    const char* text;
    const char* want;
  };
  const Case cases[] = {
      {"[alarms]\nslack_fraction = 0.0\n", "test.toml:2: alarms.slack_fraction"},
      {"[alarms]\nslack_fraction = 1.0\n", "test.toml:2: alarms.slack_fraction: must be below 1"},
      {"[alarms]\nslack_fraction = -0.2\n", "alarms.slack_fraction"},
      {"[alarms]\nslack_fraction = nan\n", "alarms.slack_fraction"},
      {"[alarms]\nslack_fraction = \"half\"\n", "test.toml:2: alarms.slack_fraction: must be a number"},
      {"[alarms]\n\noverload_fraction = 1.0\n", "test.toml:3: alarms.overload_fraction: must be in (1, 100]"},
      {"[alarms]\noverload_fraction = 0.8\n", "alarms.overload_fraction"},
      {"[alarms]\noverload_fraction = 1000\n", "alarms.overload_fraction"},
      {"[alarms]\noverload_fraction = inf\n", "alarms.overload_fraction"},
      {"[alarms]\nforce_deadband = -0.01\n", "test.toml:2: alarms.force_deadband"},
      {"[alarms]\nforce_deadband = 0.5\n", "alarms.force_deadband: must be below slack_fraction"},
      {"[alarms]\nslack_fraction = 0.9\nforce_deadband = 0.2\n", "alarms.force_deadband"},
      {"[alarms]\noverload_fraction = 1.1\nforce_deadband = 0.2\n", "alarms.force_deadband: must be below overload_fraction - 1"},
      {"[alarms]\nslack_fractoin = 0.4\n", "alarms.slack_fractoin"},
  };
  for (const Case& c : cases) {
    const std::string e = errorOf(c.text);
    EXPECT_NE(e.find(c.want), std::string::npos) << c.text << " -> " << e;
  }
}

namespace {
/// loadTwinConfig() of `text` written to a file (the daemon's own [sensors] /
/// [estimator] keys are read there); the error text, or "" when it loads.
std::string loadError(const std::string& text, TwinConfig* out = nullptr) {
  char path[] = "/tmp/hoist_config_testXXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) return "mkstemp failed";
  FILE* f = fdopen(fd, "w");
  std::fputs(text.c_str(), f);
  std::fclose(f);
  std::string err;
  try {
    const TwinConfig c = loadTwinConfig(path);
    if (out) *out = c;
  } catch (const std::exception& e) {
    err = e.what();
  }
  std::remove(path);
  return err;
}
}  // namespace

TEST(SensorConfig, ClockOffsetAndClearHoldReadValidatedAndPrinted) {
  TwinConfig c;
  EXPECT_EQ(loadError("[sensors]\nimu_accel_noise = 0.004\nmax_clock_offset = 0.25\n"
                      "[estimator]\nenabled = true\nclear_hold = 3\n", &c), "");
  EXPECT_EQ(c.estimator.max_clock_offset, 0.25);
  EXPECT_EQ(c.estimator.clear_hold, 3.0);
  EXPECT_EQ(c.estimator.settings.noise.imu_accel, 0.004);  // the estimator's keys beside them
  EXPECT_TRUE(c.estimator.enabled);
  // Defaults.
  TwinConfig d;
  EXPECT_EQ(loadError("", &d), "");
  EXPECT_EQ(d.estimator.max_clock_offset, 0.5);
  EXPECT_EQ(d.estimator.clear_hold, 2.0);
  // Printed back (--print-config) and read again.
  const std::string text = toToml(c);
  EXPECT_NE(text.find("max_clock_offset = 0.25"), std::string::npos) << text;
  EXPECT_NE(text.find("clear_hold = 3.0"), std::string::npos) << text;
  TwinConfig e;
  EXPECT_EQ(loadError(text, &e), "");
  EXPECT_EQ(e.estimator.max_clock_offset, 0.25);
  EXPECT_EQ(e.estimator.clear_hold, 3.0);
  // Bad values name the file line and key.
  const std::string neg = loadError("[sensors]\n\nmax_clock_offset = -1\n");
  EXPECT_NE(neg.find(":3: sensors.max_clock_offset: must be in (0, 10]"), std::string::npos) << neg;
  const std::string big = loadError("[estimator]\nclear_hold = 100\n");
  EXPECT_NE(big.find(":2: estimator.clear_hold: must be in [0, 60]"), std::string::npos) << big;
  const std::string type = loadError("[sensors]\nmax_clock_offset = \"soon\"\n");
  EXPECT_NE(type.find("sensors.max_clock_offset: must be a number"), std::string::npos) << type;
}
