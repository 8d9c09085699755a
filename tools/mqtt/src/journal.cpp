// hoist-mqtt's store-and-forward journal: see hoist/mqtt/journal.hpp.
#include "hoist/mqtt/journal.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "hoist/io/checked_file.hpp"
#include "journal_format.hpp"

namespace hoist::mqtt {

using namespace journal_format;
using Clock = std::chrono::steady_clock;

Journal::~Journal() {
  try {
    close();
  } catch (...) {
  }
}

void Journal::fail(const std::string& what, int err) {
  ++write_errors_;
  last_error_ = path_ + ": " + what + (err ? std::string(": ") + std::strerror(err) : std::string());
}

std::string Journal::ownDirectoryError(const std::string& dir) {
  struct stat st{};
  if (::lstat(dir.c_str(), &st) != 0) return "[buffer] dir " + dir + ": " + std::strerror(errno);
  char mode[8];
  std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
  if (S_ISLNK(st.st_mode))
    return "[buffer] dir " + dir + ": is a symbolic link; give the real directory (owned by the bridge's user, "
           "not writable by group or others)";
  if (!S_ISDIR(st.st_mode)) return "[buffer] dir " + dir + ": not a directory";
  if (st.st_uid != ::geteuid())
    return "[buffer] dir " + dir + " (mode " + mode + "): owned by uid " + std::to_string(st.st_uid) +
           ", not by the bridge's user (uid " + std::to_string(::geteuid()) +
           "); its records are replayed with the bridge's credentials: use a directory of its own";
  if (st.st_mode & (S_IWGRP | S_IWOTH))
    return "[buffer] dir " + dir + " (mode " + mode + "): writable by group or others; its records are replayed "
           "with the bridge's credentials: chmod go-w " + dir;
  return "";
}

JournalReport Journal::open(const std::string& dir, const JournalLimits& limits) {
  close();
  dir_ = dir.empty() ? std::string(".") : dir;
  while (dir_.size() > 1 && dir_.back() == '/') dir_.pop_back();
  path_ = dir_ + "/journal.bin";
  limits_ = limits;
  JournalReport rep;
  rep.path = path_;
  if (limits_.max_bytes < 4096) throw JournalError("[buffer] max_bytes: " + std::to_string(limits_.max_bytes) + " < 4096");
  struct stat st{};
  if (::stat(dir_.c_str(), &st) != 0) {
    if (errno != ENOENT) throw JournalError("[buffer] dir " + dir_ + ": " + std::strerror(errno));
    if (::mkdir(dir_.c_str(), 0750) != 0)
      throw JournalError("[buffer] dir " + dir_ + ": cannot create it: " + std::strerror(errno));
  }
  // Its records are replayed with the bridge's credentials: the directory
  // must be the bridge's own (not a symlink, owned by this user, not
  // writable by group or others).
  if (std::string why = ownDirectoryError(dir_); !why.empty()) throw JournalError(why);
  // The checked writer's rules: a writable directory, a regular target.
  if (std::string why = hoist::io::outputPathError(path_, "[buffer] dir:"); !why.empty()) throw JournalError(why);
  if (::lstat(path_.c_str(), &st) != 0) {
    try {
      hoist::io::CheckedFile f(path_, "[buffer] dir:");
      f.write(header());
      f.close(/*durable=*/true);
    } catch (const hoist::io::WriteError& e) {
      throw JournalError(e.what());
    }
    rep.created = true;
  }
  fd_ = ::open(path_.c_str(), O_RDWR | O_NOFOLLOW | O_CLOEXEC);
  if (fd_ < 0) throw JournalError("[buffer] dir: " + path_ + ": cannot open: " + std::strerror(errno));
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd_);
    fd_ = -1;
    throw JournalError("[buffer] dir: " + path_ + ": not a regular file; refusing to use it");
  }
  if ((st.st_mode & 07777) != kFileMode && ::fchmod(fd_, kFileMode) != 0) {
    ::close(fd_);
    fd_ = -1;
    throw JournalError("[buffer] dir: " + path_ + ": cannot make it mode 0600: " + std::strerror(errno));
  }
  const auto size = static_cast<std::uint64_t>(st.st_size);

  unsigned char h[kHeaderBytes];
  const std::string want = header();
  if (size < kHeaderBytes || !readAt(fd_, 0, h, kHeaderBytes) || std::memcmp(h, want.data(), kHeaderBytes) != 0) {
    rep.problem = size < kHeaderBytes ? "file shorter than its header"
                  : std::memcmp(h, kMagic, sizeof kMagic) != 0
                      ? "not a hoist-mqtt journal (bad magic)"
                      : "journal version " + std::to_string(get(h + 8, 2)) + " (this bridge reads version " +
                            std::to_string(kVersion) + ") or a damaged header";
    rep.skipped_bytes = size;
    recreate(rep);
    return rep;
  }

  // Scan: the first record that fails a check ends the good part.
  std::uint64_t off = kHeaderBytes, last_seq = 0;
  std::string body;
  std::deque<Entry> all;
  while (off < size) {
    unsigned char pre[kRecordPrefix];
    const std::uint64_t left = size - off;
    auto bad = [&](const std::string& why) { rep.problem = "record at byte " + std::to_string(off) + ": " + why; };
    if (left < kRecordPrefix) {
      bad("truncated (" + std::to_string(left) + " bytes left, a record prefix is 8)");
      break;
    }
    if (!readAt(fd_, off, pre, kRecordPrefix)) {
      bad(std::string("cannot read: ") + std::strerror(errno));
      break;
    }
    const std::uint64_t len = get(pre, 4);
    const auto crc = static_cast<std::uint32_t>(get(pre + 4, 4));
    // Lengths before any allocation.
    if (len > kMaxRecordBytes) {
      bad("length " + std::to_string(len) + " exceeds the record limit " + std::to_string(kMaxRecordBytes));
      break;
    }
    if (len > left - kRecordPrefix) {
      bad("truncated (length " + std::to_string(len) + ", " + std::to_string(left - kRecordPrefix) + " bytes left)");
      break;
    }
    if (len < kConsumedBody) {
      bad("length " + std::to_string(len) + " is shorter than any record");
      break;
    }
    body.resize(len);
    if (!readAt(fd_, off + kRecordPrefix, body.data(), len)) {
      bad(std::string("cannot read: ") + std::strerror(errno));
      break;
    }
    if (crc32(body.data(), len) != crc) {
      bad("CRC mismatch");
      break;
    }
    const auto type = static_cast<std::uint8_t>(body[0]);
    if (type == kTypeConsumed) {
      if (len != kConsumedBody) {
        bad("consumed marker of length " + std::to_string(len));
        break;
      }
      const std::uint64_t s = get(reinterpret_cast<const unsigned char*>(body.data()) + 4, 8);
      if (s > last_seq) {
        bad("consumed marker past the last message");
        break;
      }
      consumed_seq_ = std::max(consumed_seq_, s);
    } else if (type == kTypeMessage) {
      OutMsg m;
      std::uint64_t seq = 0;
      if (std::string why = decodeMessage(body, m, seq); !why.empty()) {
        bad(why);
        break;
      }
      if (seq <= last_seq) {
        bad("sequence " + std::to_string(seq) + " not after " + std::to_string(last_seq));
        break;
      }
      last_seq = seq;
      all.push_back({off, static_cast<std::uint32_t>(kRecordPrefix + len), seq, m.cls});
    } else {
      bad("unknown record type " + std::to_string(type));
      break;
    }
    off += kRecordPrefix + len;
  }
  if (off < size) {
    rep.skipped_bytes = size - off;
    if (::ftruncate(fd_, static_cast<off_t>(off)) != 0 || ::fdatasync(fd_) != 0)
      fail("cannot cut off the bad part", errno);
  }
  end_ = off;
  next_seq_ = last_seq + 1;
  marked_seq_ = consumed_seq_;
  for (const auto& e : all) {
    if (e.seq <= consumed_seq_) {
      ++rep.already_sent;
      continue;
    }
    index_.push_back(e);
    live_bytes_ += e.bytes;
    n_alarm_ += e.cls == MsgClass::Alarm ? 1 : 0;
  }
  rep.recovered = index_.size();
  rep.recovered_bytes = live_bytes_;
  last_sync_ = Clock::now();
  if (index_.empty() && end_ > kHeaderBytes) {  // all sent: start afresh
    if (::ftruncate(fd_, kHeaderBytes) == 0) end_ = kHeaderBytes;
    consumed_seq_ = marked_seq_ = 0;
    next_seq_ = 1;
  }
  return rep;
}

