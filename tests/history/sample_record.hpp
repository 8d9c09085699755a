// sample_record.hpp -- trip records for the history tests: every field set
// to a distinct value that depends on (seed, trip), so a column that is not
// stored, swapped or truncated shows; and an independent, hand-written
// field-by-field comparison (not the schema's table, which it checks).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>

#include "hoist/history/store.hpp"
#include "hoist/trip_record.hpp"

namespace hoist::test {

inline TripRecord sampleRecord(std::int64_t trip, const std::string& shaft = "", int bins = 12) {
  std::mt19937_64 g(static_cast<std::uint64_t>(trip) * 7919u + shaft.size());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto x = [&](double scale) { return scale * u(g); };
  TripRecord r;
  r.shaft = shaft;
  r.trip = trip;
  r.wall_start_us = 1'700'000'000'000'000LL + trip * 120'000'000LL;
  r.wall_end_us = r.wall_start_us + 60'000'000LL + trip;
  r.t_start = 120.0 * trip + x(1e-3);
  r.t_end = r.t_start + 60.0 + x(1.0);
  r.direction = trip % 2 ? TripDirection::Down : TripDirection::Up;
  r.depth_start = trip % 2 ? 10.0 : 900.0 + x(1.0);
  r.depth_end = trip % 2 ? 900.0 + x(1.0) : 10.0;
  r.peak_speed = 12.0 + x(0.1);
  r.peak_accel = 0.8 + x(0.01);
  r.Fa_start = 1e5 + x(1e4), r.sigma_Fa_start = 300.0 + x(10.0), r.Fa_end = 2e5 + x(1e4), r.sigma_Fa_end = 310.0 + x(10.0);
  r.moment_start = x(1e5), r.sigma_moment_start = 500.0 + x(1.0), r.moment_end = x(1e5), r.sigma_moment_end = -1.0;
  r.b_start = x(0.5), r.sigma_b_start = 0.01 + x(1e-3), r.b_end = x(0.5), r.sigma_b_end = 0.02 + x(1e-3);
  r.nis_peak = 1.0 + x(0.3);
  r.constancy_peak = 2.0 + x(0.3);
  r.mismatch = trip % 3 == 0;
  r.min_clearance = 0.05 + x(0.01);
  r.min_clearance_depth = 400.0 + x(100.0);
  r.lambda0_min = 5e5 + x(1e4), r.lambda0_max = 7e5 + x(1e4);
  r.lambda_guide_max = 2e3 + x(1e2);
  if (trip % 3 == 0) r.alarms = {"MODEL_MISMATCH", "GUIDE_PRELOAD_LOW"};
  if (trip % 5 == 0) r.alarms.push_back("SHAFT_FINGERPRINT");
  r.depth_bin = 10.0;
  for (int i = 0; i < bins; ++i) {
    DepthBinStats b;
    b.depth_lo = 10.0 * i;
    b.samples = 100 + i + static_cast<int>(trip);
    b.fy_mean = x(1e-3), b.fy_rms = 1e-2 + x(1e-3), b.fy_hf_rms = 2e-2 + x(1e-3);
    b.resid_mean = x(1e-4), b.resid_rms = 1e-3 + x(1e-4);
    b.y_c_mean = x(1e-3), b.y_c_rms = 1e-3 + x(1e-4);
    b.theta_mean = x(1e-4), b.theta_rms = 1e-4 + x(1e-5);
    r.bins.push_back(b);
  }
  r.id.attempted = true;
  r.id.scale = 0.9 + x(0.1);
  r.id.sigma_scale = 0.03 + x(0.01);
  r.id.moment = x(1e5), r.id.sigma_moment = 400.0 + x(10.0);
  r.id.imbalance = x(0.1), r.id.sigma_imbalance = trip % 2 ? -1.0 : 0.2 + x(0.01);
  r.id.informative = trip % 4 != 0;
  r.id.loss30_separation = 0.3 / r.id.sigma_scale;
  r.id.chi2 = 1000.0 + x(50.0);
  r.id.dof = 998 + static_cast<int>(trip);
  r.id.cpu_seconds = 0.2 + x(0.05);
  r.id.note = trip % 4 ? "" : "moment near zero: the trip carries \"little\" information, \xc2\xb1 it's fine";
  return r;
}

/// Field by field, written out by hand (independent of history/schema.cpp).
/// sampleRecord with the preload identified: s +- 0.03, informative (for
/// the trend's tests: hoist/preload_trend.hpp).
inline TripRecord identifiedRecord(std::int64_t trip, double s, const std::string& shaft = "", int bins = 4) {
  TripRecord r = sampleRecord(trip, shaft, bins);
  r.id.scale = s;
  r.id.sigma_scale = 0.03;
  r.id.informative = true;
  return r;
}

inline void expectSameRecord(const TripRecord& a, const TripRecord& b) {
  EXPECT_EQ(a.shaft, b.shaft);
  EXPECT_EQ(a.trip, b.trip);
  EXPECT_EQ(a.wall_start_us, b.wall_start_us);
  EXPECT_EQ(a.wall_end_us, b.wall_end_us);
  EXPECT_EQ(a.t_start, b.t_start);
  EXPECT_EQ(a.t_end, b.t_end);
  EXPECT_EQ(a.direction, b.direction);
  EXPECT_EQ(a.depth_start, b.depth_start);
  EXPECT_EQ(a.depth_end, b.depth_end);
  EXPECT_EQ(a.peak_speed, b.peak_speed);
  EXPECT_EQ(a.peak_accel, b.peak_accel);
  EXPECT_EQ(a.Fa_start, b.Fa_start);
  EXPECT_EQ(a.sigma_Fa_start, b.sigma_Fa_start);
  EXPECT_EQ(a.Fa_end, b.Fa_end);
  EXPECT_EQ(a.sigma_Fa_end, b.sigma_Fa_end);
  EXPECT_EQ(a.moment_start, b.moment_start);
  EXPECT_EQ(a.sigma_moment_start, b.sigma_moment_start);
  EXPECT_EQ(a.moment_end, b.moment_end);
  EXPECT_EQ(a.sigma_moment_end, b.sigma_moment_end);
  EXPECT_EQ(a.b_start, b.b_start);
  EXPECT_EQ(a.sigma_b_start, b.sigma_b_start);
  EXPECT_EQ(a.b_end, b.b_end);
  EXPECT_EQ(a.sigma_b_end, b.sigma_b_end);
  EXPECT_EQ(a.nis_peak, b.nis_peak);
  EXPECT_EQ(a.constancy_peak, b.constancy_peak);
  EXPECT_EQ(a.mismatch, b.mismatch);
  EXPECT_EQ(a.min_clearance, b.min_clearance);
  EXPECT_EQ(a.min_clearance_depth, b.min_clearance_depth);
  EXPECT_EQ(a.lambda0_min, b.lambda0_min);
  EXPECT_EQ(a.lambda0_max, b.lambda0_max);
  EXPECT_EQ(a.lambda_guide_max, b.lambda_guide_max);
  EXPECT_EQ(a.alarms, b.alarms);
  EXPECT_EQ(a.depth_bin, b.depth_bin);
  ASSERT_EQ(a.bins.size(), b.bins.size());
  for (std::size_t i = 0; i < a.bins.size(); ++i) {
    SCOPED_TRACE("bin " + std::to_string(i));
    const auto &x = a.bins[i], &y = b.bins[i];
    EXPECT_EQ(x.depth_lo, y.depth_lo);
    EXPECT_EQ(x.samples, y.samples);
    EXPECT_EQ(x.fy_mean, y.fy_mean);
    EXPECT_EQ(x.fy_rms, y.fy_rms);
    EXPECT_EQ(x.fy_hf_rms, y.fy_hf_rms);
    EXPECT_EQ(x.resid_mean, y.resid_mean);
    EXPECT_EQ(x.resid_rms, y.resid_rms);
    EXPECT_EQ(x.y_c_mean, y.y_c_mean);
    EXPECT_EQ(x.y_c_rms, y.y_c_rms);
    EXPECT_EQ(x.theta_mean, y.theta_mean);
    EXPECT_EQ(x.theta_rms, y.theta_rms);
  }
  EXPECT_EQ(a.id.attempted, b.id.attempted);
  EXPECT_EQ(a.id.scale, b.id.scale);
  EXPECT_EQ(a.id.sigma_scale, b.id.sigma_scale);
  EXPECT_EQ(a.id.moment, b.id.moment);
  EXPECT_EQ(a.id.sigma_moment, b.id.sigma_moment);
  EXPECT_EQ(a.id.imbalance, b.id.imbalance);
  EXPECT_EQ(a.id.sigma_imbalance, b.id.sigma_imbalance);
  EXPECT_EQ(a.id.informative, b.id.informative);
  EXPECT_EQ(a.id.loss30_separation, b.id.loss30_separation);
  EXPECT_EQ(a.id.chi2, b.id.chi2);
  EXPECT_EQ(a.id.dof, b.id.dof);
  EXPECT_EQ(a.id.cpu_seconds, b.id.cpu_seconds);
  EXPECT_EQ(a.id.note, b.id.note);
}

/// The message of the history::StoreError `f` throws, or "(no error)".
inline std::string storeErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const history::StoreError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace hoist::test
