// The model's valid range and output plausibility: see hoist/plausibility.hpp.
#include "hoist/plausibility.hpp"

#include <cmath>

namespace hoist {

LengthRange validLengthRange(const ShaftParams& p) {
  return {kMinEndDistance, p.maxRopeLength() - kMinEndDistance};
}

PlausibilityBounds plausibilityBounds(const ShaftParams& p, double max_lateral) {
  PlausibilityBounds b;
  b.lateral = max_lateral;
  b.theta = max_lateral / p.h;
  b.x_c = max_lateral + 10.0 * (p.m * p.g + p.Fa + p.rho1 * p.g * p.L) * p.L / p.EA;
  b.force = 10.0 * (p.m * p.g + std::fabs(p.Fa) + p.Tb1 + p.Tb2 + (p.rho1 + 2.0 * p.rho2) * p.g * p.L);
  return b;
}

const char* implausible(const CageResponse& r, double h, const PlausibilityBounds& b, double& value,
                        double& limit) {
  auto over = [&](double v, double lim) {
    value = v;
    limit = lim;
    return !(std::fabs(v) <= lim);  // NaN is over
  };
  if (over(r.y_c - h * r.theta, b.lateral) || over(r.y_c + h * r.theta, b.lateral)) {
    value = std::fabs(r.y_c - h * r.theta) > std::fabs(r.y_c + h * r.theta) ? r.y_c - h * r.theta
                                                                             : r.y_c + h * r.theta;
    return "y_c";
  }
  if (over(r.theta, b.theta)) return "theta";
  if (over(r.x_c, b.x_c)) return "x_c";
  static const char* const names[5] = {"lambda_0", "lambda_1", "lambda_2", "lambda_3", "lambda_4"};
  for (int k = 0; k < 5; ++k)
    if (over(r.lambda[static_cast<std::size_t>(k)], b.force)) return names[k];
  return nullptr;
}

}  // namespace hoist
