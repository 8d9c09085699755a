// Test helper (tests/dash, not installed): publishes synthetic forecast_t
// messages on <prefix>HOIST_FORECAST, as hoist-twind will once its forecast
// worker runs), for the dashboard's Node tests.
//
//   hoist-test-forecast-pub LCM_URL [PREFIX] [COUNT] [PERIOD_MS]
//
// Each message: seq = k, t_start = 20 + k, two scenarios --
//   "estop":    worst 12.5 mm at +2.0 s, WARNING in 1.5 s, CRITICAL in 2.5 s,
//               lambda_0 2.40 .. 15.00 kN, 50 series points;
//   "<img src=x onerror=alert(1)>\x1b[2J" (a hostile name: must stay text):
//               worst 40.0 mm at +6.0 s, no WARNING / CRITICAL (-1), 20 points.
// Before the first valid message it publishes one forecast whose
// scenarios[0].num_points claims 30000 (the checked decoder must drop it).
// With the first valid one, a PREDICTED_CLEARANCE WARNING RAISE on
// <prefix>HOIST_ALARM as the daemon raises it: value 19.39 s to the crossing,
// threshold 20 s (the horizon) -- seconds, not metres.
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "hoist/alarm_t.hpp"
#include "raised_alarm.hpp"
#include "hoist/forecast_t.hpp"

namespace {

hoist::forecast_scenario_t scenario(const std::string& name, int n, double worst, double t_worst, double t_warn,
                                    double t_crit) {
  hoist::forecast_scenario_t s{};
  s.name = name;
  s.status = hoist::forecast_scenario_t::STATUS_OK;
  s.horizon = s.t_reached = 20.0;
  s.min_clearance = worst;
  s.t_min_clearance = t_worst;
  s.t_warning = t_warn;
  s.t_critical = t_crit;
  s.peak_y_c = 0.01;
  s.peak_theta = 1e-3;
  for (int k = 0; k < 4; ++k) s.peak_lambdas[k] = 40.0 + k;
  s.lambda0_min = 2400.0;
  s.lambda0_max = 15000.0;
  s.num_points = static_cast<std::int16_t>(n);
  for (int i = 0; i < n; ++i) {
    const double t = 20.0 * (i + 1) / n;
    s.series_t.push_back(t);
    s.series_min_clearance.push_back(worst + 0.0002 * (t - t_worst) * (t - t_worst));
    s.series_lambda0_min.push_back(8848.0 - 3000.0 * (i % 7) / 6.0);
    s.series_lambda0_max.push_back(8848.0 + 3000.0 * (i % 5) / 4.0);
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s LCM_URL [PREFIX] [COUNT] [PERIOD_MS]\n", argv[0]);
    return 2;
  }
  const std::string prefix = argc > 2 ? argv[2] : "";
  const int count = argc > 3 ? std::atoi(argv[3]) : 20;
  const int period_ms = argc > 4 ? std::atoi(argv[4]) : 250;
  ::lcm::LCM lcm(argv[1]);
  if (!lcm.good()) return 1;
  const std::string ch = prefix + "HOIST_FORECAST";
  DaemonVoice voice(lcm, prefix, 3000);  // the daemon's instance id, as hoist-twind's own forecasts carry
  for (int k = 0; k < count; ++k) {
    hoist::forecast_t f{};
    f.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::system_clock::now().time_since_epoch())
                  .count();
    f.seq = k;
    f.instance_id = voice.instance;
    f.t_start = 20.0 + k;
    f.l = 150.0;
    f.v = 5.0;
    f.plan_seq = -1;
    f.compute_time = 0.02;
    f.num_scenarios = 2;
    f.scenarios = {scenario("estop", 50, 0.0125, 2.0, 1.5, 2.5),
                   scenario("<img src=x onerror=alert(1)>\x1b[2J", 20, 0.040, 6.0, -1.0, -1.0)};
    std::vector<std::uint8_t> b(static_cast<std::size_t>(f.getEncodedSize()));
    f.encode(b.data(), 0, static_cast<int>(b.size()));
    if (k == 0) {
      // scenarios[0].num_points at 8 + 9 * 8 + 1 + (4 + 6) + 1 + 112: 30000.
      std::vector<std::uint8_t> bad = b;
      const std::size_t np = 8 + 9 * 8 + 1 + 4 + 6 + 1 + 112;
      bad[np] = 0x75;
      bad[np + 1] = 0x30;
      lcm.publish(ch, bad.data(), static_cast<unsigned>(bad.size()));
    }
    lcm.publish(ch, b.data(), static_cast<unsigned>(b.size()));
    if (k == 0) {
      const hoist::alarm_t a = voice.sign(raisedAlarm(
          f.utime, f.t_start, "PREDICTED_CLEARANCE", hoist::alarm_t::LEVEL_WARNING, 19.39, 20.0,
          "PREDICTED_CLEARANCE WARNING raised: forecast scenario 'estop' crosses the CRITICAL clearance threshold "
          "in 19.4 s (horizon 20 s) [unacknowledged]"));
      lcm.publish(prefix + "HOIST_ALARM", &a);
    }
    std::printf("published %s seq %d (%zu bytes)\n", ch.c_str(), k, b.size());
    std::fflush(stdout);
    std::this_thread::sleep_for(std::chrono::milliseconds(period_ms));
  }
  return 0;
}
