// Trips and their records (hoist/trip_detector.hpp, trip_accumulator.hpp,
// trip_recorder.hpp, trip_pipeline.hpp): the detector on hand-made winder
// signals, the accumulator's figures against values computed by hand, and
// recordTrips on a recording of two trips made by our own model at n = 60.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "hoist/clearance.hpp"
#include "hoist/trip_pipeline.hpp"
#include "hoist/trip_recorder.hpp"
#include "trip_truth.hpp"

using namespace hoist;
using namespace hoist::test;

namespace {

Kinematics kin(double l, double v, double a) { return {l, v, a}; }

}  // namespace

TEST(TripDetector, RestMovingRestWithHysteresisAndInching) {
  TripDetectorSettings s;  // rest_speed 0.01, leave at 0.02, hold 1 s, min travel 0.5 m
  TripDetector d(s);
  std::vector<std::pair<double, TripEvent>> ev;
  std::vector<double> deps;
  double l = 100.0, t = 0.0;
  auto feed = [&](double v, double a, double dur) {
    for (double u = 0.0; u < dur - 1e-9; u += 0.01) {
      t += 0.01;
      l += v * 0.01;
      const TripEvent e = d.update(t, kin(l, v, a));
      if (e != TripEvent::None) ev.emplace_back(t, e);
      if (e == TripEvent::Departed) deps.push_back(d.departureTime());
    }
  };
  feed(0.5, 0.0, 1.0);    // the recording starts moving: no departure known
  feed(0.0, 0.0, 2.0);    // rest
  feed(0.015, 0.0, 3.0);  // hovering between the thresholds: still at rest, no trip
  feed(0.0, 0.0, 1.0);
  const double t_dep = t;
  feed(2.0, 0.0, 10.0);   // a trip of 20 m ...
  feed(0.005, 0.0, 0.5);  // ... a short pause that is not an arrival ...
  feed(2.0, 0.0, 5.0);    // ... and on
  const double t_arr = t;
  feed(0.0, 0.0, 3.0);
  feed(0.03, 0.0, 2.0);   // inching 6 cm: not a trip
  feed(0.0, 0.0, 2.0);
  ASSERT_EQ(ev.size(), 4u);
  EXPECT_EQ(ev[0].second, TripEvent::Departed);
  EXPECT_NEAR(deps[0], t_dep, 1e-9);  // the last still sample before the motion
  EXPECT_NEAR(ev[0].first, t_dep + 0.01, 1e-9);
  EXPECT_EQ(ev[1].second, TripEvent::Arrived);
  EXPECT_NEAR(ev[1].first, t_arr + 0.01 + 1.0, 0.011);
  EXPECT_EQ(ev[2].second, TripEvent::Departed);
  EXPECT_EQ(ev[3].second, TripEvent::NotATrip);
  EXPECT_THROW(TripDetector(TripDetectorSettings{0.0}), std::invalid_argument);
}

