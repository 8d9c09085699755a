// hoist/history/store.hpp -- the history database: one TripRecord per
// (shaft, trip), with its depth bins, in SQLite or PostgreSQL.
//
// Who calls: hoist-trips (tools/trips) and, later, the daemon's trip worker
// -- never the real-time loop (every call does file or network I/O and may
// block for the database's timeouts).  One Store per thread: a Store is not
// thread-safe; two processes may open the same database (SQLite: WAL and a
// 5 s busy timeout; PostgreSQL: the server).
//
// open (openStore): creates the database at schema version kSchemaVersion,
// or migrates an older one step by step (each step one transaction); a newer
// version, a database that is not ours, or garbage is refused with
// StoreError naming the database.
//
// One writer per shaft (the shaft's daemon, or one hoist-trips ingest at a
// time): trip numbers are the key, and a number assigned while PostgreSQL
// is down is this writer's own (last seen + queued + 1).
//
// put(): one transaction per record (the trip row and its bins together or
// nothing).  Idempotent on (shaft, trip): a record whose key is already
// stored is left as it is and reported Duplicate, so a retry never doubles a
// trip.  trip == 0: the store assigns the next number of the shaft.  A record
// recordError() refuses is rejected with StoreError (nothing written).
// PostgreSQL: when the server cannot be reached, the record goes to the
// on-disk queue (hoist/history/queue.hpp) and put() reports Queued; every
// later put() and flush() first writes the queue in order.
//
// Reading: every value is checked against its column (kind, finite, ranges,
// schema.hpp); a bad row throws StoreError naming the trip and column.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hoist/history/config.hpp"
#include "hoist/trip_record.hpp"

namespace hoist::history {

class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class PutResult { Stored, Duplicate, Queued };
const char* toString(PutResult r);

struct StoreStats {
  std::int64_t stored = 0;      ///< records written by this Store
  std::int64_t duplicates = 0;  ///< puts of a key already stored
  std::int64_t queued = 0;      ///< records put into the outage queue
  std::int64_t flushed = 0;     ///< queued records written since
  std::int64_t pending = 0;     ///< records waiting in the queue now
  std::int64_t queue_rejected = 0;  ///< queue files that failed their CRC (moved aside as .bad)
  bool connected = true;        ///< PostgreSQL: the server answered the last attempt
  std::string last_error;       ///< the last connection error ("" = none)
};

struct ListFilter {
  std::optional<std::string> shaft;  ///< only this shaft (nullopt: every shaft)
  bool with_bins = false;            ///< also read the depth bins
  std::int64_t from_trip = 0, to_trip = 0;  ///< 0: no bound
  std::int64_t limit = 0;            ///< at most this many trips, the first in (shaft, trip) order (0: all)
};

class Store {
 public:
  virtual ~Store() = default;

  /// Writes `r` (see above); `r.trip` is set when it was 0.
  virtual PutResult put(TripRecord& r) = 0;
  /// Trips ordered by (shaft, trip).
  virtual std::vector<TripRecord> list(const ListFilter& f = {}) = 0;
  /// One trip with its bins, or nullopt.
  virtual std::optional<TripRecord> get(const std::string& shaft, std::int64_t trip) = 0;
  /// Marks (on) or unmarks a trip as part of the baseline (the commissioning
  /// fingerprint).  Throws StoreError when the trip is not stored.
  virtual void markBaseline(const std::string& shaft, std::int64_t trip, bool on, std::int64_t now_us) = 0;
  /// The marked trips of `shaft`, ascending.
  virtual std::vector<std::int64_t> baseline(const std::string& shaft) = 0;
  /// Deletes the trips that ended more than keep_days before now_us (with
  /// their bins and marks); keep_days <= 0 does nothing.  Returns how many.
  virtual std::int64_t prune(int keep_days, std::int64_t now_us) = 0;
  /// The number the next trip of `shaft` gets (1 for a new shaft).
  virtual std::int64_t nextTrip(const std::string& shaft) = 0;
  /// PostgreSQL: writes the queue now if the server is back (else does
  /// nothing); returns how many queued records remain.  SQLite: 0.
  virtual std::int64_t flush() = 0;
  virtual StoreStats stats() const = 0;
  /// The schema version of the open database.
  virtual int schemaVersion() = 0;
  /// "sqlite /path" or "postgresql postgresql://..." (never a password).
  virtual std::string describe() const = 0;
};

/// Opens the store `o` names.  Throws StoreError (bad database, newer
/// schema, SQLite file not openable).  PostgreSQL: a server that is down
/// at open is not an error (records queue until it is back); a server that
/// refuses us (authentication, a newer schema) is.
std::unique_ptr<Store> openStore(const StoreOptions& o);

}  // namespace hoist::history
