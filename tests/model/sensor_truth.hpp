// Truths for the load estimator's tests: the project's own model at a high n
// (static correction on) driven by a load the estimator's config does not
// know, read through the sensor model (hoist::sensorModel) with what real
// sensors add: seeded white noise, band-limited vibration the model does not
// carry, an accelerometer offset.  Header-only; used by the
// tests/model/load_estimator*_test.cpp files.
//
// simulate() is the expensive part (a high-n run); measure() adds the
// sensors' errors for one seed and is cheap, so many seeds share one run.
#pragma once

#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "hoist/fast_solver.hpp"
#include "hoist/load_estimator.hpp"
#include "hoist/profile.hpp"

namespace hoist::test {

struct Load {
  double Fa, b;
};

/// The true response, every 0.01 s: kinematics, noise-free sensor values and the true loads and state.
struct CleanTruth {
  std::vector<double> t;
  std::vector<Kinematics> k;
  std::vector<SensorValues> z;
  std::vector<double> Fa, M, theta, y_c;
};

/// The shaft `p` at n = n_truth under `load` (and, from t_step on, `step` on
/// top of it, applied as a step: the exact superposition of a load-only
/// solver started at rest then) on `prof`.
inline CleanTruth simulate(ShaftParams p, const HoistProfile& prof, Load load, int n_truth, double t_step = -1.0,
                           Load step = {0.0, 0.0}) {
  p.n = n_truth;
  p.static_correction = true;
  p.Fa = load.Fa;
  p.b = load.b;
  FastSolver s(std::make_shared<const ShaftModel>(p));
  ShaftParams ps = p;
  ps.Fa = step.Fa;
  ps.b = step.Fa != 0.0 ? step.b : 0.0;
  FastSolver ds(std::make_shared<const ShaftModel>(ps), Forcing::LoadOnly);
  bool stepped = false;
  CleanTruth tr;
  const double dt = 0.01;
  const int sub = 4;
  const double t0 = prof.startTime(), t_end = prof.endTime();
  const int nout = static_cast<int>(std::floor((t_end - t0) / dt + 1e-9));
  s.initialize(t0, prof.at(t0));
  for (int k = 0; k <= nout; ++k) {
    const double t = t0 + k * dt;
    if (k > 0) {
      for (int j = 1; j <= sub; ++j) {
        const double tj = t0 + (k - 1) * dt + j * dt / sub;
        s.step(tj, prof.at(tj));
        if (stepped) ds.step(tj, prof.at(tj));
      }
    }
    if (t_step >= 0.0 && !stepped && t >= t_step - 1e-9) {
      ds.initialize(t, prof.at(t), InitialState::Rest);
      stepped = true;
    }
    CageResponse r = s.response();
    double Fa = load.Fa, M = load.Fa * load.b;
    if (stepped) {
      const CageResponse& d = ds.response();
      r.y_c += d.y_c;
      r.theta += d.theta;
      r.y_c_ddot += d.y_c_ddot;
      r.theta_dot += d.theta_dot;
      r.lambda[0] += d.lambda[0];
      Fa += step.Fa;
      M += step.Fa * step.b;
    }
    tr.t.push_back(t);
    tr.k.push_back(prof.at(t));
    tr.z.push_back(sensorModel(r, p.g));
    tr.Fa.push_back(Fa);
    tr.M.push_back(M);
    tr.theta.push_back(r.theta);
    tr.y_c.push_back(r.y_c);
  }
  return tr;
}

/// Band-limited noise: a random-phase multisine of `lines` lines with
/// frequencies drawn uniformly in [f_lo, f_hi] Hz and equal amplitudes, so
/// its power lies in the band by construction and its RMS is `rms`.
class BandNoise {
 public:
  BandNoise(double f_lo, double f_hi, double rms, unsigned seed, int lines = 64) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> f(f_lo, f_hi), ph(0.0, 2.0 * std::numbers::pi);
    const double amp = rms * std::sqrt(2.0 / lines);
    for (int i = 0; i < lines; ++i) lines_.push_back({2.0 * std::numbers::pi * f(rng), ph(rng), amp});
  }
  double at(double t) const {
    double s = 0.0;
    for (const Line& l : lines_) s += l.amp * std::sin(l.w * t + l.phase);
    return s;
  }

 private:
  struct Line {
    double w, phase, amp;
  };
  std::vector<Line> lines_;
};

/// What the sensors add to the truth.
struct SensorErrors {
  SensorNoise white;           ///< white noise per sample
  double vibration = 0.0;      ///< RMS of 15-50 Hz vibration on f_y, times white.imu_accel
  double accel_offset = 0.0;   ///< constant offset of f_y [m/s^2]
};

/// The truth read by the sensors with `err`, seeded.
inline std::vector<MeasurementSample> measure(const CleanTruth& tr, const SensorErrors& err, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N01(0.0, 1.0);
  const BandNoise vib(15.0, 50.0, err.vibration * err.white.imu_accel, seed * 7919u + 1u);
  std::vector<MeasurementSample> out;
  out.reserve(tr.t.size());
  for (std::size_t i = 0; i < tr.t.size(); ++i) {
    MeasurementSample m;
    m.t = tr.t[i];
    m.k = tr.k[i];
    m.z = {tr.z[i].f_y + err.white.imu_accel * N01(rng) + vib.at(m.t) + err.accel_offset,
           tr.z[i].omega + err.white.imu_rate * N01(rng), tr.z[i].rope_load + err.white.rope_load * N01(rng)};
    m.present = kSensorImuAccel | kSensorImuRate | kSensorRopeLoad;
    out.push_back(m);
  }
  return out;
}

/// A trip down (the paper's 50 -> 300 m), `rest` s at the bottom, the trip
/// back up: the station sequence.  Starts at rest (t = 0 .. 2 s).
inline HoistProfile stationSequence(double rest = 10.0) {
  const HoistProfile down = HoistProfile::trapezoid(50.0, 5.0, 1.0, 250.0, 55.0);
  const HoistProfile up = HoistProfile::trapezoid(300.0, 5.0, 1.0, -250.0, 55.0);
  std::vector<ProfileSample> s;
  const double dt = 0.01;
  const double t_down = 2.0, t_up = t_down + 55.0 + rest, t_end = t_up + 60.0;
  for (int i = 0; i * dt <= t_end + 1e-9; ++i) {
    const double t = i * dt;
    Kinematics k;
    if (t < t_down) k = {50.0, 0.0, 0.0};
    else if (t < t_up) k = down.at(std::min(t - t_down, 55.0));
    else k = up.at(t - t_up);
    if (t >= t_down && t < t_up && t - t_down >= 55.0) k = {300.0, 0.0, 0.0};
    s.push_back({t, k});
  }
  return HoistProfile(std::move(s));
}

}  // namespace hoist::test
