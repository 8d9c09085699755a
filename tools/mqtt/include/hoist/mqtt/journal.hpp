// hoist/mqtt/journal.hpp -- hoist-mqtt's store-and-forward journal: the
// messages the bridge would have sent while the broker (or, in Sparkplug
// mode, the primary host) is away, in a bounded file that survives a restart
// of the bridge ([buffer] dir, max_bytes, fsync_interval; docs/mqtt.md).
//
// One file, <dir>/journal.bin:
//   header  16 bytes: "HOISTJNL", u16 version (1), u16 header size (16),
//           u32 CRC-32 of the 12 bytes before it
//   records u32 body length, u32 CRC-32 of the body, body; little-endian.
//     message  u8 type 1, u8 class (0 cage, 1 health, 2 alarm), u8 qos,
//              u8 flags (1 retain, 2 sparkplug), u64 sequence, i64 queued
//              time (wall clock, microseconds), u32 topic length, topic,
//              payload (the rest of the body)
//     consumed u8 type 2, 3 zero bytes, u64 sequence: every message up to
//              and including it has been sent (written at sync time)
// Sequences increase through the file.  Reading validates every length
// against the record limit and the bytes left in the file BEFORE allocating,
// then the CRC, then the fields; the first record that fails ends the good
// part: it and everything after it are reported (open() returns what was
// recovered and what was skipped, and why) and cut off, and the bridge goes
// on.  A header that is not ours skips the whole file.
//
// Bounded by max_bytes (the file's size): when an append would pass it the
// journal is compacted -- the records still to be sent are copied into a new
// file (the project's checked writer: a fresh O_CREAT|O_EXCL|O_NOFOLLOW
// temporary file, fsynced, renamed over journal.bin) -- dropping, oldest
// first, cage states and estimates (class Cage), then health-class messages,
// and alarm transitions only when nothing else is left, until the file is at
// most 3/4 of max_bytes.  Each drop is counted by class.
//
// Durability: appends are written at once (write(2)); fdatasync runs every
// fsync_interval seconds (sync(), called by the owner's loop) or after every
// append with fsync_interval 0.  A power failure loses at most the records
// appended since the last fsync; what was sent since the last sync may be
// sent again after the restart (the consumed marker is written at sync time).
//
// Not thread-safe; hoist-mqtt uses it from its one loop thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hoist/mqtt/outbox.hpp"

namespace hoist::mqtt {

/// The journal directory cannot be used (start-up error; names the path).
class JournalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct JournalLimits {
  std::uint64_t max_bytes = 64ull << 20;  ///< the file's size at most (header included)
  double fsync_interval = 1.0;            ///< [s]; 0 = fdatasync after every append
};

/// What open() found.
struct JournalReport {
  std::string path;                  ///< <dir>/journal.bin
  bool created = false;              ///< there was no journal: a new one was made
  std::uint64_t recovered = 0;       ///< messages still to be sent
  std::uint64_t recovered_bytes = 0;
  std::uint64_t already_sent = 0;    ///< messages marked consumed (dropped at the next compaction)
  std::uint64_t skipped_bytes = 0;   ///< from the first bad record (or a bad header) to the end
  std::string problem;               ///< "" or what was wrong, with its byte offset
};

class Journal {
 public:
  static constexpr std::uint16_t kVersion = 1;
  static constexpr std::size_t kHeaderBytes = 16;
  static constexpr std::size_t kRecordPrefix = 8;      ///< u32 length + u32 CRC
  static constexpr std::size_t kMessageFixed = 24;     ///< message body before the topic
  static constexpr std::uint32_t kMaxRecordBytes = 16u << 20;  ///< a body longer than this is corrupt

  Journal() = default;
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  /// Opens (or creates) <dir>/journal.bin: `dir` is created if missing (one
  /// level, mode 0750); it must be a writable directory owned by this
  /// process's user, not a symbolic link and not writable by group or others
  /// (ownDirectoryError), and journal.bin, if present, a regular file; the
  /// file is kept mode 0600.  Throws JournalError naming the path (and the
  /// directory's mode) otherwise.  A corrupt or truncated file is not an
  /// error: see the report.
  JournalReport open(const std::string& dir, const JournalLimits& limits);
  bool isOpen() const { return fd_ >= 0; }
  /// Syncs (consumed marker, fdatasync) and closes.
  void close();

