// The study catalogue: see hoist/study/studies.hpp.
#include "hoist/study/studies.hpp"

#include <cstdio>

#include "hoist/study/parameters.hpp"

namespace hoist::study {
namespace {
std::string fmt(double v) { return formatValue(v); }
}  // namespace

const std::vector<std::string>& paperStudyNames() {
  static const std::vector<std::string> names = {"response", "preload", "tension-difference",
                                                 "eccentric-load", "mass"};
  return names;
}

Study sweepStudy(const std::string& key, const std::vector<double>& values, const ShaftParams& base) {
  if (values.empty()) throw ParamError(key, "no values to sweep");
  Study s;
  s.name = "sweep";
  s.key = key;
  s.title = "sweep of " + key;
  for (double v : values) {
    RunSpec r;
    r.value = v;
    r.params = base;
    applyParameter(r.params, key, v);
    try {
      r.params.validate();
    } catch (const ParamError& e) {
      throw ParamError(key, "value " + fmt(v) + " gives invalid parameters (" + e.what() + ")");
    }
    r.label = key + "=" + fmt(v);
    s.runs.push_back(std::move(r));
  }
  return s;
}

std::optional<Study> paperStudy(const std::string& name, const ShaftParams& base) {
  Study s;
  if (name == "response") {
    s.name = name;
    s.title = "baseline response (Section 3.1)";
    s.figures = "2-5";
    RunSpec r;
    r.label = "baseline";
    r.params = base;
    r.params.validate();
    s.runs.push_back(r);
    return s;
  }
  if (name == "preload") {
    s = sweepStudy("guide_ropes.preload", {4.8e4, 5.4e4, 6e4}, base);
    s.title = "total preload Tb1 + Tb2, Tb1 = Tb2 (Section 3.2, case 1)";
    s.figures = "6-7";
    for (auto& r : s.runs) r.label = "Tb1+Tb2=" + fmt(r.value) + " N";
  } else if (name == "tension-difference") {
    ShaftParams b = base;
    applyParameter(b, "guide_ropes.preload", 6e4);
    s = sweepStudy("guide_ropes.preload_difference", {0.0, 5000.0, 10000.0}, b);
    s.title = "tension difference dT = Tb2 - Tb1 at Tb1 + Tb2 = 6e4 N (Section 3.2, case 2)";
    s.figures = "8-9";
    for (auto& r : s.runs) r.label = "dT=" + fmt(r.value) + " N";
  } else if (name == "eccentric-load") {
    s = sweepStudy("load.eccentric_force", {1000.0, 2000.0, 3000.0}, base);
    s.title = "eccentric load Fa (Section 3.3)";
    s.figures = "10-11";
    for (auto& r : s.runs) r.label = "Fa=" + fmt(r.value) + " N";
  } else if (name == "mass") {
    s = sweepStudy("cage.mass_and_inertia", {800.0, 1200.0, 1600.0}, base);
    s.title = "cage mass m with J in proportion (Section 3.3)";
    s.figures = "12-13";
    for (auto& r : s.runs) r.label = "m=" + fmt(r.params.m) + " kg, J=" + fmt(r.params.J);
  } else {
    return std::nullopt;
  }
  s.name = name;
  return s;
}

}  // namespace hoist::study
