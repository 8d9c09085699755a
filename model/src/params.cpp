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

}  // namespace

std::string ParamField::key() const { return std::string(section) + "." + std::string(name); }

std::string ParamField::element() const {
  return index < 0 ? key() : key() + "[" + std::to_string(index) + "]";
}

double ParamField::get(const ShaftParams& p) const {
  switch (type) {
    case ParamType::Real: return p.*real;
    case ParamType::Integer: return p.*integer;
    case ParamType::Boolean: return p.*boolean ? 1.0 : 0.0;
    case ParamType::Initial: return p.*initial == InitialState::Static ? 0.0 : 1.0;
  }
  return 0.0;
}

void ParamField::set(ShaftParams& p, double v) const {
  switch (type) {
    case ParamType::Real: p.*real = v; break;
    case ParamType::Integer: p.*integer = static_cast<int>(v); break;
    case ParamType::Boolean: p.*boolean = v != 0.0; break;
    case ParamType::Initial: p.*initial = v == 0.0 ? InitialState::Static : InitialState::Rest; break;
  }
}

std::string ParamField::check(double v) const {
  if (type == ParamType::Integer) {
    if (bound == ParamBound::Closed && !(v >= lo && v <= hi))
      return "must be between " + fmt(lo) + " and " + fmt(hi) + " (got " + fmt(v) + ")";
    return {};
  }
  if (bound == ParamBound::None) return {};
  if (!std::isfinite(v)) return "must be a finite number (got " + fmt(v) + ")";
  switch (bound) {
    case ParamBound::Positive:
      if (!(v > 0.0)) return "must be > 0 (got " + fmt(v) + ")";
      break;
    case ParamBound::NonNegative:
      if (!(v >= 0.0)) return "must be >= 0 (got " + fmt(v) + ")";
      break;
    case ParamBound::Closed:
      if (!(v >= lo && v <= hi)) return "must be in [" + fmt(lo) + ", " + fmt(hi) + "] (got " + fmt(v) + ")";
      break;
    default: break;
  }
  return {};
}

const ParamField* findParam(std::string_view key) {
  for (const auto& f : kParamFields)
    if (f.element() == key || (f.index < 0 && f.key() == key)) return &f;
  return nullptr;
}

std::vector<const ParamField*> paramFieldsOf(std::string_view section, std::string_view name) {
  std::vector<const ParamField*> out;
  for (const auto& f : kParamFields)
    if (f.section == section && f.name == name) out.push_back(&f);
  return out;
}

void ShaftParams::validate() const {
  // Each value on its own, in table order.
  for (const auto& f : kParamFields)
    if (std::string why = f.check(f.get(*this)); !why.empty()) throw ParamError(f.key(), why);
  // Relations between values.
  if (!(2.0 * h < L))
    throw ParamError("cage.half_height", "cage height 2h = " + fmt(2.0 * h) +
                                             " m must be shorter than the guide ropes (guide_ropes.length = " +
                                             fmt(L) + " m)");
  if (!(l0 < maxRopeLength()))
    throw ParamError("hoisting_rope.initial_length",
                     "must be < L - 2h = " + fmt(maxRopeLength()) + " m so the cage is inside the guide ropes (got " +
                         fmt(l0) + ")");
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
