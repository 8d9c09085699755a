#include "hoist/study/metrics.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace hoist::study {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Index range [i0, i1) of samples with t in [t0, t1] (t ascending).
std::pair<std::size_t, std::size_t> range(const std::vector<double>& t, double t0, double t1) {
  const double eps = 1e-9 * std::max(1.0, std::abs(t1));
  auto b = std::lower_bound(t.begin(), t.end(), t0 - eps);
  auto e = std::upper_bound(t.begin(), t.end(), t1 + eps);
  if (e < b) e = b;
  return {static_cast<std::size_t>(b - t.begin()), static_cast<std::size_t>(e - t.begin())};
}

void checkSizes(const std::vector<double>& t, const std::vector<double>& y) {
  if (t.size() != y.size()) throw std::invalid_argument("metrics: t and y differ in length");
}

/// In-place iterative radix-2 FFT (size a power of two).
///
/// Kept hand-written on purpose, rather than a library's FFT:
///   * Debian's kissfft (libkissfft-dev) is built for float only
///     (kiss_fft_scalar=float): single precision would move the detrended
///     spectral peaks that tests/study/study_metrics_test checks;
///   * FFTW's planner (fftw_plan_*) is not thread-safe, and the studies run
///     their cases on parallel threads (--jobs): it would need a global lock
///     around planning, and a run-time library in the package, for 20 lines;
///   * the input is zero-padded to a power of two anyway (oversampling for
///     the peak interpolation), so radix 2 loses nothing; sizes are at most a
///     few 10^5 points, offline, far from any hot path.
/// Correctness: study_metrics_test (pure and damped sines, two tones, drift).
void fft(std::vector<std::complex<double>>& a) {
  const std::size_t n = a.size();
  for (std::size_t i = 1, j = 0; i < n; ++i) {
    std::size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  for (std::size_t len = 2; len <= n; len <<= 1) {
    const double ang = -2.0 * std::numbers::pi / static_cast<double>(len);
    const std::complex<double> wl(std::cos(ang), std::sin(ang));
    for (std::size_t i = 0; i < n; i += len) {
      std::complex<double> w(1.0);
      for (std::size_t k = 0; k < len / 2; ++k) {
        const auto u = a[i + k];
        const auto v = a[i + k + len / 2] * w;
        a[i + k] = u + v;
        a[i + k + len / 2] = u - v;
        w *= wl;
      }
    }
  }
}

}  // namespace

std::vector<Window> paperWindows() {
  return {{"trip", -1e300, 1e300}, {"uniform", 5.0, 50.0}, {"decel", 50.0, 60.0}};
}

std::vector<double> detrended(const std::vector<double>& t, const std::vector<double>& y, double t0,
                              double t1, int degree) {
  checkSizes(t, y);
  if (degree < 0) throw std::invalid_argument("detrended: degree must be >= 0");
  const auto [i0, i1] = range(t, t0, t1);
  const std::size_t n = i1 - i0;
  std::vector<double> out(y.begin() + static_cast<long>(i0), y.begin() + static_cast<long>(i1));
  if (n == 0) return out;
  const int d = std::min<int>(degree, static_cast<int>(n) - 1);
  const double tm = 0.5 * (t[i0] + t[i1 - 1]);
  const double hw = std::max(0.5 * (t[i1 - 1] - t[i0]), 1e-300);
  Eigen::MatrixXd A(n, d + 1);
  Eigen::VectorXd b(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = (t[i0 + i] - tm) / hw;
    double p = 1.0;
    for (int k = 0; k <= d; ++k, p *= s) A(static_cast<long>(i), k) = p;
    b(static_cast<long>(i)) = out[i];
  }
  const Eigen::VectorXd c = A.colPivHouseholderQr().solve(b);
  const Eigen::VectorXd r = b - A * c;
  for (std::size_t i = 0; i < n; ++i) out[i] = r(static_cast<long>(i));
  return out;
}

