// hoist/history/queue.hpp -- the on-disk queue of trip records that could
// not be written (a PostgreSQL outage), flushed in order when the server is
// back.
//
// One file per record in `dir`: q-<20-digit sequence>.trip, holding
//   "hoist-trip-queue 1 <crc32 hex> <length>\n" + the record as JSON
// (record_json.hpp).  Each file is written through io::CheckedFile with
// close(durable): a temporary file, fsync, rename, fsync of the folder, so a
// file that exists is complete (a kill -9 or power loss while writing
// leaves no file, or a stray temporary that is ignored).  The CRC and length
// catch a file damaged later; such a file is renamed to *.bad, counted and
// reported, never silently dropped or retried forever.
//
// Who calls: the PostgreSQL store only (one process per queue folder; the
// folder is created 0700 on the first push).  Not thread-safe.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hoist/trip_record.hpp"

namespace hoist::history {

class RecordQueue {
 public:
  explicit RecordQueue(std::string dir);

  struct Entry {
    std::string path;
    std::uint64_t seq = 0;
  };

  /// Appends `r` (durably).  Throws io::WriteError when it cannot be
  /// written (the caller then has nowhere to keep the record: it reports).
  void push(const TripRecord& r);
  /// The queued files, oldest first.
  std::vector<Entry> pending() const;
  /// Reads one entry.  A damaged file (CRC, length, JSON, a value the
  /// schema refuses) is renamed to *.bad, counted in rejected() and
  /// returns false with `why` set.
  bool read(const Entry& e, TripRecord& out, std::string& why);
  /// Removes an entry once its record is in the database (fsyncs the folder).
  void remove(const Entry& e);
  std::int64_t rejected() const { return rejected_; }
  const std::string& dir() const { return dir_; }
  /// The largest trip number of `shaft` among the queued records (0: none).
  std::int64_t maxTrip(const std::string& shaft);

 private:
  std::string dir_;
  std::int64_t rejected_ = 0;
};

/// CRC-32 (IEEE 802.3) of `data`: zlib's crc32.
std::uint32_t crc32(const void* data, std::size_t n);

}  // namespace hoist::history
