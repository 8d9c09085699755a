// rows.hpp (history/src, private) -- a trip row and its bin rows into a
// TripRecord, checked column by column, for both back ends.  `col(i, kind)`
// returns the i-th selected column as a Value of whatever kind the database
// holds (the check compares it with the schema's kind).
//
// Trip rows are selected as tripColumnList() (shaft, trip, fields...); bin
// rows as binColumnList().  Throws StoreError naming the trip and column.
#pragma once

#include <string>

#include "hoist/history/schema.hpp"
#include "hoist/history/store.hpp"

namespace hoist::history::detail {

inline std::string tripName(const std::string& shaft, std::int64_t trip) {
  return "trip " + (shaft.empty() ? std::string() : shaft + "/") + std::to_string(trip);
}

inline void checked(const std::string& what, std::string_view column, Kind kind, const Value& v) {
  if (auto e = valueError(column, kind, v); !e.empty())
    throw StoreError("history database: " + what + ": column " + std::string(column) + ": " + e);
}

template <class Col>
TripRecord readTripRow(Col&& col, const std::string& db) {
  TripRecord r;
  const Value shaft = col(0, Kind::Text), trip = col(1, Kind::Integer);
  checked(db + ": a trip", "shaft", Kind::Text, shaft);
  checked(db + ": a trip", "trip", Kind::Integer, trip);
  r.shaft = shaft.text;
  r.trip = trip.integer;
  const std::string what = db + ": " + tripName(r.shaft, r.trip);
  int i = 2;
  for (const auto& f : tripFields()) {
    const Value v = col(i++, f.kind);
    checked(what, f.column, f.kind, v);
    f.set(r, v);
  }
  return r;
}

template <class Col>
DepthBinStats readBinRow(Col&& col, const std::string& what) {
  DepthBinStats b;
  int i = 0;
  for (const auto& f : binFields()) {
    const Value v = col(i++, f.kind);
    checked(what + " bin", f.column, f.kind, v);
    f.set(b, v);
  }
  return b;
}

}  // namespace hoist::history::detail