TEST(TripAccumulator, FiguresOfAHandMadeTrip) {
  ShaftParams twin;
  twin.n = 8;
  EstimatorSettings est;
  ConditionSettings cond;
  cond.depth_bin = 10.0;
  cond.band_hz = 1.0;
  TripAccumulator acc(twin, est, cond, 0.01);
  // 30 m down at 1 m/s with constant f_y = 0.01 and a 10 Hz +-0.003 square wave above the band.
  LoadEstimate e;
  e.Fa = 1500.0;
  e.sigma_Fa = 10.0;
  e.fa_observed = true;
  e.moment = 900.0;
  e.sigma_moment = 20.0;
  e.moment_observed = true;
  e.b = 0.6;
  e.sigma_b = 0.01;
  e.lambda = {9000.0, 10.0, -20.0, 30.0, -40.0};
  MeasurementSample m;
  m.present = kSensorImuAccel;
  for (int i = 0; i <= 3000; ++i) {
    m.t = 5.0 + i * 0.01;
    const bool moving = i > 0 && i < 3000;
    m.k = kin(40.0 + i * 0.01, moving ? 1.0 : 0.0, 0.0);
    m.z.f_y = 0.01 + ((i / 5) % 2 ? 0.003 : -0.003);
    e.y_c = 1e-3 * (m.k.l - 40.0) / 30.0;
    e.theta = 2e-4;
    e.lambda[0] = 9000.0 + (i == 1500 ? 500.0 : 0.0);
    e.nis_window = i == 2000 ? 300.0 : 100.0;
    e.nis_dof = 100;
    e.mismatch = i == 2500;
    if (i == 3000) e.Fa = 1400.0;
    if (i == 0) acc.begin(m, tripEstimate(e));
    else acc.add(m, tripEstimate(e));
    if (i == 100) acc.addAlarm("CAGE_POS_Y");
    if (i == 200) acc.addAlarm("CAGE_POS_Y");
  }
  const TripRecord r = acc.finish(35.0, m.k);
  EXPECT_EQ(r.direction, TripDirection::Down);
  EXPECT_DOUBLE_EQ(r.t_start, 5.0);
  EXPECT_DOUBLE_EQ(r.t_end, 35.0);
  EXPECT_DOUBLE_EQ(r.depth_start, 40.0);
  EXPECT_NEAR(r.depth_end, 70.0, 1e-9);
  EXPECT_DOUBLE_EQ(r.peak_speed, 1.0);
  EXPECT_DOUBLE_EQ(r.Fa_start, 1500.0);
  EXPECT_DOUBLE_EQ(r.Fa_end, 1400.0);
  EXPECT_DOUBLE_EQ(r.sigma_moment_start, 20.0);
  EXPECT_DOUBLE_EQ(r.nis_peak, 3.0);
  EXPECT_TRUE(r.mismatch);
  EXPECT_DOUBLE_EQ(r.lambda0_max, 9500.0);
  EXPECT_DOUBLE_EQ(r.lambda0_min, 9000.0);
  EXPECT_DOUBLE_EQ(r.lambda_guide_max, 40.0);
  ASSERT_EQ(r.alarms.size(), 1u);
  // Clearance: the bottom sleeve y_c + h theta is largest at the end: 0.3 - (1e-3 + 8 * 2e-4).
  EXPECT_NEAR(r.min_clearance, 0.3 - (1e-3 + 8.0 * 2e-4), 1e-12);
  EXPECT_NEAR(r.min_clearance_depth, 70.0, 1e-9);
  ASSERT_EQ(r.bins.size(), 4u);  // [40, 50), [50, 60), [60, 70), and 70 (the end sample)
  EXPECT_DOUBLE_EQ(r.bins[1].depth_lo, 50.0);
  EXPECT_NEAR(r.bins[1].samples, 1000, 1);
  // The band split: the in-band mean is the constant, the square wave is above the band
  // (a first-order low-pass at 1 Hz passes about 1/(2 pi 10 / 1) of a 10 Hz wave).
  EXPECT_NEAR(r.bins[1].fy_mean, 0.01, 2e-4);
  EXPECT_NEAR(r.bins[1].fy_hf_rms, 0.003, 3e-4);
  EXPECT_NEAR(r.bins[1].y_c_mean, 1e-3 * 15.0 / 30.0, 2e-6);
  EXPECT_NEAR(r.bins[1].theta_rms, 2e-4, 1e-12);
  EXPECT_FALSE(acc.active());
}

TEST(TripRecorder, TicksKeptBeforeTheDepartureKeepTheirGuideDeflection) {
  // Rest, a creep between rest_speed and the departure threshold (kept: the
  // trip starts at the last still sample), the trip, the arrival.  The guide
  // rope is deflected by 0.25 m during the creep only: the record's smallest
  // clearance is the creep's (guide_rope_gap - 0.25), at the creep's depth.
  ShaftParams twin;
  twin.n = 8;
  TripRecorder rec(twin, EstimatorSettings{}, ConditionSettings{}, 0.01);
  LoadEstimate e;
  MeasurementSample m;
  double t = 0.0, l = 100.0;
  bool arrived = false;
  auto feed = [&](double v, double dur, double deflection) {
    for (double u = 0.0; u < dur - 1e-9; u += 0.01) {
      t += 0.01;
      l += v * 0.01;
      m.t = t;
      m.k = kin(l, v, 0.0);
      e.t = t;
      arrived = rec.add(m, e, deflection) || arrived;
    }
  };
  feed(0.0, 2.0, 0.0);
  const double l_creep = l + 0.015 * 0.01;  // the creep's first sample
  feed(0.015, 0.5, 0.25);  // above rest_speed 0.01, below the departure at 0.02
  feed(2.0, 10.0, 0.0);
  feed(0.0, 2.0, 0.0);
  ASSERT_TRUE(arrived);
  const TripRecord& r = rec.record();
  EXPECT_NEAR(r.depth_start, l_creep - 0.015 * 0.01, 1e-9);  // the last still sample
  const double expected = cageClearance(0.0, 0.0, twin.h, 0.25, ConditionSettings{}.clearance).min_clearance;
  EXPECT_NEAR(r.min_clearance, expected, 1e-12);
  EXPECT_NEAR(r.min_clearance_depth, l_creep, 1e-9);
}

