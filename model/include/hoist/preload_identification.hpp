// hoist/preload_identification.hpp -- the guide-rope preload identified from
// one trip's IMU data (issue 32; docs/condition-identification.md).
//
// The unknowns: the uniform preload scale s (both guide ropes' tensioning
// weights Tb1, Tb2 times s; s = 1 is the configured preload), the moment M
// of the load, and the accelerometer's offset o where it is not calibrated.
// The lateral/torsional subsystem is driven by the moment alone (hoist/
// fast_solver.hpp, Forcing::LoadOnly is its exact derivative), so for the
// trip's kinematics the measurements are
//     f_y(t)   = M H_f(t; s) + o        omega(t) = M H_w(t; s)
// with H the response to M = 1 N m of the same n-mode model whose guide-rope
// preloads are scaled by s.  At a given s the model is LINEAR in (M, o): one
// weighted least squares gives the profile chi2(s) (one solver run over the
// trip per s).  s is the minimum of that profile: a grid over [0.3, 1.6]
// (the information on s sharpens as s falls, so the profile is far from a
// parabola over that range), then local parabolas through (c - d, c, c + d),
// d ~ one sigma, re-centred on their vertex until it moves less than d / 4.
// A minimum on the grid's ends is reported not identifiable.  The tilt's
// depth shape is what separates s from M: the ropes' own weight adds tension
// rho2 g (L - x) that does not
// scale with s.
//
// Weights: each sample's variance is the sensor's (EstimatorSettings::noise)
// plus (model_error x the predicted value)^2, as the load estimator does.
// sigma(s): the profile's curvature over +- one sigma about the minimum
// (Delta chi2 = 1: the marginal sigma of s, M and o profiled out, without
// the first-order linearization in s); sigma(M): its conditional variance at
// the minimum plus (dM/ds sigma(s))^2.  Both times sqrt(chi2 / dof) when that
// is above 1 (vibration the model does not carry, or a model that is wrong,
// widens the band instead of hiding behind it).  The offset enters with its
// prior (accel_offset_sigma) as one more observation.  Where M is within 3
// sigma of zero, s is a ratio with heavy tails: reported not identifiable.
//
// The imbalance between the two ropes is not identifiable from the cage: the
// model is symmetric in the two guide ropes (each has a top and a bottom
// sleeve, y measured along the same +y), so the response is an even function
// of (T2 - T1) and its derivative at balance is zero -- the Fisher
// information of the imbalance vanishes (tested: swapping Tb1 and Tb2 leaves
// the response unchanged to round-off).  It is reported as not identifiable
// (sigma_imbalance = -1) with the reason in the note.
//
// Who calls it: TripAccumulator::finish (hoist/trip_accumulator.hpp), off the
// real-time loop.  Allocates; 10-15 solver runs over the trip at the twin's n.
#pragma once

#include <vector>

#include "hoist/load_estimator.hpp"
#include "hoist/profile.hpp"
#include "hoist/trip_record.hpp"

namespace hoist {

struct PreloadFitOptions {
  double max_sigma = 0.1;           ///< [condition] max_sigma: informative when sigma(s) <= this
  double accel_offset_sigma = 0.0;  ///< prior sigma of the IMU's offset [m/s^2]; 0: calibrated, not fitted
  double max_step = kDefaultMaxStep;  ///< largest solver step [s] (the twin's)
  int max_iterations = 4;           ///< local parabolas at most (up to three solver runs each)
};

/// The fit and, per sample of the trip, the prediction of f_y it implies (the
/// identified model's f_y; NaN where the sample had no accelerometer), for the
/// record's residual bins.
struct PreloadFit {
  PreloadIdentification id;
  std::vector<double> fitted_fy;
  int iterations = 0;  ///< solver runs over the trip (profile evaluations)
};

/// Identify s (and M, o) from `trip`: the samples from the departure (at
/// rest: the solvers start in static equilibrium there) to the arrival, in
/// time order.  `twin` is the twin's shaft (its n, its preloads are s = 1).
/// Never throws for lack of information: a trip without IMU samples or
/// without motion returns attempted = false; a trip whose moment is too
/// small to tell s returns informative = false with the reason in `note`.
/// Throws std::invalid_argument for bad options, std::domain_error as the
/// solver does.
PreloadFit identifyPreload(const ShaftParams& twin, const EstimatorSettings& est, const PreloadFitOptions& opt,
                           const std::vector<MeasurementSample>& trip);

/// The response of the twin's model with its guide-rope preloads scaled
/// (Tb1 * scale * (1 - imbalance), Tb2 * scale * (1 + imbalance)) to a unit
/// moment (1 N m) over `trip`, started static at the first sample, read by
/// the sensor model: out_fy[i], out_omega[i] per sample.  The building block
/// of identifyPreload; public for tests and studies.
void unitMomentResponse(const ShaftParams& twin, double scale, double imbalance, double max_step,
                        const std::vector<MeasurementSample>& trip, std::vector<double>& out_fy,
                        std::vector<double>& out_omega);

}  // namespace hoist