/// A header that is not ours: the file starts again (its bytes are reported).
void Journal::recreate(JournalReport& rep) {
  (void)rep;
  const std::string h = header();
  if (::ftruncate(fd_, 0) != 0 || !writeAt(0, h) || ::fdatasync(fd_) != 0) fail("cannot rewrite the header", errno);
  end_ = kHeaderBytes;
  last_sync_ = Clock::now();
}

void Journal::close() {
  if (fd_ < 0) return;
  sync(true);
  ::close(fd_);
  fd_ = -1;
  index_.clear();
  end_ = live_bytes_ = consumed_seq_ = marked_seq_ = 0;
  next_seq_ = 1;
  n_alarm_ = 0;
}

bool Journal::writeAt(std::uint64_t offset, const std::string& bytes) {
  const char* p = bytes.data();
  std::size_t n = bytes.size();
  while (n > 0) {
    const ssize_t w = ::pwrite(fd_, p, n, static_cast<off_t>(offset));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<std::size_t>(w);
    offset += static_cast<std::uint64_t>(w);
  }
  return true;
}

bool Journal::append(const OutMsg& m) {
  if (fd_ < 0) return false;
  const std::uint64_t need = kRecordPrefix + kMessageFixed + m.topic.size() + m.payload.size();
  if (need - kRecordPrefix > kMaxRecordBytes || need > (limits_.max_bytes - kHeaderBytes) / 2) {
    ++oversized_;
    return false;
  }
  if (end_ + need > limits_.max_bytes && !makeRoom(need)) return false;
  const auto age = Clock::now() - (m.queued == Clock::time_point{} ? Clock::now() : m.queued);
  const std::int64_t utime =
      wallUtime() - std::chrono::duration_cast<std::chrono::microseconds>(std::max(age, Clock::duration::zero())).count();
  const std::string rec = encodeMessage(m, next_seq_, utime);
  if (!writeAt(end_, rec)) {
    fail("append failed", errno);
    // A partial record would be cut off at the next open; cut it now.
    if (::ftruncate(fd_, static_cast<off_t>(end_)) != 0) {
    }
    return false;
  }
  index_.push_back({end_, static_cast<std::uint32_t>(rec.size()), next_seq_, m.cls});
  ++next_seq_;
  end_ += rec.size();
  live_bytes_ += rec.size();
  n_alarm_ += m.cls == MsgClass::Alarm ? 1 : 0;
  ++appended_;
  unsynced_ = true;
  if (limits_.fsync_interval <= 0.0) sync(true);
  return true;
}

