// hoist/clearance.hpp -- the cage's remaining clearance in the shaft, from the
// model's outputs and the shaft's gaps given as plain numbers (no config, no
// alarm state).  The same figures the daemon's alarms use
// (service/core/include/hoist/service/core/alarms.hpp, computeClearance), so a forecast
// and the live twin measure alike:
//   top-sleeve excursion      y_top    = y_c - h theta
//   bottom-sleeve excursion   y_bottom = y_c + h theta
//   toward +y                 e_pos    = max(y_top, y_bottom)
//   toward -y                 e_neg    = max(-y_top, -y_bottom)
//   guide ropes               e_guide  = largest |y_1(x)|, |y_2(x)| (GuideRopeEnvelope)
//   clearance = min(gap_pos_y - e_pos, gap_neg_y - e_neg, guide_rope_gap - e_guide)
// Threshold levels as the alarms set them: WARNING when any excursion reaches
// warning_fraction x its gap, CRITICAL at critical_fraction x its gap (raw
// crossing: the alarms' deadband and on/off delays are not applied here).
#pragma once

namespace hoist {

/// Gaps and alarm fractions ([alarms] gap_pos_y, gap_neg_y, guide_rope_gap,
/// warning_fraction, critical_fraction; same defaults).
struct ClearanceLimits {
  double gap_pos_y = 0.30;         ///< cage to wall / neighbour on the +y side [m]
  double gap_neg_y = 0.30;         ///< ... on the -y side [m]
  double guide_rope_gap = 0.30;    ///< allowed guide-rope lateral deflection [m]
  double warning_fraction = 0.5;   ///< WARNING at fraction x gap, in (0, critical_fraction)
  double critical_fraction = 0.8;  ///< CRITICAL at fraction x gap, in (warning_fraction, 1]
  /// Throws std::invalid_argument naming the field at fault.
  void validate() const;
};

enum class ClearanceLevel { None = 0, Warning = 1, Critical = 2 };

struct CageClearance {
  double excursion_pos = 0.0;    ///< max(y_top, y_bottom) [m]
  double excursion_neg = 0.0;    ///< max(-y_top, -y_bottom) [m]
  double guide_deflection = 0.0; ///< [m]
  double min_clearance = 0.0;    ///< smallest remaining clearance [m]
  ClearanceLevel level = ClearanceLevel::None;  ///< highest threshold reached
};

/// Clearance of one cage state (y_c [m], theta [rad], h cage half height [m],
/// guide_deflection [m]).  Pure, allocation-free.
CageClearance cageClearance(double y_c, double theta, double h, double guide_deflection,
                            const ClearanceLimits& lim);

}  // namespace hoist
