// hoist/io/estimator_config.hpp -- the load estimator's configuration
// ([sensors] and [estimator], hoist/load_estimator.hpp) and the measurement
// CSV of hoist-estimate / hoist-sim --write-measurements.
//
// [sensors]   imu_accel_noise, imu_rate_noise, rope_load_noise: the standard
//             deviation per sample of each sensor's white noise.
// [estimator] enabled (default false) and every EstimatorSettings field by a
//             snake_case key (kEstimatorFields: the one table the reader, the
//             documentation and the tests follow).
// Every key is optional (default: EstimatorSettings{}).  Errors are
// ConfigError "file:line: section.key: why": unknown keys (did you mean),
// wrong types, and everything EstimatorSettings::validate() refuses.
//
// Measurement CSV: a header naming the columns; t [s], l [m], v [m/s],
// a [m/s^2] required; f_y [m/s^2], omega [rad/s], rope_load [N] optional (a
// column that is absent: that sensor is absent; an empty field in a present
// column: that sample is absent).  Other columns are ignored (and listed).
// '#' lines and blank lines are skipped; a UTF-8 BOM and CRLF are accepted.
// Rejected with file, line and column (MeasurementError): missing or
// duplicate columns, non-numeric or non-finite fields, empty t/l/v/a, wrong
// field counts, t not strictly increasing, gaps, |v| or |a| beyond the
// profile reader's limits (ProfileLimits), l <= 0, more than max_rows rows,
// fewer than two rows, an empty or binary file.
#pragma once

#include <array>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "hoist/io/error.hpp"
#include "hoist/io/profile.hpp"
#include "hoist/load_estimator.hpp"

