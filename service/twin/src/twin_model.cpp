// The model a TwinCore runs: see hoist/service/twin/twin_model.hpp.
#include "hoist/service/twin/twin_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hoist::service::inline twin {

PlausibilityBounds twinPlausibilityBounds(const TwinConfig& cfg, const ShaftParams& shaft) {
  // The lateral limit: plausible_factor x the largest gap, but never below
  // 1 m (hoist-sim's limit): tiny test gaps must raise clearance alarms, not
  // model faults.
  const double lateral =
      std::max(1.0, cfg.service.plausible_factor *
                        std::max({cfg.alarms.gap_pos_y, cfg.alarms.gap_neg_y, cfg.alarms.guide_rope_gap}));
  return plausibilityBounds(shaft, lateral);
}

ShaftParams withPreloadScale(ShaftParams shaft, double scale) {
  shaft.Tb1 *= scale;
  shaft.Tb2 *= scale;
  return shaft;
}

std::unique_ptr<TwinModel> buildTwinModel(const TwinConfig& cfg, double scale) {
  if (!(std::isfinite(scale) && scale > 0.0))
    throw std::invalid_argument("preload scale " + std::to_string(scale) + ": must be a finite number > 0");
  const ShaftParams p = withPreloadScale(cfg.shaft, scale);
  p.validate();
  auto m = std::make_unique<TwinModel>(scale, makeSolver(Method::Fast, std::make_shared<const ShaftModel>(p)),
                                       cfg.service.envelope_points, cfg.service.shape_points);
  m->bounds = twinPlausibilityBounds(cfg, p);
  if (cfg.estimator.enabled) m->estimator = LoadEstimator::buildModel(p);
  return m;
}

}  // namespace hoist::service::twin
