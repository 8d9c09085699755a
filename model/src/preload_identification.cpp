// identifyPreload: the profile chi2(s) over one trip, (M, o) linear at each s (hoist/preload_identification.hpp).
#include "hoist/preload_identification.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace hoist {

namespace {

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

}  // namespace

void unitMomentResponse(const ShaftParams& twin, double scale, double imbalance, double max_step,
                        const std::vector<MeasurementSample>& trip, std::vector<double>& out_fy,
                        std::vector<double>& out_omega) {
  out_fy.assign(trip.size(), 0.0);
  out_omega.assign(trip.size(), 0.0);
  if (trip.empty()) return;
  ShaftParams q = twin;
  q.Tb1 *= scale * (1.0 - imbalance);
  q.Tb2 *= scale * (1.0 + imbalance);
  q.Fa = 1.0;
  q.b = 1.0;
  FastSolver s(std::make_shared<const ShaftModel>(q), Forcing::LoadOnly);
  s.initialize(trip.front().t, trip.front().k, InitialState::Static);
  for (std::size_t i = 0; i < trip.size(); ++i) {
    if (i > 0) {
      const MeasurementSample& prev = trip[i - 1];
      const MeasurementSample& m = trip[i];
      const double h = m.t - prev.t;
      const int n = h > 0.0 ? substepCount(h, max_step) : 1;
      for (int j = 1; j < n; ++j) {
        const double u = static_cast<double>(j) / n;
        s.step(prev.t + u * h, interpolate(prev.k, m.k, h, u));
      }
      s.step(m.t, m.k);
    }
    const SensorValues z = sensorModel(s.response(), q.g);
    out_fy[i] = z.f_y;
    out_omega[i] = z.omega;
  }
}