double dominantFrequencyFFT(const std::vector<double>& t, const std::vector<double>& y, double t0,
                            double t1, const FrequencyOptions& opt) {
  checkSizes(t, y);
  const auto [i0, i1] = range(t, t0, t1);
  const std::size_t n = i1 - i0;
  if (n < 8) return kNaN;
  const double T = t[i1 - 1] - t[i0];
  const double dt = T / static_cast<double>(n - 1);
  if (!(dt > 0.0)) return kNaN;
  std::vector<double> r = detrended(t, y, t0, t1, opt.detrend_degree);
  double scale = 0.0, ymax = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    scale = std::max(scale, std::abs(r[i]));
    ymax = std::max(ymax, std::abs(y[i0 + i]));
  }
  if (!(scale > 1e-12 * std::max(ymax, 1e-300))) return kNaN;  // constant after detrending
  std::size_t m = 1;
  while (m < n * static_cast<std::size_t>(std::max(1, opt.oversample))) m <<= 1;
  std::vector<std::complex<double>> a(m, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                          static_cast<double>(n - 1));
    a[i] = r[i] * w;
  }
  fft(a);
  const double df = 1.0 / (static_cast<double>(m) * dt);
  const double fnyq = 0.5 / dt;
  const double fmax = opt.f_max > 0.0 ? std::min(opt.f_max, fnyq) : fnyq;
  const double fmin = opt.min_cycles / (T + dt);
  const std::size_t kmin = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(fmin / df)));
  const std::size_t kmax = std::min(m / 2 - 1, static_cast<std::size_t>(std::floor(fmax / df)));
  if (kmin >= kmax) return kNaN;
  // If the strongest component lies below the band, the dominant oscillation
  // is too slow to be resolved in this window: do not report a sidelobe.
  {
    double below = 0.0, in = 0.0;
    for (std::size_t k = 1; k < kmin; ++k) below = std::max(below, std::abs(a[k]));
    for (std::size_t k = kmin; k <= kmax; ++k) in = std::max(in, std::abs(a[k]));
    if (below > in) return kNaN;
  }
  // Global maximum of |X| over the admissible band; it must be a local maximum
  // (not the band edge, where the spectrum of a slower component leaks in).
  std::size_t best = 0;
  double bestMag = -1.0;
  for (std::size_t k = std::max<std::size_t>(kmin, 1); k <= kmax; ++k) {
    const double mag = std::abs(a[k]);
    if (mag > bestMag && mag >= std::abs(a[k - 1]) && mag >= std::abs(a[k + 1])) {
      bestMag = mag;
      best = k;
    }
  }
  if (best == 0 || !(bestMag > 0.0)) return kNaN;
  const double am = std::log(std::abs(a[best - 1]) + 1e-300);
  const double a0 = std::log(std::abs(a[best]) + 1e-300);
  const double ap = std::log(std::abs(a[best + 1]) + 1e-300);
  const double den = am - 2.0 * a0 + ap;
  double delta = den < 0.0 ? 0.5 * (am - ap) / den : 0.0;
  delta = std::clamp(delta, -0.5, 0.5);
  return (static_cast<double>(best) + delta) * df;
}

Spectrum amplitudeSpectrum(const std::vector<double>& t, const std::vector<double>& y, double t0,
                           double t1, const FrequencyOptions& opt) {
  checkSizes(t, y);
  Spectrum sp;
  const auto [i0, i1] = range(t, t0, t1);
  const std::size_t n = i1 - i0;
  if (n < 8) return sp;
  const double dt = (t[i1 - 1] - t[i0]) / static_cast<double>(n - 1);
  if (!(dt > 0.0)) return sp;
  const std::vector<double> r = detrended(t, y, t0, t1, opt.detrend_degree);
  std::size_t m = 1;
  while (m < n * static_cast<std::size_t>(std::max(1, opt.oversample))) m <<= 1;
  std::vector<std::complex<double>> a(m, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    a[i] = r[i] * (0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                        static_cast<double>(n - 1)));
  fft(a);
  for (std::size_t k = 0; k <= m / 2; ++k) {
    sp.f.push_back(static_cast<double>(k) / (static_cast<double>(m) * dt));
    sp.mag.push_back(std::abs(a[k]));
  }
  return sp;
}

