// hoist/io/lcm_log.hpp -- a safe reader of LCM log files (lcm-logger's format),
// used instead of liblcm's eventlog reader by hoist-log2csv and hoist-replay.
//
// The format (lcm/eventlog.c): each event is a 28-byte header -- the sync word
// 0xEDA1DA01, int64 event number, int64 timestamp [us], int32 channel length,
// int32 data length, all big-endian -- then the channel bytes and the data.
//
// LCM 1.3.1's reader mallocs the data length from the header without checking
// it against the file (a header claiming 0x7fffffff bytes segfaults it), and
// stops at the first corrupted event.  This reader validates every header
// before it allocates: channel length in [1, 999] (as liblcm), no control
// bytes in the channel name, data length in [0, max_data] and channel + data
// within the bytes left in the file, and the event must be followed by the
// next sync word or the end of the file.  An event that fails any check is
// corrupt: the reader scans forward to the next sync word whose event passes
// them all, and continues.  stats() reports the bytes skipped and an estimate
// of the events lost (from the gap in event numbers around a corrupt region,
// at least one per region).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace hoist::io {

struct LcmLogEvent {
  std::int64_t eventnum = 0;
  std::int64_t timestamp = 0;  ///< [us since the Unix epoch]
  std::string channel;
  std::vector<std::uint8_t> data;
  std::uint64_t offset = 0;    ///< byte offset of the event's sync word in the file
};

struct LcmLogStats {
  std::uint64_t events = 0;         ///< good events returned
  std::uint64_t bytes_skipped = 0;  ///< bytes in corrupt regions (incl. a truncated tail)
  std::uint64_t events_lost = 0;    ///< estimated events in those regions (>= 1 per region)
  std::uint64_t regions = 0;        ///< corrupt regions
  std::uint64_t first_bad_offset = 0;  ///< offset of the first corrupt region (if any)
  bool lost() const { return bytes_skipped > 0 || events_lost > 0; }
};

class LcmLogReader {
 public:
  static constexpr std::uint32_t kSync = 0xEDA1DA01u;
  static constexpr std::size_t kHeader = 28;
  static constexpr std::int32_t kMaxChannel = 999;
  static constexpr std::uint32_t kDefaultMaxData = 64u << 20;  ///< 64 MiB

  /// Opens `path`; check ok() / error().
  explicit LcmLogReader(const std::string& path, std::uint32_t max_data = kDefaultMaxData);
  ~LcmLogReader();
  LcmLogReader(const LcmLogReader&) = delete;
  LcmLogReader& operator=(const LcmLogReader&) = delete;

  bool ok() const { return error_.empty(); }
  /// "PATH: what went wrong (errno text)" after a failed open or a read error.
  const std::string& error() const { return error_; }

  /// The next good event; false at the end of the file or on a read error
  /// (then !ok()).  Corrupt regions are skipped and counted.
  bool next(LcmLogEvent& ev);

  const LcmLogStats& stats() const { return stats_; }
  /// One line: "N events; M bytes skipped in K corrupt region(s) (first at
  /// byte B), about L event(s) lost" (or "N events, no corruption").
  std::string summary() const;

 private:
  bool readAt(std::uint64_t off, void* buf, std::size_t n);
  bool syncAt(std::uint64_t off);
  /// Validates the event at `off` (header, lengths, next sync); fills the
  /// header fields of `ev` and the end offset.
  bool validAt(std::uint64_t off, LcmLogEvent& ev, std::uint32_t& chl, std::uint32_t& dl, std::uint64_t& end);
  /// The next offset >= `from` holding the sync word, or size_.
  std::uint64_t findSync(std::uint64_t from);
  void closeRegion(std::uint64_t at, const LcmLogEvent* next);
  void fail(const std::string& what);

  std::string path_;
  std::FILE* f_ = nullptr;
  std::uint64_t size_ = 0;
  std::uint64_t pos_ = 0;       ///< where the next event is expected
  std::uint64_t good_end_ = 0;  ///< end of the last good event
  std::uint32_t max_data_;
  bool have_last_num_ = false;
  std::int64_t last_num_ = 0;
  LcmLogStats stats_;
  std::string error_;
};

}  // namespace hoist::io
