// hoist/params.hpp -- every symbol of Wang et al. (2016), Section 2-3, as one
// validated value type.  SI units throughout.  No I/O here: loading from TOML
// lives in io/ (hoist_io); this header only states and checks values.
//
// Frame (x down from the shaft top, y lateral, theta): model/include/hoist/solver.hpp
// and docs/model.md "Frame and signs".
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
//   static_correction residual flexibility of the guide ropes (not in the paper)
//
// The table kParamFields below is the one place that maps a configuration key
// to its member, unit, paper symbol and bounds: validate(), the TOML reader
// and writer (hoist_io), --print-config, hoist-study's --param and the key
// list in README.md (checked by a test) all follow it.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hoist {

/// How the state at t = 0 is chosen (docs/model.md "Left open by the paper").
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
  /// load.max_payload: the conveyance's rating [N]; the load estimate is
  /// plausible only with 0 <= Fa <= this.  0 = derived: max(5 |Fa|, 2 m g).
  double max_payload = 0.0;
  /// load.max_offset: the largest |b| a load can sit at (the conveyance's
  /// half-width) [m].  0 = derived: max(2 |b|, h / 4).
  double max_offset = 0.0;
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
  /// model.static_correction: add the guide ropes' residual flexibility at the
  /// sleeves (the quasi-static compliance of the modes above n, from the exact
  /// static Green's function) to the sleeve constraints of the fast path, so
  /// that statics are exact for every n and the tilt converges at n ~ 10-20
  /// (docs/model.md).  false = the paper's literal truncation (reproduces the
  /// reference data); the paper path (Method::Paper) requires false.
  bool static_correction = true;

  bool operator==(const ShaftParams&) const = default;

  /// Throws ParamError naming the key of the first invalid value.
  void validate() const;

  /// Largest admissible hoisting-rope length: the bottom sleeves must stay
  /// inside the guide ropes, 0 < l < L - 2h.
  double maxRopeLength() const { return L - 2.0 * h; }
  /// max_payload, or its derived default when 0.
  double payloadLimit() const { return max_payload > 0.0 ? max_payload : std::max(5.0 * std::abs(Fa), 2.0 * m * g); }
  /// max_offset, or its derived default when 0.
  double offsetLimit() const { return max_offset > 0.0 ? max_offset : std::max(2.0 * std::abs(b), 0.25 * h); }
};

/// The paper's Section 3 baseline (also the default-constructed value).
inline ShaftParams paperBaseline() { return ShaftParams{}; }

// ---- the parameter table ------------------------------------------------------

/// How a value is stored (and written in TOML).
enum class ParamType { Real, Integer, Boolean, Initial };

/// The check validate() applies to one value on its own (relations between
/// values, such as 2h < L, are checked after all single values).
enum class ParamBound {
  None,         ///< anything of the right type
  Finite,       ///< a finite number
  Positive,     ///< finite and > 0
  NonNegative,  ///< finite and >= 0
  Closed,       ///< finite and in [lo, hi]
};

/// One value of ShaftParams: where it lives in the TOML file and in the struct.
/// Exactly one of the member pointers is set, matching `type`.
struct ParamField {
  std::string_view section;  ///< TOML table, e.g. "guide_ropes"
  std::string_view name;     ///< key in that table, e.g. "preload"
  int index;                 ///< element of a TOML array (guide_ropes.preload = [Tb1, Tb2]); -1: a scalar
  ParamType type;
  double ShaftParams::*real;
  int ShaftParams::*integer;
  bool ShaftParams::*boolean;
  InitialState ShaftParams::*initial;
  std::string_view unit;    ///< SI unit ("" if none)
  std::string_view symbol;  ///< the paper's symbol
  ParamBound bound;
  double lo, hi;            ///< for ParamBound::Closed
  bool sweepable;           ///< hoist-study --param may set it on its own
  std::string_view doc;     ///< short meaning (README, --help, TOML comments)

  /// "section.name": the key validate() and the TOML reader report.
  std::string key() const;
  /// key() with "[index]" for an array element: "guide_ropes.preload[1]".
  std::string element() const;
  /// The value as a number (booleans 0/1; the initial state 0 = static, 1 = rest).
  double get(const ShaftParams& p) const;
  /// Store a number (see get()); the caller has checked it with check().
  void set(ShaftParams& p, double v) const;
  /// Why `v` is not admissible on its own ("must be > 0 (got -1)"), or "" if it is.
  std::string check(double v) const;
};

namespace detail {
constexpr ParamField real(std::string_view sec, std::string_view name, double ShaftParams::*m, std::string_view unit,
                          std::string_view sym, ParamBound b, std::string_view doc, int index = -1,
                          double lo = 0.0, double hi = 0.0, bool sweepable = true) {
  return {sec, name, index, ParamType::Real, m, nullptr, nullptr, nullptr, unit, sym, b, lo, hi, sweepable, doc};
}
}  // namespace detail

