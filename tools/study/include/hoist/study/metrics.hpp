// hoist/study/metrics.hpp -- per-run metrics of the paper's studies: peaks, RMS
// and the dominant frequency of a (detrended) signal in a time window.
// Pure numerics: no I/O.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace hoist::study {

/// A named time window [t0, t1] (inclusive) of a trip.
struct Window {
  std::string name;
  double t0 = 0.0;
  double t1 = 0.0;
};

/// The paper's stages for the Fig. 2 profile: uniform velocity 5-50 s,
/// deceleration and rest 50-60 s (and the whole trip).
std::vector<Window> paperWindows();

/// Options of the frequency estimators.
struct FrequencyOptions {
  /// Degree of the least-squares polynomial removed before the analysis (the
  /// quasi-static drift of the cage as l changes); 0 removes the mean only.
  int detrend_degree = 2;
  /// Frequencies below min_cycles / window length are not reported (a window
  /// must hold at least this many periods for a meaningful estimate).
  double min_cycles = 2.0;
  /// Upper search limit [Hz]; <= 0: the Nyquist frequency of the samples.
  double f_max = 0.0;
  /// Zero-padding factor of the FFT (the peak is then refined by parabolic
  /// interpolation of the log magnitude).
  int oversample = 8;
};

/// Samples of y with t in [t0, t1] (t ascending, uniform spacing assumed for
/// the FFT), the least-squares polynomial of degree `degree` removed.
std::vector<double> detrended(const std::vector<double>& t, const std::vector<double>& y,
                              double t0, double t1, int degree);

/// One-sided magnitude spectrum of the Hann-windowed, detrended, zero-padded
/// signal in [t0, t1]: frequencies [Hz] and |X| (empty if < 8 samples).
struct Spectrum {
  std::vector<double> f, mag;
};
Spectrum amplitudeSpectrum(const std::vector<double>& t, const std::vector<double>& y, double t0,
                           double t1, const FrequencyOptions& opt = {});

/// Dominant frequency [Hz] of y in [t0, t1]: peak of the Hann-windowed,
/// zero-padded FFT magnitude of the detrended signal, refined by parabolic
/// interpolation.  NaN if the window holds fewer than 8 samples, the signal is
/// (numerically) constant after detrending, no peak lies in the admissible
/// band [min_cycles / (t1 - t0), f_max], or the spectrum is strongest below
/// that band (the dominant oscillation is too slow for the window).
double dominantFrequencyFFT(const std::vector<double>& t, const std::vector<double>& y, double t0,
                            double t1, const FrequencyOptions& opt = {});

/// Power-weighted mean frequency [Hz] (spectral centroid of |X|^2) of the
/// detrended signal over the admissible band [min_cycles / (t1 - t0), f_max]:
/// a robust single number for multi-modal or chirping signals whose highest
/// spectral peak jumps between modes (the cage rotation).  NaN as above.
double spectralCentroid(const std::vector<double>& t, const std::vector<double>& y, double t0,
                        double t1, const FrequencyOptions& opt = {});

/// Frequency [Hz] from zero crossings of the detrended signal: (crossings - 1)
/// / (2 (t_last - t_first)) between the first and last crossing, with linear
/// interpolation of the crossing instants.  Small wiggles are ignored by a
/// hysteresis of `hysteresis` times the detrended RMS.  NaN with < 3 crossings.
double zeroCrossingFrequency(const std::vector<double>& t, const std::vector<double>& y, double t0,
                             double t1, int detrend_degree = 2, double hysteresis = 0.1);

/// max |y| over samples with t in [t0, t1] (NaN if none).
double peakAbs(const std::vector<double>& t, const std::vector<double>& y, double t0, double t1);
/// sqrt(mean y^2) over samples with t in [t0, t1] (NaN if none).
double rms(const std::vector<double>& t, const std::vector<double>& y, double t0, double t1);
/// max |detrended y| over [t0, t1]: the oscillation amplitude about the drift.
double oscillationAmplitude(const std::vector<double>& t, const std::vector<double>& y, double t0,
                            double t1, int detrend_degree = 2);

/// Ordered name -> value list (the columns of a summary CSV row).
class MetricSet {
 public:
  void set(const std::string& name, double value);
  /// Throws std::out_of_range naming the metric if absent.
  double get(const std::string& name) const;
  bool has(const std::string& name) const;
  const std::vector<std::pair<std::string, double>>& items() const { return items_; }

 private:
  std::vector<std::pair<std::string, double>> items_;
};

}  // namespace hoist::study
