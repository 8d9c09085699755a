// hoist/history/schema.hpp -- the history database's schema, once, for both
// back ends (SQLite and PostgreSQL) and for the record's JSON/CSV forms.
//
// Every stored column of a TripRecord (hoist/trip_record.hpp) and of a
// DepthBinStats is one row of tripFields() / binFields(): its column name,
// its kind (real, integer, boolean, text), the schema version that added it,
// and how to read it from and write it into the record.  The DDL, the
// INSERT statements, the readers' checks, the JSON codec and the CSV export
// are all made from these tables, so a new record field is one row here
// plus a migration (a new version in schemaSteps()).
//
// Versions (docs/condition.md "Schema"):
//   1  schema_version(version); trips (shaft, trip, every TripRecord field;
//      key (shaft, trip)); bins (shaft, trip, idx, every DepthBinStats field;
//      key (shaft, trip, idx), deleted with their trip)
//   2  baseline (shaft, trip, marked_us): the trips an operator marked as the
//      commissioning fingerprint; an index on trips(wall_end_us) for pruning
// The DDL uses types both engines read the same way (BIGINT, DOUBLE
// PRECISION, TEXT): SQLite gives them INTEGER / REAL / TEXT affinity.
//
// Thread safety: the tables are immutable after first use (function-local
// statics).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hoist/trip_record.hpp"

namespace hoist::history {

/// The schema version this program writes (and migrates older ones to).
inline constexpr int kSchemaVersion = 2;

/// Upper limits a record read from a database (or a queue file) must meet;
/// anything beyond is "absurd" and rejected with a clear error.
inline constexpr std::size_t kMaxBins = 100000;
inline constexpr std::size_t kMaxText = 4096;

enum class Kind { Real, Integer, Boolean, Text };

/// One value of a column (the member that matches the kind is used).
struct Value {
  Kind kind = Kind::Real;
  double real = 0.0;
  std::int64_t integer = 0;  ///< also a Boolean (0/1)
  std::string text;
};

template <class Record>
struct Field {
  std::string_view column;
  Kind kind;
  int since;  ///< schema version that added the column
  Value (*get)(const Record&);
  void (*set)(Record&, const Value&);
};
using TripField = Field<TripRecord>;
using BinField = Field<DepthBinStats>;

/// The columns of `trips` after (shaft, trip), in order.
std::span<const TripField> tripFields();
/// The columns of `bins` after (shaft, trip, idx), in order.
std::span<const BinField> binFields();

/// The SQL statements that take a database from version `to - 1` to `to`
/// (to = 1: create it), the last one setting schema_version.  Throws
/// std::out_of_range for a version this program does not know.
std::vector<std::string> schemaSteps(int to);

/// "INSERT INTO trips(shaft,trip,...) VALUES(?,?,...)" with `placeholder`
/// "?" (SQLite) or "$" (PostgreSQL: $1, $2, ...), and the same for bins.
std::string insertTripSql(bool numbered);
std::string insertBinSql(bool numbered);
/// "shaft,trip,col,..." of trips / "col,..." of bins (after the keys).
std::string tripColumnList();
std::string binColumnList();

/// Why `r` cannot be stored ("" if it can): a non-finite number, a
/// direction other than +-1, a negative trip number or bin count, more than
/// kMaxBins bins, bins out of order, an alarm name with ';' or a shaft name
/// or text longer than kMaxText.  Names the field ("bins[3].fy_rms: nan").
std::string recordError(const TripRecord& r);

/// Checks a value read back from a database against its field: the kind,
/// finite reals, booleans 0/1, direction +-1, text length.  Returns "" or
/// why not.
std::string valueError(std::string_view column, Kind kind, const Value& v);

/// The alarms as stored: kinds joined with ';' ("" = none); and back.
std::string joinAlarms(const std::vector<std::string>& alarms);
std::vector<std::string> splitAlarms(std::string_view s);

}  // namespace hoist::history