TEST(RecordTrips, TwoTripsOfOurOwnModel) {
  ShaftParams truth_p;
  truth_p.n = 60;
  const auto down = tripKinematics(50.0, 150.0, 3.0, 34.0), up = tripKinematics(200.0, -150.0, 3.0, 34.0);
  const UnitRuns ud = truthRuns(truth_p, 1.0, down), uu = truthRuns(truth_p, 1.0, up);
  SensorNoise noise;
  auto samples = tripSamples(ud, down, 0.0, 1600.0, 0.7, noise, 5);
  const auto second = tripSamples(uu, up, samples.back().t + 0.01, 600.0, -0.9, noise, 6);
  samples.insert(samples.end(), second.begin(), second.end());
  ShaftParams twin;
  twin.n = 25;
  EstimatorSettings est;
  ConditionSettings cond;
  double last_progress = 0.0;
  const auto recs = recordTrips(twin, est, cond, 0.0025, samples, [&](double f) { last_progress = f; });
  EXPECT_DOUBLE_EQ(last_progress, 1.0);
  ASSERT_EQ(recs.size(), 2u);
  const double M[2] = {1600.0 * 0.7, -600.0 * 0.9};
  for (int k = 0; k < 2; ++k) {
    const TripRecord& r = recs[k];
    std::printf("[ trip %lld ] %s %.1f -> %.1f m, t %.2f -> %.2f, vmax %.2f, Fa %.0f -> %.0f, M %.0f -> %.0f, "
                "s = %.3f +- %.3f (M %.0f +- %.0f), %zu bins, cpu %.3f s\n  %s\n",
                static_cast<long long>(r.trip), r.direction == TripDirection::Down ? "down" : "up", r.depth_start,
                r.depth_end, r.t_start, r.t_end, r.peak_speed, r.Fa_start, r.Fa_end, r.moment_start, r.moment_end,
                r.id.scale, r.id.sigma_scale, r.id.moment, r.id.sigma_moment, r.bins.size(), r.id.cpu_seconds,
                r.id.note.c_str());
    EXPECT_EQ(r.trip, k + 1);
    EXPECT_EQ(r.direction, k == 0 ? TripDirection::Down : TripDirection::Up);
    EXPECT_NEAR(r.depth_start, k == 0 ? 50.0 : 200.0, 1e-6);
    EXPECT_NEAR(r.depth_end, k == 0 ? 200.0 : 50.0, 1e-6);
    EXPECT_NEAR(r.peak_speed, 8.0, 0.05);
    EXPECT_TRUE(r.id.attempted);
    EXPECT_LT(std::abs(r.id.moment - M[k]), 3.0 * r.id.sigma_moment);
    if (r.id.sigma_scale > 0.0) { EXPECT_LT(std::abs(r.id.scale - 1.0), 3.0 * r.id.sigma_scale); }
    EXPECT_EQ(r.bins.size(), 16u);  // 50 .. 200 m in 10 m bins, the end depth's bin included
    for (const DepthBinStats& b : r.bins) {
      EXPECT_GT(b.samples, 0);
      EXPECT_LT(std::abs(b.resid_mean), 5.0 * noise.imu_accel / std::sqrt(b.samples) + 1e-4) << b.depth_lo;
    }
    EXPECT_LT(std::abs(r.Fa_end - (k == 0 ? 1600.0 : 600.0)), 3.0 * r.sigma_Fa_end);
  }
  EXPECT_NEAR(recs[0].t_start, 3.0, 0.02);  // departs from the last rest sample
  ConditionSettings badc;
  badc.depth_bin = -1.0;
  try {
    recordTrips(twin, est, badc, 0.0025, samples);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("condition.depth_bin"), std::string::npos);
  }
}
