// hoist/plausibility.hpp -- the model's valid range of rope length and a
// plausibility bound on its outputs (beyond finiteness).
//
// Valid range.  The reduced model is verified over 0 < l < L - 2h, but it is
// a numerical model: as l -> 0 the hoisting rope's axial stiffness EA/l and as
// l -> L - 2h the guide-rope segment below the cage make the step
// ill-conditioned.  Measured (hoist-sim, rest start, n = 50, 2.5 ms
// substeps): bounded and within 1 % of the static values down to 1e-5 m from
// either end; at 1e-7 m the state reaches 1e282 m within 3 s.  The valid
// range is therefore [d, L - 2h - d] with d = kMinEndDistance = 0.05 m, a
// factor 5000 above the last stable distance measured.  hoist-sim rejects a
// profile that leaves it; the daemon raises MODEL_DOMAIN and holds.
//
// Plausibility.  A state can be finite and still nonsense (y_c = -1e159 m).
// With a lateral limit Y [m] (a cage or guide rope further than Y from its
// axis has left the shaft; the daemon uses plausible_factor x its largest
// configured gap but at least 1 m, hoist-sim 1 m):
//   |y_c - h theta|, |y_c + h theta|         <= Y
//   |theta|                                   <= Y / h
//   |x_c|                                     <= Y + 10 (m g + Fa + rho1 g L) L / EA
//   |lambda_0 .. lambda_4|                    <= 10 (m g + Fa + Tb1 + Tb2 + (rho1 + 2 rho2) g L)
// i.e. no rope force above ten times the whole system's weight plus both
// preloads, no stretch above ten times the static one at full depth.  The
// normal values are orders of magnitude inside (paper shaft: |y_c| 6 mm,
// |lambda_0| 8.8 kN against Y = 1 m and 890 kN).
#pragma once

#include "hoist/params.hpp"
#include "hoist/solver.hpp"

namespace hoist {

/// Smallest distance of the rope length from either end of its range [m].
inline constexpr double kMinEndDistance = 0.05;

/// [lo, hi] = [kMinEndDistance, L - 2h - kMinEndDistance].
struct LengthRange {
  double lo = 0.0, hi = 0.0;
  bool contains(double l) const { return l >= lo && l <= hi; }
};
LengthRange validLengthRange(const ShaftParams& p);

struct PlausibilityBounds {
  double lateral = 1.0;  ///< Y: |y_top|, |y_bottom| [m]
  double theta = 0.0;    ///< [rad]
  double x_c = 0.0;      ///< [m]
  double force = 0.0;    ///< every |lambda_k| [N]
};
/// Bounds for the shaft `p` with lateral limit `max_lateral` (> 0) [m].
PlausibilityBounds plausibilityBounds(const ShaftParams& p, double max_lateral);

/// nullptr if `r` is finite and inside `b`; otherwise the name of the first
/// offending quantity ("y_c", "theta", "x_c", "lambda_k", "non-finite") with
/// its value and limit.  No allocation.
const char* implausible(const CageResponse& r, double h, const PlausibilityBounds& b, double& value,
                        double& limit);

}  // namespace hoist
