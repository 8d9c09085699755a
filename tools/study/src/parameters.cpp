// The keys hoist-study --param can sweep: see hoist/study/parameters.hpp.
// The plain keys come from hoist::kParamFields; only the derived ones are
// written here.
#include "hoist/study/parameters.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

namespace hoist::study {

std::string formatValue(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

namespace {

std::string fmt(double v) { return formatValue(v); }

/// A key that sets several members at once.
struct Derived {
  const char* key;
  const char* help;
  std::function<void(ShaftParams&, const std::string&, double)> set;
  std::function<double(const ShaftParams&)> get;
};

const std::vector<Derived>& derivedKeys() {
  static const std::vector<Derived> d = {
      {"guide_ropes.preload", "total preload Tb1 + Tb2 [N], split equally",
       [](ShaftParams& p, const std::string&, double v) { p.Tb1 = p.Tb2 = 0.5 * v; },
       [](const ShaftParams& p) { return p.Tb1 + p.Tb2; }},
      {"guide_ropes.preload_difference", "Tb2 - Tb1 [N] at the current total",
       [](ShaftParams& p, const std::string&, double v) {
         const double total = p.Tb1 + p.Tb2;
         p.Tb1 = 0.5 * (total - v);
         p.Tb2 = 0.5 * (total + v);
       },
       [](const ShaftParams& p) { return p.Tb2 - p.Tb1; }},
      {"guide_ropes.preload_split", "Tb1 / (Tb1 + Tb2) at the current total",
       [](ShaftParams& p, const std::string& key, double v) {
         if (!(v > 0.0 && v < 1.0)) throw ParamError(key, "split must be in (0, 1), got " + fmt(v));
         const double total = p.Tb1 + p.Tb2;
         p.Tb1 = v * total;
         p.Tb2 = (1.0 - v) * total;
       },
       [](const ShaftParams& p) { return p.Tb1 / (p.Tb1 + p.Tb2); }},
      {"cage.mass_and_inertia", "m [kg] with J scaled in proportion (the paper's mass study)",
       [](ShaftParams& p, const std::string& key, double v) {
         if (!(v > 0.0)) throw ParamError(key, "mass must be > 0, got " + fmt(v));
         p.J *= v / p.m;
         p.m = v;
       },
       [](const ShaftParams& p) { return p.m; }},
  };
  return d;
}

/// Why a table key cannot be swept on its own.
std::string notSweepable(const ParamField& f) {
  if (f.real == &ShaftParams::l0) return "not sweepable here: the profile fixes l(t) (use --profile)";
  return "not sweepable (not a number; use the command-line option)";
}

std::string helpOf(const ParamField& f) {
  std::string s(f.symbol.empty() ? f.doc : f.symbol);
  if (!f.unit.empty()) s += " [" + std::string(f.unit) + "]";
  if (!f.symbol.empty()) s += ", " + std::string(f.doc);
  return s;
}

}  // namespace

const std::vector<std::string>& sweepableKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> v;
    for (const auto& f : kParamFields)
      if (f.sweepable) v.push_back(f.element());
    for (const auto& d : derivedKeys()) v.emplace_back(d.key);
    return v;
  }();
  return keys;
}

std::string parameterHelp() {
  std::string s;
  auto line = [&s](std::string key, const std::string& help) {
    key.resize(std::max<std::size_t>(key.size() + 2, 34), ' ');
    s += "  " + key + help + "\n";
  };
  for (const auto& f : kParamFields)
    if (f.sweepable) line(f.element(), helpOf(f));
  for (const auto& d : derivedKeys()) line(d.key, d.help);
  return s;
}

void applyParameter(ShaftParams& p, const std::string& key, double value) {
  if (!std::isfinite(value)) throw ParamError(key, "value must be finite, got " + fmt(value));
  for (const auto& d : derivedKeys())
    if (key == d.key) return d.set(p, key, value);
  const ParamField* f = findParam(key);
  if (f && !f->sweepable) throw ParamError(key, notSweepable(*f));
  if (!f) {
    std::string list;
    for (const auto& k : sweepableKeys()) list += (list.empty() ? "" : ", ") + k;
    throw ParamError(key, "unknown or unsweepable key; valid keys: " + list);
  }
  if (f->type == ParamType::Integer &&
      (value != std::floor(value) || (f->bound == ParamBound::Closed && !(value >= f->lo && value <= f->hi))))
    throw ParamError(key, "must be an integer in [" + fmt(f->lo) + ", " + fmt(f->hi) + "], got " + fmt(value));
  if (f->type == ParamType::Boolean && value != 0.0 && value != 1.0)
    throw ParamError(key, "must be 0 (false) or 1 (true), got " + fmt(value));
  f->set(p, value);
}

double parameterValue(const ShaftParams& p, const std::string& key) {
  for (const auto& d : derivedKeys())
    if (key == d.key) return d.get(p);
  if (const ParamField* f = findParam(key); f && f->sweepable) return f->get(p);
  throw ParamError(key, "unknown key");
}

}  // namespace hoist::study
