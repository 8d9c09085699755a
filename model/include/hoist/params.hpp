// hoist/params.hpp -- every symbol of Wang et al. (2016), Section 2-3, as one
// validated value type.  SI units throughout.  No I/O here: loading from TOML
// lives in io/ (hoist_io); this header only states and checks values.
//
// Symbols (paper -> field):
//   rho1 -> rho1      hoisting-rope mass per length           [kg/m]
//   EA   -> EA        hoisting-rope axial stiffness            [N]
//   u1   -> u1        hoisting-rope distributed damping       [kg/(m s)]
//   l(0) -> l0        initial hoisting-rope length             [m]
//   L    -> L         guide-rope length                        [m]
//   rho2 -> rho2      guide-rope mass per length              [kg/m]
//   u2   -> u2        guide-rope distributed damping          [kg/(m s)]
//   Tb1, Tb2          guide-rope preloads at the lower end     [N]
//   m, J              cage mass [kg] and moment of inertia     [kg m^2]
//   h                 cage half height (cage is 2h tall)       [m]
//   Fa, b             eccentric load [N] and its offset        [m]
//   n                 assumed modes per rope
//   g                 gravity                                  [m/s^2]
#pragma once

#include <stdexcept>
#include <string>

namespace hoist {

/// How the state at t = 0 is chosen (MODEL.md "Left open by the paper").
enum class InitialState {
  Static,  ///< static equilibrium of the reduced system (v = a = 0, all loads), zero velocity
  Rest,    ///< q = 0, q' = 0: the eccentric load acts as a step at t = 0
};

const char* toString(InitialState s);

/// Thrown by validate(): `key()` is the TOML key (e.g. "cage.mass") at fault.
class ParamError : public std::invalid_argument {
 public:
  ParamError(std::string key, const std::string& what)
      : std::invalid_argument(key + ": " + what), key_(std::move(key)) {}
  const std::string& key() const { return key_; }

 private:
  std::string key_;
};

/// Largest number of assumed modes accepted (memory and time grow as n^2..n^3).
inline constexpr int kMaxModes = 1000;

struct ShaftParams {
  // [hoisting_rope]
  double rho1 = 3.0;   ///< hoisting_rope.mass_per_length
  double EA = 3.2e7;   ///< hoisting_rope.axial_stiffness
  double u1 = 30.0;    ///< hoisting_rope.damping
  double l0 = 50.0;    ///< hoisting_rope.initial_length
  // [guide_ropes]
  double L = 400.0;    ///< guide_ropes.length
  double rho2 = 2.2;   ///< guide_ropes.mass_per_length
  double u2 = 0.3;     ///< guide_ropes.damping
  double Tb1 = 3.0e4;  ///< guide_ropes.preload[0]
  double Tb2 = 3.0e4;  ///< guide_ropes.preload[1]
  // [cage]
  double m = 800.0;    ///< cage.mass
  double J = 870.0;    ///< cage.inertia
  double h = 8.0;      ///< cage.half_height
  // [load]
  double Fa = 1000.0;  ///< load.eccentric_force
  double b = 1.0;      ///< load.offset
  // [model]
  int n = 50;          ///< model.modes
  double g = 9.81;     ///< model.gravity
  InitialState initial = InitialState::Static;  ///< model.initial
  /// model.rho_inf: spectral radius at infinite frequency of the generalized-alpha
  /// integrator, in [0, 1).  1 would be the trapezoidal rule, which is only
  /// marginally stable for the index-3 constraints with moving sleeves (the
  /// multipliers grow without bound, see tests); 0.9 damps the spurious
  /// constraint oscillation while keeping second-order accuracy.
  double rho_inf = 0.9;

  /// Throws ParamError naming the key of the first invalid value.
  void validate() const;

  /// Largest admissible hoisting-rope length: the bottom sleeves must stay
  /// inside the guide ropes, 0 < l < L - 2h.
  double maxRopeLength() const { return L - 2.0 * h; }
};

/// The paper's Section 3 baseline (also the default-constructed value).
inline ShaftParams paperBaseline() { return ShaftParams{}; }

}  // namespace hoist
