// hoist/study/parameters.hpp -- the keys hoist-study --param can sweep: the
// sweepable entries of hoist::kParamFields (hoist/params.hpp) plus a few
// derived ones (total preload, preload difference and split, mass with
// inertia in proportion).
#pragma once

#include <string>
#include <vector>

#include "hoist/params.hpp"

namespace hoist::study {

/// Keys accepted by applyParameter(), in help order.
const std::vector<std::string>& sweepableKeys();
/// One line per key: "key  meaning".
std::string parameterHelp();

/// Set `key` to `value` in `p` (e.g. "cage.mass", "guide_ropes.preload" = total
/// preload split equally, "guide_ropes.preload_difference" = Tb2 - Tb1 at the
/// current total).  Throws ParamError(key, ...) for an unknown key or a value
/// of the wrong kind (e.g. a non-integer model.modes); does not validate the
/// whole set (call p.validate()).
void applyParameter(ShaftParams& p, const std::string& key, double value);
/// Current value of `key` in `p` (the inverse of applyParameter()).
double parameterValue(const ShaftParams& p, const std::string& key);

/// A parameter value as it appears in labels and messages ("%g").
std::string formatValue(double v);

}  // namespace hoist::study