bool Journal::readMessage(const Entry& e, OutMsg& out, std::string* why) {
  std::string rec(e.bytes, '\0');
  if (!readAt(fd_, e.offset, rec.data(), rec.size())) {
    if (why) *why = std::string("cannot read: ") + std::strerror(errno);
    return false;
  }
  const auto* p = reinterpret_cast<const unsigned char*>(rec.data());
  const std::string body = rec.substr(kRecordPrefix);
  if (get(p, 4) != body.size() || crc32(body.data(), body.size()) != get(p + 4, 4)) {
    if (why) *why = "changed on disk (length or CRC)";
    return false;
  }
  std::uint64_t seq = 0;
  if (std::string w = decodeMessage(body, out, seq); !w.empty() || seq != e.seq) {
    if (why) *why = w.empty() ? "sequence changed on disk" : w;
    return false;
  }
  return true;
}

std::optional<OutMsg> Journal::peek() {
  if (index_.empty() || fd_ < 0) return std::nullopt;
  OutMsg m;
  std::string why;
  if (!readMessage(index_.front(), m, &why)) {
    ++read_errors_;
    last_error_ = path_ + ": record at byte " + std::to_string(index_.front().offset) + ": " + why;
    return std::nullopt;
  }
  return m;
}

void Journal::pop() {
  if (index_.empty()) return;
  const Entry e = index_.front();
  index_.pop_front();
  live_bytes_ -= e.bytes;
  n_alarm_ -= e.cls == MsgClass::Alarm ? 1 : 0;
  consumed_seq_ = e.seq;
  ++popped_;
  if (index_.empty()) {
    // Everything sent: back to the bare header (nothing to replay after a restart).
    if (::ftruncate(fd_, kHeaderBytes) == 0) {
      end_ = kHeaderBytes;
      marked_seq_ = consumed_seq_;
      unsynced_ = true;
    }
  }
}

