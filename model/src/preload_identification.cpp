// identifyPreload: Gauss-Newton on (M, s, o) over one trip (hoist/preload_identification.hpp).
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
      !(opt.fd_step > 0.0 && opt.fd_step < 0.5) || opt.max_iterations < 1)
    throw std::invalid_argument("identifyPreload: bad options (max_sigma > 0, accel_offset_sigma >= 0, "
                                "max_step >= 0, 0 < fd_step < 0.5, max_iterations >= 1)");
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
  const int np = fit_offset ? 3 : 2;
  const double sa2 = est.noise.imu_accel * est.noise.imu_accel, sw2 = est.noise.imu_rate * est.noise.imu_rate;
  const double me = est.model_error;

  std::vector<double> H0f, H0w, H1f, H1w, pf(trip.size(), 0.0), pw(trip.size(), 0.0);
  double s0 = 1.0, s = 1.0, M = 0.0, o = 0.0, chi2 = 0.0;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(np, np);
  int dof = static_cast<int>(n_acc + n_rate) - np + (fit_offset ? 1 : 0);
  for (int it = 0; it < opt.max_iterations; ++it) {
    const double ds = s0 * opt.fd_step;
    unitMomentResponse(twin, s0, 0.0, opt.max_step, trip, H0f, H0w);
    unitMomentResponse(twin, s0 + ds, 0.0, opt.max_step, trip, H1f, H1w);
    // Linear least squares in (M, P = M (s - s0), o).
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(np, np);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(np);
    Eigen::VectorXd row(np);
    auto accumulate = [&](auto&& visit) {
      for (std::size_t i = 0; i < trip.size(); ++i) {
        const MeasurementSample& m = trip[i];
        if (m.present & kSensorImuAccel) {
          row(0) = H0f[i];
          row(1) = (H1f[i] - H0f[i]) / ds;
          if (fit_offset) row(2) = 1.0;
          visit(row, m.z.f_y, 1.0 / (sa2 + me * me * pf[i] * pf[i]));
        }
        if (m.present & kSensorImuRate) {
          row(0) = H0w[i];
          row(1) = (H1w[i] - H0w[i]) / ds;
          if (fit_offset) row(2) = 0.0;
          visit(row, m.z.omega, 1.0 / (sw2 + me * me * pw[i] * pw[i]));
        }
      }
    };
    accumulate([&](const Eigen::VectorXd& j, double z, double w) {
      A.noalias() += w * j * j.transpose();
      r.noalias() += w * z * j;
    });
    if (fit_offset) A(2, 2) += 1.0 / (opt.accel_offset_sigma * opt.accel_offset_sigma);
    const Eigen::VectorXd p = A.ldlt().solve(r);
    M = p(0);
    const double P = p(1);
    o = fit_offset ? p(2) : 0.0;
    const double step = std::abs(M) > 0.0 ? P / M : 0.0;
    s = s0 + step;
    // Fisher information in (M, s, o) at the solution, the predictions, chi2.
    Eigen::MatrixXd F = Eigen::MatrixXd::Zero(np, np);
    chi2 = 0.0;
    for (std::size_t i = 0; i < trip.size(); ++i) {
      const MeasurementSample& m = trip[i];
      const double dHf = (H1f[i] - H0f[i]) / ds, dHw = (H1w[i] - H0w[i]) / ds;
      const double hf = H0f[i] + step * dHf, hw = H0w[i] + step * dHw;
      if (m.present & kSensorImuAccel) {
        const double w = 1.0 / (sa2 + me * me * pf[i] * pf[i]);
        row(0) = hf;
        row(1) = M * dHf;
        if (fit_offset) row(2) = 1.0;
        F.noalias() += w * row * row.transpose();
        const double pred = M * hf + o;
        chi2 += w * (m.z.f_y - pred) * (m.z.f_y - pred);
        out.fitted_fy[i] = pred;
      }
      if (m.present & kSensorImuRate) {
        const double w = 1.0 / (sw2 + me * me * pw[i] * pw[i]);
        row(0) = hw;
        row(1) = M * dHw;
        if (fit_offset) row(2) = 0.0;
        F.noalias() += w * row * row.transpose();
        chi2 += w * (m.z.omega - M * hw) * (m.z.omega - M * hw);
      }
      pf[i] = M * hf;  // the next step's model-error weights
      pw[i] = M * hw;
    }
    if (fit_offset) F(2, 2) += 1.0 / (opt.accel_offset_sigma * opt.accel_offset_sigma);
    Eigen::FullPivLU<Eigen::MatrixXd> lu(F);
    if (!lu.isInvertible()) {
      cov.setConstant(std::numeric_limits<double>::infinity());
      break;
    }
    cov = lu.inverse();
    const double sig_s = std::sqrt(std::max(0.0, cov(1, 1)));
    // Converged, or not identifiable (then moving s0 on a wild step is pointless).
    if (std::abs(step) <= 0.1 * sig_s || !(sig_s < 0.5)) break;
    s0 = std::clamp(s, 0.3, 2.0);
  }
  const double inflate = dof > 0 ? std::sqrt(std::max(1.0, chi2 / dof)) : 1.0;
  id.scale = s;
  id.moment = M;
  id.sigma_scale = std::isfinite(cov(1, 1)) ? inflate * std::sqrt(std::max(0.0, cov(1, 1))) : -1.0;
  id.sigma_moment = std::isfinite(cov(0, 0)) ? inflate * std::sqrt(std::max(0.0, cov(0, 0))) : -1.0;
  id.chi2 = chi2;
  id.dof = dof;
  id.imbalance = 0.0;
  id.sigma_imbalance = -1.0;
  id.informative = id.sigma_scale > 0.0 && id.sigma_scale <= opt.max_sigma;
  id.loss30_separation = id.sigma_scale > 0.0 ? 0.3 / id.sigma_scale : 0.0;
  if (id.informative)
    id.note = fmt("this IMU can see a 30 %% preload loss on this trip (s = %.3f +- %.3f: %.1f sigma)", s,
                  id.sigma_scale, id.loss30_separation);
  else if (id.sigma_scale > 0.0)
    id.note = fmt("this IMU cannot see a 30 %% preload loss on this trip (sigma of s %.3g: %.1f sigma; "
                  "moment %.0f N m)",
                  id.sigma_scale, id.loss30_separation, M);
  else
    id.note = fmt("this IMU cannot see a 30 %% preload loss on this trip (no information on s; moment %.0f N m)",
                  M);
  id.note += "; the imbalance of the two ropes is not identifiable (the response is symmetric in them)";
  id.cpu_seconds = threadCpuSeconds() - cpu0;
  return out;
}

}  // namespace hoist