double spectralCentroid(const std::vector<double>& t, const std::vector<double>& y, double t0,
                        double t1, const FrequencyOptions& opt) {
  const Spectrum sp = amplitudeSpectrum(t, y, t0, t1, opt);
  if (sp.f.size() < 2) return kNaN;
  const double T = t1 - t0 < 1e299 ? t1 - t0 : 1e300;
  const auto [i0, i1] = range(t, t0, t1);
  const double span = i1 > i0 ? t[i1 - 1] - t[i0] : T;
  const double fmin = opt.min_cycles / span;
  const double fmax = opt.f_max > 0.0 ? opt.f_max : sp.f.back();
  double w = 0.0, wf = 0.0;
  for (std::size_t k = 0; k < sp.f.size(); ++k) {
    if (sp.f[k] < fmin || sp.f[k] > fmax) continue;
    const double p = sp.mag[k] * sp.mag[k];
    w += p;
    wf += p * sp.f[k];
  }
  return w > 0.0 ? wf / w : kNaN;
}

double zeroCrossingFrequency(const std::vector<double>& t, const std::vector<double>& y, double t0,
                             double t1, int detrend_degree, double hysteresis) {
  checkSizes(t, y);
  const auto [i0, i1] = range(t, t0, t1);
  const std::size_t n = i1 - i0;
  if (n < 4) return kNaN;
  const std::vector<double> r = detrended(t, y, t0, t1, detrend_degree);
  double ss = 0.0;
  for (double v : r) ss += v * v;
  const double thr = hysteresis * std::sqrt(ss / static_cast<double>(n));
  if (ss == 0.0) return kNaN;
  // Schmitt trigger: a crossing counts once the signal has passed from beyond
  // -thr to beyond +thr (or back); its instant is the last sign change before,
  // interpolated linearly.
  int state = 0;  // +1 last beyond +thr, -1 last beyond -thr, 0 not yet
  std::vector<double> crossings;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = r[i];
    const int now = v > thr ? 1 : (v < -thr ? -1 : 0);
    if (now == 0 || now == state) continue;
    if (state != 0) {
      std::size_t k = i;  // first sample of the current sign run
      while (k > 0 && (r[k - 1] > 0.0) == (v > 0.0)) --k;
      if (k > 0) {
        const double ta = t[i0 + k - 1], tb = t[i0 + k];
        crossings.push_back(ta + (tb - ta) * r[k - 1] / (r[k - 1] - r[k]));
      }
    }
    state = now;
  }
  if (crossings.size() < 3) return kNaN;
  const double span = crossings.back() - crossings.front();
  if (!(span > 0.0)) return kNaN;
  return static_cast<double>(crossings.size() - 1) / (2.0 * span);
}

double peakAbs(const std::vector<double>& t, const std::vector<double>& y, double t0, double t1) {
  checkSizes(t, y);
  const auto [i0, i1] = range(t, t0, t1);
  if (i1 == i0) return kNaN;
  double m = 0.0;
  for (std::size_t i = i0; i < i1; ++i) m = std::max(m, std::abs(y[i]));
  return m;
}

double rms(const std::vector<double>& t, const std::vector<double>& y, double t0, double t1) {
  checkSizes(t, y);
  const auto [i0, i1] = range(t, t0, t1);
  if (i1 == i0) return kNaN;
  double s = 0.0;
  for (std::size_t i = i0; i < i1; ++i) s += y[i] * y[i];
  return std::sqrt(s / static_cast<double>(i1 - i0));
}

double oscillationAmplitude(const std::vector<double>& t, const std::vector<double>& y, double t0,
                            double t1, int detrend_degree) {
  const std::vector<double> r = detrended(t, y, t0, t1, detrend_degree);
  if (r.empty()) return kNaN;
  double m = 0.0;
  for (double v : r) m = std::max(m, std::abs(v));
  return m;
}

void MetricSet::set(const std::string& name, double value) {
  for (auto& kv : items_)
    if (kv.first == name) {
      kv.second = value;
      return;
    }
  items_.emplace_back(name, value);
}

double MetricSet::get(const std::string& name) const {
  for (const auto& kv : items_)
    if (kv.first == name) return kv.second;
  throw std::out_of_range("no metric named '" + name + "'");
}

bool MetricSet::has(const std::string& name) const {
  for (const auto& kv : items_)
    if (kv.first == name) return true;
  return false;
}

}  // namespace hoist::study