void Journal::sync(bool force) {
  if (fd_ < 0) return;
  const auto now = Clock::now();
  if (!force && std::chrono::duration<double>(now - last_sync_).count() < limits_.fsync_interval) return;
  if (consumed_seq_ > marked_seq_ && !index_.empty()) {
    const std::string rec = consumedRecord(consumed_seq_);
    if (end_ + rec.size() > limits_.max_bytes) {
      rewrite({}, std::vector<bool>(index_.size(), false));  // compaction leaves out what was sent: no marker needed
    } else if (writeAt(end_, rec)) {
      end_ += rec.size();
      marked_seq_ = consumed_seq_;
      unsynced_ = true;
    } else {
      fail("cannot write the consumed marker", errno);
    }
  }
  if (unsynced_) {
    if (::fdatasync(fd_) == 0) {
      ++fsyncs_;
      unsynced_ = false;
    } else {
      fail("fdatasync failed", errno);
    }
  }
  last_sync_ = now;
}

bool Journal::makeRoom(std::uint64_t record_bytes) {
  // Target: the live records and the new one in at most 3/4 of max_bytes.
  const std::uint64_t budget = limits_.max_bytes / 4 * 3;
  const std::uint64_t target = budget > kHeaderBytes + record_bytes ? budget - kHeaderBytes - record_bytes : 0;
  std::vector<bool> drop(index_.size(), false);
  std::uint64_t live = live_bytes_;
  for (int cls = 0; cls < 3 && live > target; ++cls)
    for (std::size_t i = 0; i < index_.size() && live > target; ++i)
      if (!drop[i] && static_cast<int>(index_[i].cls) == cls) {
        drop[i] = true;
        live -= index_[i].bytes;
      }
  return rewrite({}, drop);
}

bool Journal::prepend(const std::vector<OutMsg>& older) {
  if (fd_ < 0) return false;
  if (older.empty()) return true;
  return rewrite(older, std::vector<bool>(index_.size(), false));
}

bool Journal::rewrite(const std::vector<OutMsg>& older, const std::vector<bool>& drop) {
  std::deque<Entry> fresh;
  std::uint64_t off = kHeaderBytes, seq = 1, live = 0;
  std::size_t alarms = 0;
  std::uint64_t dropped[3] = {0, 0, 0}, unreadable = 0;
  try {
    hoist::io::CheckedFile f(path_, "[buffer] dir:");
    f.write(header());
    auto put = [&](const OutMsg& m, std::int64_t utime) {
      const std::string rec = encodeMessage(m, seq, utime);
      f.write(rec);
      fresh.push_back({off, static_cast<std::uint32_t>(rec.size()), seq, m.cls});
      ++seq;
      off += rec.size();
      live += rec.size();
      alarms += m.cls == MsgClass::Alarm ? 1 : 0;
    };
    auto utimeOf = [](const OutMsg& m) {
      const auto age = Clock::now() - (m.queued == Clock::time_point{} ? Clock::now() : m.queued);
      return wallUtime() -
             std::chrono::duration_cast<std::chrono::microseconds>(std::max(age, Clock::duration::zero())).count();
    };
    for (const auto& m : older) put(m, utimeOf(m));
    for (std::size_t i = 0; i < index_.size(); ++i) {
      if (drop[i]) {
        ++dropped[static_cast<int>(index_[i].cls)];
        continue;
      }
      OutMsg m;
      if (!readMessage(index_[i], m, nullptr)) {
        ++unreadable;
        continue;
      }
      put(m, utimeOf(m));
    }
    f.close(/*durable=*/true);
  } catch (const hoist::io::WriteError& e) {
    ++write_errors_;
    last_error_ = e.what();
    return false;
  }
  // The new file is in place: switch to it.
  const int nfd = ::open(path_.c_str(), O_RDWR | O_NOFOLLOW | O_CLOEXEC);
  struct stat st{};
  if (nfd < 0 || ::fstat(nfd, &st) != 0 || !S_ISREG(st.st_mode) || ::fchmod(nfd, kFileMode) != 0) {
    if (nfd >= 0) ::close(nfd);
    fail("cannot reopen after compaction", errno);
    return false;
  }
  ::close(fd_);
  fd_ = nfd;
  index_ = std::move(fresh);
  end_ = off;
  live_bytes_ = live;
  n_alarm_ = alarms;
  next_seq_ = seq;
  consumed_seq_ = marked_seq_ = 0;
  unsynced_ = false;
  for (int c = 0; c < 3; ++c) dropped_[c] += dropped[c];
  read_errors_ += unreadable;
  ++compactions_;
  last_sync_ = Clock::now();
  return true;
}

}  // namespace hoist::mqtt
