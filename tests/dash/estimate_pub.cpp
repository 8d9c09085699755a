// Test helper (tests/dash, not installed): publishes synthetic estimate_t
// messages on <prefix>HOIST_ESTIMATE, as hoist-twind does with [estimator]
// enabled, for the dashboard's Node tests.
//
//   hoist-test-estimate-pub LCM_URL PREFIX COUNT PERIOD_MS [MODE]
//
// Realistic values (utime = wall clock): Fa = 1502 +- 0.3 N (sigma 3.1 N),
// b = 0.601 +- 0.002 m (sigma 0.0102 m), theta = 6.5e-4 +- 1e-5 rad (sigma
// 1e-5 rad) against an open-loop theta of 8.3e-4 rad, the window's NIS about
// 306 over 300 degrees of freedom (bounds 253.9 .. 349.9, MODEL_MISMATCH
// bound 372), both sensors in use.  MODE:
//   normal    (default) as above;
//   mismatch  NIS 450 over the bound: mismatch, nis_exceeded; first one
//             MODEL_MISMATCH WARNING RAISE on <prefix>HOIST_ALARM (value 450,
//             threshold 372), as the daemon raises it;
//   norope    the rope load cell is gone: Fa and b not observed (sigma -1),
//             sensors = IMU only;
//   inuse     as normal, the daemon's alarms judge the estimate (in_use), and
//             a cage_state_t of the open-loop twin (theta = theta_open =
//             8.3e-4 rad, l, y_c) on <prefix>HOIST_CAGE with each estimate;
//   calibrating  as normal, a load an operator declared known is in force
//             (calibrating, after alarm_ack_t ACTION_CALIBRATE).
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "hoist/alarm_t.hpp"
#include "raised_alarm.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/estimate_t.hpp"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: hoist-test-estimate-pub LCM_URL PREFIX COUNT PERIOD_MS [normal|mismatch|norope|inuse|calibrating]\n");
    return 2;
  }
  const std::string prefix = argv[2];
  const int count = std::atoi(argv[3]);
  const int period_ms = std::atoi(argv[4]);
  const std::string mode = argc > 5 ? argv[5] : "normal";
  if (mode != "normal" && mode != "mismatch" && mode != "norope" && mode != "inuse" &&
      mode != "calibrating") {
    std::fprintf(stderr, "hoist-test-estimate-pub: unknown MODE '%s'\n", mode.c_str());
    return 2;
  }
  ::lcm::LCM lcm(argv[1]);
  if (!lcm.good()) {
    std::fprintf(stderr, "hoist-test-estimate-pub: cannot open LCM at %s\n", argv[1]);
    return 1;
  }
  const std::string ch = prefix + "HOIST_ESTIMATE";
  for (int k = 0; k < count; ++k) {
    hoist::estimate_t e{};
    e.utime = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    e.seq = k;
    e.instance_id = 4242;
    e.t = 0.01 * k;
    e.l = 50.0 + 0.045 * k;
    e.v = 4.5;
    e.Fa = 1502.0 + 0.3 * std::sin(0.1 * k);
    e.sigma_Fa = 3.1;
    e.b = 0.601 + 0.002 * std::sin(0.05 * k);
    e.sigma_b = 0.0102;
    e.moment = e.Fa * e.b;
    e.sigma_moment = 16.0;
    e.x_c = 0.0016;
    e.sigma_x_c = 1e-4;
    e.y_c = 2.5e-3 + 1e-4 * std::sin(0.07 * k);
    e.sigma_y_c = 1.5e-4;
    e.theta = 6.5e-4 + 1e-5 * std::sin(0.05 * k);
    e.sigma_theta = 1e-5;
    e.theta_open = 8.3e-4;
    for (int i = 0; i < 5; ++i) {
      e.lambdas[i] = i == 0 ? 31000.0 : 40.0 + 10.0 * i;
      e.sigma_lambdas[i] = i == 0 ? 5.0 : 1.5;
    }
    e.nis = 1.0 + 0.5 * std::sin(0.3 * k);
    e.nis_dof = 300;
    e.nis_window = 306.0 + 4.0 * std::sin(0.02 * k);
    e.nis_lower = 253.9;
    e.nis_upper = 349.9;
    e.nis_bound = 372.0;
    e.drift = 0.4;
    e.sensors = 7;  // SENSOR_IMU_ACCEL, SENSOR_IMU_RATE, SENSOR_ROPE_LOAD
    e.imu_age = 0.004;
    e.rope_load_age = 0.009;
    e.fa_observed = 1;
    e.moment_observed = 1;
    e.accepted = 1000 + k;
    e.gated = 2;
    e.implausible = 1;
    // The last recorded trip's detectability: trip 12 could see a 30 %
    // preload loss (5.2 sigma); with the rope load cell gone, trip 13 not.
    e.detect_trip = 12;
    e.loss30_separation = 5.2;
    e.loss30_visible = 1;
    if (mode == "mismatch") {
      e.nis_window = 450.0;
      e.mismatch = 1;
      e.nis_exceeded = 1;
      if (k == 0) {
        DaemonVoice voice(lcm, prefix, 300);  // no daemon here: a health of instance 4242 first
        const hoist::alarm_t a =
            voice.sign(raisedAlarm(e.utime, e.t, "MODEL_MISMATCH", hoist::alarm_t::LEVEL_WARNING, 450.0, 372.0,
                                   "MODEL_MISMATCH WARNING raised: the shaft does not behave like its model"));
        lcm.publish(prefix + "HOIST_ALARM", &a);
      }
    } else if (mode == "norope") {
      e.sigma_Fa = e.sigma_b = -1.0;
      e.Fa = 1500.0;  // the configured load: no estimate
      e.b = 0.0;
      e.sensors = 3;  // the IMU only
      e.rope_load_age = -1.0;
      e.fa_observed = 0;
      e.detect_trip = 13;
      e.loss30_separation = 1.6;
      e.loss30_visible = 0;
    }
    if (mode == "calibrating") e.calibrating = 1;
    if (mode == "inuse") {
      e.in_use = 1;
      hoist::cage_state_t c{};
      c.utime = e.utime;
      c.seq = k;
      c.instance_id = e.instance_id;
      c.t = e.t;
      c.l = e.l;
      c.v = e.v;
      c.y_c = 2.9e-3;
      c.theta = e.theta_open;
      c.y_top = c.y_bottom = c.y_c;
      c.clearance_pos_y = 0.016 - c.y_c;
      c.clearance_neg_y = 0.016 + c.y_c;
      c.clearance_guide = 0.3;
      c.min_clearance = c.clearance_pos_y;
      c.lambdas[0] = 31000.0;
      lcm.publish(prefix + "HOIST_CAGE", &c);
    }
    lcm.publish(ch, &e);
    std::this_thread::sleep_for(std::chrono::milliseconds(period_ms));
  }
  std::printf("published %d estimates on %s (%s)\n", count, ch.c_str(), mode.c_str());
  return 0;
}
