// ConditionText: one sentence of the shaft's memory (the preload trend's,
// the fingerprint's, a trip-end preload verdict's), as the trip room's
// worker writes it and the loop carries it into the alarm texts: a fixed
// array, so that handing it over and keeping it allocate nothing.  Long
// enough for the longest sentence with the trips it names (the preload
// trend's advice came to about 260 characters with three trips); a longer
// one is cut, never overrun.  The alarm text around it (ShaftOutputs)
// leaves room for the kind, level, event and state.
#pragma once

#include <array>
#include <cstddef>

namespace hoist::service::inline app {

inline constexpr std::size_t kConditionTextChars = 400;
using ConditionText = std::array<char, kConditionTextChars>;

}  // namespace hoist::service::app
