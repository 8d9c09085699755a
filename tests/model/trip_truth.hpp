// Test support (issue 32): truths for the trip tests, made by the project's
// own model at a high n with the static correction, read by the sensor model
// with seeded white noise.
//
// The model is linear in its loads for given kinematics, so one trip's truth
// for ANY load is the superposition of three runs of the truth model on the
// trip's kinematics (exact to round-off, LoadEstimator.SensitivityIsTheExactDerivative):
//   full:  Forcing::Full with no eccentric load (the rope force of the empty cage)
//   unit:  Forcing::LoadOnly with Fa = 1 N, M = 1 N m
//   dist:  Forcing::LoadOnly driven by a disturbance moment D(l) that acts only
//          while the cage's top sleeves are in [dist_from, dist_from + dist_len)
//          (a local lateral push on the cage, e.g. air from a station inset,
//          acting off its axis) -- set through FastSolver::setLoad per step
// z = full + Fa unit_long + M unit_lat + dist.  TripTruth caches these per
// (preload scale, kinematics) so sequences of many trips cost a few runs.
#pragma once

#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <tuple>
#include <vector>

#include "hoist/load_estimator.hpp"

namespace hoist::test {

/// Kinematics of one trip segment: `pre` s of rest at l0, a jerk-limited trip
/// of `travel` m (> 0 down), rest until `total` s; sampled every dt from 0.
inline std::vector<ProfileSample> tripKinematics(double l0, double travel, double pre, double total,
                                                 double vmax = 8.0, double amax = 1.0, double jmax = 1.0,
                                                 double dt = 0.01) {
  const HoistProfile p = HoistProfile::sCurve(l0, vmax, amax, jmax, travel, total - pre, dt);
  std::vector<ProfileSample> out;
  const int n = static_cast<int>(std::lround(total / dt));
  for (int i = 0; i <= n; ++i) {
    const double t = i * dt;
    out.push_back({t, p.at(t - pre)});
  }
  return out;
}

struct UnitRuns {
  std::vector<double> rope0, rope_unit, fy_unit, om_unit, fy_dist, om_dist;
};

/// Runs of the truth model over `kin` (4 substeps per sample).
inline UnitRuns truthRuns(ShaftParams p, double scale, const std::vector<ProfileSample>& kin, double dist = 0.0,
                          double dist_from = 0.0, double dist_len = 10.0) {
  p.Tb1 *= scale;
  p.Tb2 *= scale;
  UnitRuns u;
  const int sub = 4;
  auto run = [&](ShaftParams q, Forcing f, bool disturbed, std::vector<double>* rope, std::vector<double>* fy,
                 std::vector<double>* om) {
    FastSolver s(std::make_shared<const ShaftModel>(q), f);
    auto window = [&](double l) { return l >= dist_from && l < dist_from + dist_len ? dist : 0.0; };
    if (disturbed) s.setLoad(0.0, window(kin.front().k.l));
    s.initialize(kin.front().t, kin.front().k, InitialState::Static);
    for (std::size_t i = 0; i < kin.size(); ++i) {
      if (i > 0) {
        const double h = kin[i].t - kin[i - 1].t;
        for (int j = 1; j <= sub; ++j) {
          const Kinematics kj = interpolate(kin[i - 1].k, kin[i].k, h, double(j) / sub);
          if (disturbed) s.setLoad(0.0, window(kj.l));
          s.step(kin[i - 1].t + j * h / sub, kj);
        }
      }
      const SensorValues z = sensorModel(s.response(), q.g);
      if (rope) rope->push_back(z.rope_load);
      if (fy) fy->push_back(z.f_y);
      if (om) om->push_back(z.omega);
    }
  };
  ShaftParams q0 = p;
  q0.Fa = 0.0;
  q0.b = 0.0;
  run(q0, Forcing::Full, false, &u.rope0, nullptr, nullptr);
  ShaftParams q1 = p;
  q1.Fa = 1.0;
  q1.b = 1.0;
  run(q1, Forcing::LoadOnly, false, &u.rope_unit, &u.fy_unit, &u.om_unit);
  if (dist != 0.0) run(q1, Forcing::LoadOnly, true, nullptr, &u.fy_dist, &u.om_dist);
  return u;
}

/// Samples of one trip segment starting at model time t0 under load (Fa, b).
inline std::vector<MeasurementSample> tripSamples(const UnitRuns& u, const std::vector<ProfileSample>& kin,
                                                  double t0, double Fa, double b, const SensorNoise& noise,
                                                  unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N01(0.0, 1.0);
  std::vector<MeasurementSample> out;
  const double M = Fa * b;
  for (std::size_t i = 0; i < kin.size(); ++i) {
    MeasurementSample m;
    m.t = t0 + kin[i].t;
    m.k = kin[i].k;
    double fy = M * u.fy_unit[i], om = M * u.om_unit[i];
    if (!u.fy_dist.empty()) {
      fy += u.fy_dist[i];
      om += u.om_dist[i];
    }
    m.z = {fy + noise.imu_accel * N01(rng), om + noise.imu_rate * N01(rng),
           u.rope0[i] + Fa * u.rope_unit[i] + noise.rope_load * N01(rng)};
    m.present = kSensorImuAccel | kSensorImuRate | kSensorRopeLoad;
    out.push_back(m);
  }
  return out;
}

}  // namespace hoist::test
