// ConditionSettings, TripRecorder and recordTrips (hoist/trip_pipeline.hpp, hoist/trip_recorder.hpp).
#include "hoist/trip_pipeline.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "hoist/trip_recorder.hpp"

namespace hoist {

void ConditionSettings::validate() const {
  auto bad = [](const char* key, double v, const char* rule) {
    throw std::invalid_argument(std::string(key) + ": " + rule + " (got " + std::to_string(v) + ")");
  };
  if (!(std::isfinite(depth_bin) && depth_bin > 0.0)) bad("condition.depth_bin", depth_bin, "must be > 0 m");
  if (!(std::isfinite(max_sigma) && max_sigma > 0.0)) bad("condition.max_sigma", max_sigma, "must be > 0");
  if (!(std::isfinite(band_hz) && band_hz >= 0.0)) bad("condition.band_hz", band_hz, "must be >= 0 Hz (0: from the twin)");
  if (baseline_trips < 2) bad("condition.baseline_trips", baseline_trips, "must be >= 2 (a spread needs two trips)");
  if (!(std::isfinite(fingerprint_sigma) && fingerprint_sigma > 0.0))
    bad("condition.fingerprint_sigma", fingerprint_sigma, "must be > 0");
  if (!(std::isfinite(model_check_sigma) && model_check_sigma >= 2.0))
    bad("condition.model_check_sigma", model_check_sigma, "must be >= 2 (sigma; below that healthy trips raise it)");
  if (!(std::isfinite(preload_warning) && preload_warning > 0.0 && preload_warning < 1.0))
    bad("condition.preload_warning", preload_warning, "must be in (0, 1)");
  if (!(std::isfinite(preload_critical) && preload_critical > 0.0 && preload_critical < preload_warning))
    bad("condition.preload_critical", preload_critical, "must be in (0, preload_warning)");
  if (!(std::isfinite(trend_walk) && trend_walk >= 0.0)) bad("condition.trend_walk", trend_walk, "must be >= 0");
  if (seed_trips != 0 && seed_trips < 2 * baseline_trips)
    bad("condition.seed_trips", seed_trips, "must be 0 (every stored trip) or >= 2 x baseline_trips");
  if (!(std::isfinite(accel_offset_sigma) && accel_offset_sigma >= 0.0))
    bad("sensors.imu_accel_offset_sigma", accel_offset_sigma, "must be >= 0 m/s^2");
  clearance.validate();
}

namespace {
TripDetectorSettings detectorSettings(const EstimatorSettings& est) {
  TripDetectorSettings d;
  d.rest_speed = est.rest_speed;
  return d;
}
}  // namespace

TripRecorder::TripRecorder(const ShaftParams& twin, const EstimatorSettings& est, const ConditionSettings& cond,
                           double max_step)
    : det_(detectorSettings(est)), acc_(twin, est, cond, max_step) {}

void TripRecorder::reset() {
  det_.reset();
  pending_.clear();
  acc_.abandon();
}

bool TripRecorder::add(const MeasurementSample& m, const TripEstimate& e, double guide_deflection) {
  const TripEvent ev = det_.update(m.t, m.k);
  switch (ev) {
    case TripEvent::Departed:
      if (pending_.empty()) {
        acc_.begin(m, e, guide_deflection);
      } else {
        // Each kept tick with its own guide-rope deflection (the clearance of a creep before the departure).
        acc_.begin(pending_.front().m, pending_.front().e, pending_.front().guide_deflection);
        for (std::size_t i = 1; i < pending_.size(); ++i)
          acc_.add(pending_[i].m, pending_[i].e, pending_[i].guide_deflection);
        acc_.add(m, e, guide_deflection);
      }
      pending_.clear();
      return false;
    case TripEvent::Arrived:
      acc_.add(m, e, guide_deflection);
      rec_ = acc_.finish(det_.arrivalTime(), det_.arrival());
      rec_.trip = ++trips_;
      pending_.assign(1, Pending{m, e, guide_deflection});
      return true;
    case TripEvent::NotATrip:
      ++not_a_trip_;
      acc_.abandon();
      pending_.assign(1, Pending{m, e, guide_deflection});
      return false;
    case TripEvent::None:
      break;
  }
  if (det_.moving()) {
    acc_.add(m, e, guide_deflection);
  } else if (det_.still(m.k)) {
    pending_.assign(1, Pending{m, e, guide_deflection});
  } else if (!pending_.empty()) {
    pending_.push_back(Pending{m, e, guide_deflection});
  }
  return false;
}

std::vector<TripRecord> recordTrips(const ShaftParams& twin, const EstimatorSettings& est,
                                    const ConditionSettings& cond, double max_step,
                                    const std::vector<MeasurementSample>& samples,
                                    const std::function<void(double)>& progress) {
  cond.validate();
  est.validate();
  TripRecorder rec(twin, est, cond, max_step);
  std::vector<TripRecord> out;
  std::size_t i = 0;
  estimateRecorded(
      twin, est, max_step, samples,
      [&](const LoadEstimate& e, const EstimatorCounters&) {
        if (rec.add(samples[i], e)) out.push_back(std::move(rec.record()));
        ++i;
      },
      progress);
  return out;
}

}  // namespace hoist
