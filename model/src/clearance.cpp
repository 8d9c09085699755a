#include "hoist/clearance.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hoist {

void ClearanceLimits::validate() const {
  auto positive = [](const char* key, double v) {
    if (!std::isfinite(v) || !(v > 0.0))
      throw std::invalid_argument(std::string(key) + ": must be a finite number > 0");
  };
  positive("gap_pos_y", gap_pos_y);
  positive("gap_neg_y", gap_neg_y);
  positive("guide_rope_gap", guide_rope_gap);
  if (!(warning_fraction > 0.0 && warning_fraction < critical_fraction))
    throw std::invalid_argument("warning_fraction: must lie in (0, critical_fraction)");
  if (!(critical_fraction <= 1.0)) throw std::invalid_argument("critical_fraction: must lie in (warning_fraction, 1]");
}

CageClearance cageClearance(double y_c, double theta, double h, double guide_deflection,
                            const ClearanceLimits& lim) {
  CageClearance c;
  const double y_top = y_c - h * theta, y_bottom = y_c + h * theta;
  c.excursion_pos = std::max(y_top, y_bottom);
  c.excursion_neg = std::max(-y_top, -y_bottom);
  c.guide_deflection = guide_deflection;
  c.min_clearance = std::min({lim.gap_pos_y - c.excursion_pos, lim.gap_neg_y - c.excursion_neg,
                              lim.guide_rope_gap - guide_deflection});
  auto reached = [&](double f) {
    return c.excursion_pos >= f * lim.gap_pos_y || c.excursion_neg >= f * lim.gap_neg_y ||
           guide_deflection >= f * lim.guide_rope_gap;
  };
  if (reached(lim.critical_fraction)) c.level = ClearanceLevel::Critical;
  else if (reached(lim.warning_fraction)) c.level = ClearanceLevel::Warning;
  return c;
}

}  // namespace hoist