namespace hoist::io {

/// [estimator] enabled + the filter's settings (with [sensors]' noise).
struct EstimatorConfig {
  bool enabled = false;
  EstimatorSettings settings;
};

/// One key of [sensors] / [estimator] (besides `enabled`).
struct EstimatorField {
  std::string_view section;  ///< "sensors" or "estimator"
  std::string_view key;      ///< snake_case, as in validate()'s messages
  double* (*real)(EstimatorSettings&);  ///< the member, or nullptr for an integer
  int* (*integer)(EstimatorSettings&);  ///< the member, or nullptr for a real
  std::string_view unit;
  std::string_view doc;
};

namespace detail {
template <double EstimatorSettings::*M>
double* realOf(EstimatorSettings& s) { return &(s.*M); }
template <double SensorNoise::*M>
double* noiseOf(EstimatorSettings& s) { return &(s.noise.*M); }
template <int EstimatorSettings::*M>
int* intOf(EstimatorSettings& s) { return &(s.*M); }
}  // namespace detail

/// Every key of [sensors] and [estimator] but `enabled`, in file order.
inline constexpr std::array<EstimatorField, 31> kEstimatorFields = {{
    {"sensors", "imu_accel_noise", &detail::noiseOf<&SensorNoise::imu_accel>, nullptr, "m/s^2",
     "IMU lateral specific force f_y: noise standard deviation per sample"},
    {"sensors", "imu_rate_noise", &detail::noiseOf<&SensorNoise::imu_rate>, nullptr, "rad/s",
     "IMU tilt rate omega: noise standard deviation per sample"},
    {"sensors", "rope_load_noise", &detail::noiseOf<&SensorNoise::rope_load>, nullptr, "N",
     "rope load cell: noise standard deviation per sample"},
    {"sensors", "imu_accel_offset_sigma", &detail::realOf<&EstimatorSettings::accel_offset_sigma>, nullptr, "m/s^2",
     "prior sigma of the accelerometer's constant offset on f_y, estimated with M (0: calibrated)"},
    {"estimator", "fa_walk", &detail::realOf<&EstimatorSettings::fa_walk>, nullptr, "N/sqrt(s)",
     "random walk of Fa at rest"},
    {"estimator", "moment_walk", &detail::realOf<&EstimatorSettings::moment_walk>, nullptr, "N m/sqrt(s)",
     "random walk of M at rest"},
    {"estimator", "moving_walk_scale", &detail::realOf<&EstimatorSettings::moving_walk_scale>, nullptr, "",
     "factor on both walks while the cage moves"},
    {"estimator", "rest_speed", &detail::realOf<&EstimatorSettings::rest_speed>, nullptr, "m/s",
     "|v| (and |a|) at or below this is at rest"},
    {"estimator", "fa_sigma0", &detail::realOf<&EstimatorSettings::fa_sigma0>, nullptr, "N",
     "initial sigma of Fa about the configured load"},
    {"estimator", "moment_sigma0", &detail::realOf<&EstimatorSettings::moment_sigma0>, nullptr, "N m",
     "initial sigma of M about the configured moment"},
    {"estimator", "model_error", &detail::realOf<&EstimatorSettings::model_error>, nullptr, "",
     "relative model uncertainty on the predicted dynamic part"},
    {"estimator", "gate_sigma", &detail::realOf<&EstimatorSettings::gate_sigma>, nullptr, "sigma",
     "per-sample innovation gate"},
    {"estimator", "gate_reset", nullptr, &detail::intOf<&EstimatorSettings::gate_reset>, "",
     "consecutive gated samples that mean a load change (integer)"},
    {"estimator", "nis_window", &detail::realOf<&EstimatorSettings::nis_window>, nullptr, "s", "NIS window"},
    {"estimator", "nis_alpha", &detail::realOf<&EstimatorSettings::nis_alpha>, nullptr, "",
     "MODEL_MISMATCH when the window's NIS exceeds its 1 - alpha quantile ..."},
    {"estimator", "nis_margin", &detail::realOf<&EstimatorSettings::nis_margin>, nullptr, "",
     "... and nis_margin times its degrees of freedom"},
    {"estimator", "drift_sigma", &detail::realOf<&EstimatorSettings::drift_sigma>, nullptr, "sigma",
     "MODEL_MISMATCH when a load estimate drifts more during a trip, or its short-memory twin departs more"},
    {"estimator", "constancy_memory", &detail::realOf<&EstimatorSettings::constancy_memory>, nullptr, "s",
     "memory of the short-memory load estimates of the constancy test"},
    {"estimator", "min_window_fill", &detail::realOf<&EstimatorSettings::min_window_fill>, nullptr, "",
     "the NIS test needs the window at least this full (fraction)"},
    {"estimator", "max_rate", nullptr, &detail::intOf<&EstimatorSettings::max_rate>, "Hz",
     "largest sensor update rate the NIS window is sized for (integer)"},
    {"estimator", "sensor_timeout", &detail::realOf<&EstimatorSettings::sensor_timeout>, nullptr, "s",
     "a sensor not updated for this long is not in use"},
    {"estimator", "model_band", &detail::realOf<&EstimatorSettings::model_band>, nullptr, "s",
     "sensor health: low-pass time constant splitting the model's band from the noise"},
    {"estimator", "noise_memory", &detail::realOf<&EstimatorSettings::noise_memory>, nullptr, "s",
     "sensor health: memory of the learned high-frequency noise"},
    {"estimator", "quiet_ratio", &detail::realOf<&EstimatorSettings::quiet_ratio>, nullptr, "",
     "a channel whose high-pass sigma is below quiet_ratio x its datasheet noise is quiet (a fault)"},
    {"estimator", "quiet_memory", &detail::realOf<&EstimatorSettings::quiet_memory>, nullptr, "s",
     "memory of the quiet and rejected tests"},
    {"estimator", "stuck_time", &detail::realOf<&EstimatorSettings::stuck_time>, nullptr, "s",
     "the very same value for this long is a stuck channel"},
    {"estimator", "noisy_factor", &detail::realOf<&EstimatorSettings::noisy_factor>, nullptr, "",
     "a learned noise above noisy_factor x the datasheet's is a fault"},
    {"estimator", "band_block", &detail::realOf<&EstimatorSettings::band_block>, nullptr, "s",
     "innovations are summed over blocks this long for the NIS test and the CUSUM (0: per sample)"},
    {"estimator", "change_drift", &detail::realOf<&EstimatorSettings::change_drift>, nullptr, "sigma",
     "load-change CUSUM reference k per block"},
    {"estimator", "change_threshold", &detail::realOf<&EstimatorSettings::change_threshold>, nullptr, "sigma",
     "load-change CUSUM decision level h"},
    {"estimator", "change_holdoff", &detail::realOf<&EstimatorSettings::change_holdoff>, nullptr, "s",
     "the CUSUM runs once the cage has been at rest (or the last change) this long"},
}};

/// The top-level sections of a daemon configuration besides the shaft's:
/// what a tool that reads the shaft from hoist-twind's file passes as
/// shaftParamsFromToml's `other_sections`.
const std::vector<std::string>& daemonSections();

/// [sensors] + [estimator] of a parsed file (other sections are not looked
/// at).  The result has passed EstimatorSettings::validate().
EstimatorConfig estimatorConfigFromToml(const toml::table& tbl, const std::string& source);

/// [service] max_step of a daemon configuration (just that key, read the
/// way hoist-twind reads it: a number in [0, 10] s, 0 = no substeps), or
/// `fallback` when the file has none.  So hoist-estimate substeps as the
/// live estimator does.
double serviceMaxStep(const toml::table& tbl, const std::string& source, double fallback);

/// The [sensors]/[estimator] part of a configuration as TOML (every key,
/// shortest round-trip doubles) that estimatorConfigFromToml reads back.
std::string toToml(const EstimatorConfig& c);

/// Errors in a measurement CSV (key: the column).
class MeasurementError : public InputError {
 public:
  using InputError::InputError;
};

/// What the measurement CSV's header said.
struct MeasurementColumns {
  unsigned sensors = 0;  ///< SensorBits of the sensor columns present
  std::vector<std::string> ignored;  ///< other columns (not read)
};

/// Read a measurement CSV (see above); `info` (optional) gets the columns.
/// `limits`: the profile reader's (max_gap, max_speed, max_accel, max_rows).
std::vector<MeasurementSample> readMeasurementsCsv(std::istream& in, const std::string& source,
                                                   const ProfileLimits& limits = {},
                                                   MeasurementColumns* info = nullptr);
std::vector<MeasurementSample> readMeasurementsCsvFile(const std::string& path, const ProfileLimits& limits = {},
                                                       MeasurementColumns* info = nullptr);

/// The header of a measurement CSV (hoist-sim --write-measurements).
inline constexpr std::string_view kMeasurementHeader = "t,l,v,a,f_y,omega,rope_load";
/// One row in kMeasurementHeader's order (shortest round-trip doubles);
/// sensors not in `m.present` are written as empty fields.
void appendMeasurementRow(std::string& s, const MeasurementSample& m);

}  // namespace hoist::io
