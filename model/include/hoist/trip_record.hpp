// hoist/trip_record.hpp -- one trip of the cage, as the shaft's memory keeps
// it (issue 32, docs/condition.md): what the daemon (or hoist-trips ingest)
// writes at the end of every trip, and what the history database stores.
//
// Plain data: no I/O, no allocation beyond the depth-bin vector.  The record
// is filled off the real-time loop (the trip worker) from the samples the
// loop hands it; the history store (history/) writes and reads it
// field by field, so a new field needs its column there too (schema version).
//
// Conventions: SI units; depth is the model's l (the hoisting-rope length
// below the sheave, x down); sigmas are standard deviations, and a negative
// sigma means "not observed / not identifiable" (as in estimate_t).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace hoist {

/// Statistics of one depth bin [depth_lo, depth_lo + bin) over one trip.
/// "band" is the model's band (the twin's modes, below band_hz); "hf" what
/// the accelerometer reads above it (vibration the model does not carry).
struct DepthBinStats {
  double depth_lo = 0.0;      ///< upper edge of the bin (smaller depth) [m]
  int samples = 0;            ///< accelerometer samples in the bin
  double fy_mean = 0.0;       ///< measured f_y, in-band part: mean [m/s^2]
  double fy_rms = 0.0;        ///< ... RMS about zero
  double fy_hf_rms = 0.0;     ///< measured f_y above the band: RMS [m/s^2]
  double resid_mean = 0.0;    ///< measured f_y minus the twin's prediction: mean [m/s^2]
  double resid_rms = 0.0;     ///< ... RMS
  double y_c_mean = 0.0, y_c_rms = 0.0;      ///< the twin's (estimate's) lateral displacement [m]
  double theta_mean = 0.0, theta_rms = 0.0;  ///< the twin's (estimate's) tilt [rad]
};

/// The guide-rope preload identified from one trip: the uniform scale s of
/// both guide ropes' tensioning weights (s = 1: the configured preload),
/// fitted jointly with the moment M (and the accelerometer's offset where it
/// is a state), with sigmas from the Fisher information of the same model.
struct PreloadIdentification {
  bool attempted = false;        ///< false: the trip had no IMU data or no motion
  double scale = 1.0;            ///< s, the identified preload scale
  double sigma_scale = -1.0;     ///< its sigma; < 0: not identifiable
  double moment = 0.0;           ///< M of the joint fit [N m]
  double sigma_moment = -1.0;
  double imbalance = 0.0;        ///< (T2 - T1) / (T1 + T2) of the two guide ropes' preloads
  double sigma_imbalance = -1.0; ///< < 0: not identifiable from this trip
  bool informative = false;      ///< sigma_scale <= [condition] max_sigma: the trend uses it
  /// Detectability: how many sigma separate a 30 % preload loss (s = 0.7)
  /// from the nominal on this trip's data (0.3 / sigma_scale).
  double loss30_separation = 0.0;
  double chi2 = 0.0;             ///< the fit's residual chi-square ...
  int dof = 0;                   ///< ... and its degrees of freedom
  double cpu_seconds = 0.0;      ///< what the identification cost
  std::string note;              ///< why not identifiable / informative, in a sentence
};

/// Direction of a trip: the cage going down (l growing) or up.
enum class TripDirection : std::int8_t { Down = 1, Up = -1 };

struct TripRecord {
  std::string shaft;              ///< the shaft's name ("" = the default shaft)
  std::int64_t trip = 0;          ///< trip number on this shaft (1, 2, ...; the store assigns it when 0)
  std::int64_t wall_start_us = 0; ///< wall clock at departure [us since the Unix epoch]
  std::int64_t wall_end_us = 0;   ///< wall clock at arrival (rest reached)
  double t_start = 0.0;           ///< model time at departure [s]
  double t_end = 0.0;             ///< model time at arrival [s]
  TripDirection direction = TripDirection::Down;
  double depth_start = 0.0, depth_end = 0.0;  ///< l at departure and arrival [m]
  double peak_speed = 0.0;        ///< max |v| [m/s]
  double peak_accel = 0.0;        ///< max |a| [m/s^2]

  /// The loads at departure and at arrival (the estimate's; sigma < 0 when
  /// not observed).
  double Fa_start = 0.0, sigma_Fa_start = -1.0, Fa_end = 0.0, sigma_Fa_end = -1.0;
  double moment_start = 0.0, sigma_moment_start = -1.0, moment_end = 0.0, sigma_moment_end = -1.0;
  double b_start = 0.0, sigma_b_start = -1.0, b_end = 0.0, sigma_b_end = -1.0;

  /// The model check over the trip.
  double nis_peak = 0.0;          ///< largest windowed NIS / its dof
  double constancy_peak = 0.0;    ///< largest load drift / constancy statistic [sigma]
  bool mismatch = false;          ///< MODEL_MISMATCH was active during the trip

  double min_clearance = 0.0;     ///< smallest lateral clearance to the shaft wall [m]
  double min_clearance_depth = 0.0;  ///< l where it occurred [m]
  double lambda0_min = 0.0, lambda0_max = 0.0;  ///< hoisting-rope force [N]
  double lambda_guide_max = 0.0;  ///< max |lambda_1..4| [N]
  std::vector<std::string> alarms;   ///< alarm kinds raised during the trip (names, each once)

  double depth_bin = 10.0;        ///< [condition] depth_bin [m]
  std::vector<DepthBinStats> bins;   ///< ordered by depth_lo
  PreloadIdentification id;
};

}  // namespace hoist
