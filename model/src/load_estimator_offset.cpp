// The load estimator's accelerometer offset and the operator's known-load
// calibration (hoist/load_estimator.hpp: declareKnownLoad, setAccelOffset;
// docs/estimation.md, "The accelerometer's offset").
#include "hoist/load_estimator.hpp"

#include "load_estimator_detail.hpp"

#include <cmath>
#include <stdexcept>

namespace hoist {

using namespace estimator_detail;

double LoadEstimator::accelOffsetSigma() const { return std::sqrt(std::max(Pl_(1, 1), 0.0)); }

void LoadEstimator::setAccelOffset(double value, double sigma) {
  if (!(std::isfinite(value) && std::abs(value) <= 1.0))
    throw std::invalid_argument("accel_offset: must be finite and within +-1 m/s^2");
  if (!(std::isfinite(sigma) && sigma >= 0.0 && sigma <= 1.0))
    throw std::invalid_argument("accel_offset sigma: must be in [0, 1] m/s^2");
  c0_ = value;
  // A calibrated accelerometer (imu_accel_offset_sigma = 0) keeps it fixed.
  Pc0_ = set_.accel_offset_sigma > 0.0 ? sigma * sigma : 0.0;
  // Now as well: the offset, and no correlation with M yet.
  const double dc = value - c_;
  c_ = cF_ = value;
  Pl_(1, 1) = PlF_(1, 1) = Pc0_;
  Pl_(0, 1) = Pl_(1, 0) = PlF_(0, 1) = PlF_(1, 0) = 0.0;
  pred_fy_ += dc;
}

void LoadEstimator::declareKnownLoad(double Fa, double b, double until_t) {
  if (!(std::isfinite(Fa) && Fa >= 0.0)) throw std::invalid_argument("known load Fa: must be finite and >= 0");
  if (!std::isfinite(b)) throw std::invalid_argument("known load b: must be finite");
  if (std::isnan(until_t)) throw std::invalid_argument("known load until: must be a time");
  const double M = Fa * b;
  const double sFa = std::max(kKnownLoadRelSigma * Fa, 1.0), sM = std::max(kKnownLoadRelSigma * std::abs(M), 1.0);
  // The predictions of this tick follow the pinned load (the sensitivities are linear in it).
  pred_rope_ += (Fa - Fa_) * h_rope_;
  pred_fy_ += (M - M_) * h_fy_;
  pred_om_ += (M - M_) * h_om_;
  Fa_ = FaF_ = Fa;
  M_ = MF_ = M;
  PFa_ = PFaF_ = sFa * sFa;
  Pl_(0, 0) = PlF_(0, 0) = sM * sM;
  Pl_(0, 1) = Pl_(1, 0) = PlF_(0, 1) = PlF_(1, 0) = 0.0;
  known_until_ = until_t;
  run_fa_ = run_m_ = 0;
  cusum_fa_.reset();
  cusum_m_.reset();
}

void LoadEstimator::clearKnownLoad() { known_until_ = -1e300; }

}  // namespace hoist