PreloadFit identifyPreload(const ShaftParams& twin, const EstimatorSettings& est, const PreloadFitOptions& opt,
                           const std::vector<MeasurementSample>& trip) {
  if (!(opt.max_sigma > 0.0) || !(opt.accel_offset_sigma >= 0.0) || !(opt.max_step >= 0.0) ||
      opt.max_iterations < 1 || opt.max_iterations > 50)
    throw std::invalid_argument("identifyPreload: bad options (max_sigma > 0, accel_offset_sigma >= 0, "
                                "max_step >= 0, 1 <= max_iterations <= 50)");
  const double cpu0 = threadCpuSeconds();
  PreloadFit out;
  PreloadIdentification& id = out.id;
  out.fitted_fy.assign(trip.size(), std::numeric_limits<double>::quiet_NaN());
  std::size_t n_acc = 0, n_rate = 0;
  bool moved = false;
  for (const MeasurementSample& m : trip) {
    if (m.present & kSensorImuAccel) ++n_acc;
    if (m.present & kSensorImuRate) ++n_rate;
    moved = moved || std::abs(m.k.v) > est.rest_speed;
  }
  if (n_acc + n_rate == 0 || !moved || trip.size() < 3) {
    id.note = n_acc + n_rate == 0 ? "no IMU samples on this trip: the preload is not identified"
                                  : "the cage did not move: the preload is not identified";
    id.cpu_seconds = threadCpuSeconds() - cpu0;
    return out;
  }
  id.attempted = true;
  const bool fit_offset = opt.accel_offset_sigma > 0.0 && n_acc > 0;
  const int np = fit_offset ? 2 : 1;  // linear unknowns at a given s: M (and o)
  const double sa2 = est.noise.imu_accel * est.noise.imu_accel, sw2 = est.noise.imu_rate * est.noise.imu_rate;
  const double me = est.model_error;
  const int dof = static_cast<int>(n_acc + n_rate) - np - 1 + (fit_offset ? 1 : 0);

  // The profile: at a given s, (M, o) by linear weighted least squares; one
  // solver run per s.  Weights: the sensor's variance plus the model error on
  // the prediction at s = 1 (fixed, so chi2 compares across s).
  std::vector<double> wf(trip.size(), 1.0 / sa2), ww(trip.size(), 1.0 / sw2);
  struct Eval {
    double s = 1.0, chi2 = 0.0, M = 0.0, o = 0.0, varM = 0.0;
    std::vector<double> Hf, Hw;
  };
  std::vector<Eval> evals;
  evals.reserve(3 * static_cast<std::size_t>(opt.max_iterations) + 12);  // references into it stay valid
  auto solveAt = [&](Eval& e) {
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    Eigen::Vector2d r = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < trip.size(); ++i) {
      const MeasurementSample& m = trip[i];
      if (m.present & kSensorImuAccel) {
        const Eigen::Vector2d j(e.Hf[i], 1.0);
        A += wf[i] * j * j.transpose();
        r += wf[i] * m.z.f_y * j;
      }
      if (m.present & kSensorImuRate) {
        A(0, 0) += ww[i] * e.Hw[i] * e.Hw[i];
        r(0) += ww[i] * m.z.omega * e.Hw[i];
      }
    }
    if (fit_offset) {
      A(1, 1) += 1.0 / (opt.accel_offset_sigma * opt.accel_offset_sigma);
      const Eigen::Matrix2d C = A.inverse();
      const Eigen::Vector2d p = C * r;
      e.M = p(0);
      e.o = p(1);
      e.varM = C(0, 0);
    } else {
      e.M = A(0, 0) > 0.0 ? r(0) / A(0, 0) : 0.0;
      e.o = 0.0;
      e.varM = A(0, 0) > 0.0 ? 1.0 / A(0, 0) : std::numeric_limits<double>::infinity();
    }
    e.chi2 = fit_offset ? e.o * e.o / (opt.accel_offset_sigma * opt.accel_offset_sigma) : 0.0;
    for (std::size_t i = 0; i < trip.size(); ++i) {
      const MeasurementSample& m = trip[i];
      if (m.present & kSensorImuAccel) e.chi2 += wf[i] * std::pow(m.z.f_y - e.M * e.Hf[i] - e.o, 2);
      if (m.present & kSensorImuRate) e.chi2 += ww[i] * std::pow(m.z.omega - e.M * e.Hw[i], 2);
    }
  };
  auto evalAt = [&](double sv) -> const Eval& {
    for (const Eval& e : evals)
      if (std::abs(e.s - sv) < 1e-9) return e;
    Eval e;
    e.s = sv;
    unitMomentResponse(twin, sv, 0.0, opt.max_step, trip, e.Hf, e.Hw);
    solveAt(e);
    evals.push_back(std::move(e));
    ++out.iterations;
    return evals.back();
  };
  {
    Eval& e1 = const_cast<Eval&>(evalAt(1.0));
    for (std::size_t i = 0; i < trip.size(); ++i) {
      wf[i] = 1.0 / (sa2 + std::pow(me * e1.M * e1.Hf[i], 2));
      ww[i] = 1.0 / (sw2 + std::pow(me * e1.M * e1.Hw[i], 2));
    }
    solveAt(e1);
  }
  // The profile's minimum: a coarse grid (the information on s sharpens as s
  // falls, so the profile is far from a parabola over the whole range), then
  // local parabolas through (c - d, c, c + d), d ~ one sigma, re-centred on
  // their vertex until it moves less than a quarter of d.
  constexpr double kLo = 0.3, kHi = 1.6;
  const double grid[] = {kLo, 0.5, 0.7, 0.85, 1.0, 1.2, kHi};  // 1.0: the weights' run
  constexpr std::size_t kGrid = sizeof grid / sizeof grid[0];
  std::size_t k = 0;
  for (std::size_t g = 0; g < kGrid; ++g)
    if (evalAt(grid[g]).chi2 < evalAt(grid[k]).chi2) k = g;
  auto best = [&]() -> const Eval& {
    return *std::min_element(evals.begin(), evals.end(), [](const Eval& a, const Eval& b) { return a.chi2 < b.chi2; });
  };
  double s = grid[k], sig_s = -1.0;
  bool bounded = k > 0 && k + 1 < kGrid;
  if (bounded) {
    // First guess of the curvature from the grid neighbours.
    const Eval &a = evalAt(grid[k - 1]), &c = evalAt(grid[k + 1]);
    const Eval& b = evalAt(s);
    const double d1 = (b.chi2 - a.chi2) / (b.s - a.s), d2 = (c.chi2 - b.chi2) / (c.s - b.s);
    const double curv = (d2 - d1) / (c.s - a.s);
    double center = curv > 0.0 ? std::clamp(0.5 * (a.s + b.s) - d1 / (2.0 * curv), a.s, c.s) : s;
    double d = curv > 0.0 ? std::clamp(1.0 / std::sqrt(curv), 0.02, 0.15) : 0.1;
    for (int it = 0; it < opt.max_iterations; ++it) {
      const Eval& lo = evalAt(center - d);
      const Eval& mid = evalAt(center);
      const Eval& hi = evalAt(center + d);
      const double k2 = (lo.chi2 + hi.chi2 - 2.0 * mid.chi2) / (d * d);  // = 2 curv
      if (!(k2 > 0.0)) {
        sig_s = -1.0;
        break;
      }
      sig_s = std::sqrt(2.0 / k2);
      const double v = center - (hi.chi2 - lo.chi2) / (2.0 * d * k2);
      const double dMds = (hi.M - lo.M) / (2.0 * d);
      id.sigma_moment = std::sqrt(mid.varM + dMds * dMds * sig_s * sig_s);
      s = center;
      if (std::abs(v - center) <= 0.25 * d || v < kLo || v > kHi || evals.size() + 3 > evals.capacity()) {
        if (std::abs(v - center) > 0.1 * sig_s && std::abs(v - center) < d && evals.size() < evals.capacity()) {
          evalAt(v);
          s = v;
        }
        break;
      }
      center = v;
      d = std::clamp(sig_s, 0.02, 0.15);
    }
  }
  bounded = bounded && s > kLo && s < kHi;
  if (!(bounded && sig_s > 0.0)) s = 1.0;  // not identifiable: M at the configured preload
  const Eval& fin = evalAt(s);
  if (id.sigma_moment < 0.0) id.sigma_moment = std::sqrt(fin.varM);
  if (!(bounded && sig_s > 0.0)) {
    // s unknown: M's band also spans every moment the search found as
    // plausible (within Delta chi2 = 9 of the best, over s in [0.3, 1.6]).
    double spread = 0.0;
    const double c_best = best().chi2;
    for (const Eval& e : evals)
      if (e.chi2 <= c_best + 9.0) spread = std::max(spread, std::abs(e.M - fin.M));
    id.sigma_moment = std::sqrt(fin.varM + spread * spread);
  }
  const double M = fin.M, chi2 = fin.chi2;
  const double inflate = dof > 0 ? std::sqrt(std::max(1.0, chi2 / dof)) : 1.0;
  for (std::size_t i = 0; i < trip.size(); ++i)
    if (trip[i].present & kSensorImuAccel) out.fitted_fy[i] = M * fin.Hf[i] + fin.o;
  id.scale = bounded && sig_s > 0.0 ? s : best().s;  // not identifiable: where the search ended
  id.moment = M;
  id.sigma_scale = bounded && sig_s > 0.0 ? inflate * sig_s : -1.0;
  id.sigma_moment *= inflate;
  id.chi2 = chi2;
  id.dof = dof;
  id.imbalance = 0.0;
  id.sigma_imbalance = -1.0;
  // Where M is barely known, s is a ratio with heavy tails: not identifiable
  // when M is within 3 sigma of zero.
  if (id.sigma_scale > 0.0 && std::abs(M) <= 3.0 * id.sigma_moment) id.sigma_scale = -1.0;
  id.informative = id.sigma_scale > 0.0 && id.sigma_scale <= opt.max_sigma;
  id.loss30_separation = id.sigma_scale > 0.0 ? 0.3 / id.sigma_scale : 0.0;
  if (id.informative)
    id.note = fmt("this IMU can see a 30 %% preload loss on this trip (s = %.3f +- %.3f: %.1f sigma)", s,
                  id.sigma_scale, id.loss30_separation);
  else if (id.sigma_scale > 0.0)
    id.note = fmt("this IMU cannot see a 30 %% preload loss on this trip (sigma of s %.3g: %.1f sigma; "
                  "moment %.0f N m)",
                  id.sigma_scale, id.loss30_separation, M);
  else if (std::abs(M) <= 3.0 * id.sigma_moment)
    id.note = fmt("this IMU cannot see a 30 %% preload loss on this trip: the moment (%.0f +- %.0f N m) is too "
                  "close to zero to tell the preload",
                  M, id.sigma_moment);
  else
    id.note = fmt("this IMU cannot see a 30 %% preload loss on this trip: the data do not bound the preload "
                  "between %.1f and %.1f of the configured one (moment %.0f N m)",
                  kLo, kHi, M);
  id.note += "; the imbalance of the two ropes is not identifiable (the response is symmetric in them)";
  id.cpu_seconds = threadCpuSeconds() - cpu0;
  return out;
}

}  // namespace hoist
