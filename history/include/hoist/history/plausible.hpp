// hoist/history/plausible.hpp -- is a record read from the history database
// fit to show or publish?  The readers' second check after the Store's own
// (each column's kind and range, schema.hpp valueError): recordError
// (finite numbers, direction, bins in order, text lengths) and the
// identification's plausibility (0 < s <= 5 and sigma(s) <= 5 when
// identified; depth_bin > 0; trip > 0).  Who calls: hoist-dash's Shaft
// condition view and hoist-mqtt's trip feed (a database is file input: a
// record that fails is left out and counted, never shown as trustworthy).
// Header-only, pure.
#pragma once

#include <string>

#include "hoist/history/schema.hpp"
#include "hoist/trip_record.hpp"

namespace hoist::history {

/// Why `r` is not shown ("" = it is), naming the field.
inline std::string implausible(const TripRecord& r) {
  if (auto why = recordError(r); !why.empty()) return why;
  if (r.trip <= 0) return "trip number " + std::to_string(r.trip);
  if (r.id.attempted && r.id.sigma_scale >= 0.0 && !(r.id.scale > 0.0 && r.id.scale <= 5.0))
    return "id_scale " + std::to_string(r.id.scale) + " outside (0, 5]";
  if (r.id.attempted && r.id.sigma_scale > 5.0) return "id_sigma_scale " + std::to_string(r.id.sigma_scale) + " above 5";
  if (!(r.depth_bin > 0.0)) return "depth_bin " + std::to_string(r.depth_bin);
  return {};
}

}  // namespace hoist::history
