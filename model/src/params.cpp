#include "hoist/params.hpp"

#include <cmath>
#include <sstream>

namespace hoist {

const char* toString(InitialState s) { return s == InitialState::Static ? "static" : "rest"; }

namespace {

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

void requireFinite(const char* key, double v) {
  if (!std::isfinite(v)) throw ParamError(key, "must be a finite number (got " + fmt(v) + ")");
}
void requirePositive(const char* key, double v) {
  requireFinite(key, v);
  if (!(v > 0.0)) throw ParamError(key, "must be > 0 (got " + fmt(v) + ")");
}
void requireNonNegative(const char* key, double v) {
  requireFinite(key, v);
  if (!(v >= 0.0)) throw ParamError(key, "must be >= 0 (got " + fmt(v) + ")");
}

}  // namespace

void ShaftParams::validate() const {
  requirePositive("hoisting_rope.mass_per_length", rho1);
  requirePositive("hoisting_rope.axial_stiffness", EA);
  requireNonNegative("hoisting_rope.damping", u1);
  requirePositive("guide_ropes.length", L);
  requirePositive("guide_ropes.mass_per_length", rho2);
  requireNonNegative("guide_ropes.damping", u2);
  requirePositive("guide_ropes.preload", Tb1);
  requirePositive("guide_ropes.preload", Tb2);
  requirePositive("cage.mass", m);
  requirePositive("cage.inertia", J);
  requirePositive("cage.half_height", h);
  if (!(2.0 * h < L))
    throw ParamError("cage.half_height", "cage height 2h = " + fmt(2.0 * h) +
                                             " m must be shorter than the guide ropes (guide_ropes.length = " +
                                             fmt(L) + " m)");
  requireFinite("load.eccentric_force", Fa);
  requireFinite("load.offset", b);
  requireNonNegative("model.gravity", g);
  if (n < 1 || n > kMaxModes)
    throw ParamError("model.modes", "must be between 1 and " + std::to_string(kMaxModes) + " (got " +
                                        std::to_string(n) + ")");
  requirePositive("hoisting_rope.initial_length", l0);
  if (!(l0 < maxRopeLength()))
    throw ParamError("hoisting_rope.initial_length",
                     "must be < L - 2h = " + fmt(maxRopeLength()) + " m so the cage is inside the guide ropes (got " +
                         fmt(l0) + ")");
  requireFinite("model.rho_inf", rho_inf);
  if (!(rho_inf >= 0.0 && rho_inf <= 1.0))
    throw ParamError("model.rho_inf", "must be in [0, 1] (got " + fmt(rho_inf) + ")");
  // Physical sanity: the cage rotation must be small for the linearized
  // constraints (Eq. 8) to hold.  A static tilt estimate is Fa b / (torsional
  // stiffness); we cannot bound it cheaply here, so only reject absurd offsets.
  if (std::abs(b) > L) throw ParamError("load.offset", "|b| must be smaller than the guide-rope length");
  // Physically impossible ropes.  The hoisting rope carries the cage and its
  // own weight; its static strain at the longest admissible length,
  // (m + rho1 (L - 2h)) g / EA, must stay below 2 % (a steel wire rope breaks
  // at about 1-2 %; the paper's rope is at 0.06 %), else the linear-elastic
  // model describes a rope that has already parted.
  const double strain = (m + rho1 * maxRopeLength()) * g / EA;
  if (!(strain < 0.02))
    throw ParamError("hoisting_rope.axial_stiffness",
                     "too low for the load: the static strain (m + rho1 (L - 2h)) g / EA would be " +
                         fmt(100.0 * strain) + " % (a steel rope parts at about 2 %; EA = " + fmt(EA) + " N)");
  // The guide ropes are tensioned by weights at their lower end; a preload
  // far below the rope's own weight leaves the lower part nearly slack (wave
  // speed -> 0) and the cage unguided.  Require Tb >= 1 % of rho2 g L.
  const double rope_weight = rho2 * g * L;
  for (double tb : {Tb1, Tb2})
    if (tb < 0.01 * rope_weight)
      throw ParamError("guide_ropes.preload",
                       "preload " + fmt(tb) + " N is too low for the guide rope's own weight rho2 g L = " +
                           fmt(rope_weight) + " N: it must be at least 1 % of it (the rope would hang slack)");
}

}  // namespace hoist