  /// Appends `m` (its queued time is stored as wall-clock time).  false if it
  /// was not stored: larger than a record may be (counted: oversized) or the
  /// write failed (counted: write_errors; lastError() says why).
  bool append(const OutMsg& m);

  bool empty() const { return index_.empty(); }
  std::size_t size() const { return index_.size(); }
  /// The oldest message, read back from the file; std::nullopt if it can no
  /// longer be read (counted: read_errors) -- pop() it and go on.
  std::optional<OutMsg> peek();
  /// Marks the oldest message sent.  An emptied journal is cut back to its header.
  void pop();

  /// Puts `older` (oldest first) before every message in the journal (the
  /// bridge's unacknowledged in-flight messages at shutdown).  Compacts.
  bool prepend(const std::vector<OutMsg>& older);

  /// Writes the consumed marker and fdatasyncs if anything changed since the
  /// last sync and fsync_interval has passed (always with `force`).
  void sync(bool force = false);

  // ---- counters (the bridge's health) ----
  std::uint64_t fileBytes() const { return end_; }
  std::uint64_t liveBytes() const { return live_bytes_; }
  std::size_t queuedAlarms() const { return n_alarm_; }
  std::uint64_t appended() const { return appended_; }
  std::uint64_t popped() const { return popped_; }
  std::uint64_t droppedCage() const { return dropped_[0]; }
  std::uint64_t droppedHealth() const { return dropped_[1]; }
  std::uint64_t droppedAlarm() const { return dropped_[2]; }
  std::uint64_t oversized() const { return oversized_; }
  std::uint64_t writeErrors() const { return write_errors_; }
  std::uint64_t readErrors() const { return read_errors_; }
  std::uint64_t fsyncs() const { return fsyncs_; }
  std::uint64_t compactions() const { return compactions_; }
  const std::string& lastError() const { return last_error_; }
  const std::string& path() const { return path_; }
  const JournalLimits& limits() const { return limits_; }

  /// "" if `dir` is a directory of this process's user that group and
  /// others cannot write (and not a symbolic link); else why not, naming
  /// `dir` and its mode.
  static std::string ownDirectoryError(const std::string& dir);
  static constexpr unsigned kFileMode = 0600;  ///< journal.bin's mode

  /// Encodes one message record (prefix included); exposed for the tests.
  static std::string encodeMessage(const OutMsg& m, std::uint64_t seq, std::int64_t queued_utime);
  static std::uint32_t crc32(const void* data, std::size_t n);

 private:
  struct Entry {
    std::uint64_t offset;  ///< of the record's prefix
    std::uint32_t bytes;   ///< prefix + body
    std::uint64_t seq;
    MsgClass cls;
  };
  bool writeAt(std::uint64_t offset, const std::string& bytes);
  bool readMessage(const Entry& e, OutMsg& out, std::string* why);
  /// Rewrites the file with `older` first, then the live messages except
  /// those in `drop` (indices into index_); renumbers the sequences.
  bool rewrite(const std::vector<OutMsg>& older, const std::vector<bool>& drop);
  bool makeRoom(std::uint64_t record_bytes);
  void recreate(JournalReport& rep);
  void fail(const std::string& what, int err);

  std::string dir_, path_;
  JournalLimits limits_;
  int fd_ = -1;
  std::deque<Entry> index_;
  std::uint64_t end_ = 0, live_bytes_ = 0, next_seq_ = 1, consumed_seq_ = 0, marked_seq_ = 0;
  std::size_t n_alarm_ = 0;
  bool unsynced_ = false;
  std::chrono::steady_clock::time_point last_sync_{};
  std::uint64_t appended_ = 0, popped_ = 0, dropped_[3] = {0, 0, 0}, oversized_ = 0, write_errors_ = 0,
                read_errors_ = 0, fsyncs_ = 0, compactions_ = 0;
  std::string last_error_;
};

}  // namespace hoist::mqtt