/// Every value of ShaftParams, in the order of the TOML file (sections
/// hoisting_rope, guide_ropes, cage, load, model).
inline constexpr std::array<ParamField, 21> kParamFields = {{
    detail::real("hoisting_rope", "mass_per_length", &ShaftParams::rho1, "kg/m", "rho1", ParamBound::Positive,
                 "hoisting-rope mass per length"),
    detail::real("hoisting_rope", "axial_stiffness", &ShaftParams::EA, "N", "EA", ParamBound::Positive,
                 "hoisting-rope axial stiffness"),
    detail::real("hoisting_rope", "damping", &ShaftParams::u1, "kg/(m s)", "u1", ParamBound::NonNegative,
                 "hoisting-rope distributed damping"),
    detail::real("hoisting_rope", "initial_length", &ShaftParams::l0, "m", "l(0)", ParamBound::Positive,
                 "initial hoisting-rope length (used when a profile has no l column), in (0, L - 2h)", -1, 0.0,
                 0.0, false),
    detail::real("guide_ropes", "length", &ShaftParams::L, "m", "L", ParamBound::Positive, "guide-rope length"),
    detail::real("guide_ropes", "mass_per_length", &ShaftParams::rho2, "kg/m", "rho2", ParamBound::Positive,
                 "guide-rope mass per length"),
    detail::real("guide_ropes", "damping", &ShaftParams::u2, "kg/(m s)", "u2", ParamBound::NonNegative,
                 "guide-rope distributed damping"),
    detail::real("guide_ropes", "preload", &ShaftParams::Tb1, "N", "Tb1", ParamBound::Positive,
                 "preload (tension at the lower end) of guide rope 1", 0),
    detail::real("guide_ropes", "preload", &ShaftParams::Tb2, "N", "Tb2", ParamBound::Positive,
                 "preload (tension at the lower end) of guide rope 2", 1),
    detail::real("cage", "mass", &ShaftParams::m, "kg", "m", ParamBound::Positive, "cage mass"),
    detail::real("cage", "inertia", &ShaftParams::J, "kg m^2", "J", ParamBound::Positive,
                 "cage moment of inertia about its centre"),
    detail::real("cage", "half_height", &ShaftParams::h, "m", "h", ParamBound::Positive,
                 "cage half height (the cage is 2h tall)"),
    detail::real("load", "eccentric_force", &ShaftParams::Fa, "N", "Fa", ParamBound::Finite, "eccentric load"),
    detail::real("load", "offset", &ShaftParams::b, "m", "b", ParamBound::Finite,
                 "offset of the eccentric load from the cage axis"),
    detail::real("load", "max_payload", &ShaftParams::max_payload, "N", "Fa_max", ParamBound::NonNegative,
                 "the conveyance's rating: a load estimate above it is not plausible (0: max(5 |Fa|, 2 m g))"),
    detail::real("load", "max_offset", &ShaftParams::max_offset, "m", "b_max", ParamBound::NonNegative,
                 "the largest |b| a load can sit at, the conveyance's half-width (0: max(2 |b|, h / 4))"),
    ParamField{"model", "modes", -1, ParamType::Integer, nullptr, &ShaftParams::n, nullptr, nullptr, "", "n",
               ParamBound::Closed, 1.0, double(kMaxModes), true, "assumed modes per rope (integer)"},
    detail::real("model", "gravity", &ShaftParams::g, "m/s^2", "g", ParamBound::NonNegative,
                 "gravitational acceleration"),
    ParamField{"model", "initial", -1, ParamType::Initial, nullptr, nullptr, nullptr, &ShaftParams::initial, "",
               "", ParamBound::None, 0.0, 0.0, false,
               "\"static\" (equilibrium at t = 0) or \"rest\" (q = 0)"},
    detail::real("model", "rho_inf", &ShaftParams::rho_inf, "", "rho_inf", ParamBound::Closed,
                 "generalized-alpha spectral radius at infinite frequency", -1, 0.0, 1.0),
    ParamField{"model", "static_correction", -1, ParamType::Boolean, nullptr, nullptr,
               &ShaftParams::static_correction, nullptr, "", "", ParamBound::None, 0.0, 0.0, true,
               "add the quasi-static correction (true or false)"},
}};

/// The sections of kParamFields in file order.
inline constexpr std::array<std::string_view, 5> kParamSections = {"hoisting_rope", "guide_ropes", "cage", "load",
                                                                  "model"};

/// The field of `key` ("cage.mass", or "guide_ropes.preload[1]" for an array
/// element), or nullptr.
const ParamField* findParam(std::string_view key);

/// The fields of one TOML key ("guide_ropes.preload" has two), in index order.
/// Empty for an unknown key.
std::vector<const ParamField*> paramFieldsOf(std::string_view section, std::string_view name);

}  // namespace hoist
