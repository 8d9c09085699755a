// hoist/io/lcm_log.cpp -- see lcm_log.hpp.  Written from the format described
// in lcm/eventlog.c (LCM), not from its code.
#include "hoist/io/lcm_log.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace hoist::io {

namespace {

std::uint64_t be(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

LcmLogReader::LcmLogReader(const std::string& path, std::uint32_t max_data) : path_(path), max_data_(max_data) {
  f_ = std::fopen(path.c_str(), "rb");
  if (f_ == nullptr) {
    fail(std::string("cannot open: ") + std::strerror(errno));
    return;
  }
  struct stat st {};
  if (fstat(fileno(f_), &st) != 0) {
    fail(std::string("cannot stat: ") + std::strerror(errno));
    return;
  }
  if (!S_ISREG(st.st_mode)) {
    fail("not a regular file");
    return;
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

LcmLogReader::~LcmLogReader() {
  if (f_ != nullptr) std::fclose(f_);
}

void LcmLogReader::fail(const std::string& what) {
  if (error_.empty()) error_ = path_ + ": " + what;
}

bool LcmLogReader::readAt(std::uint64_t off, void* buf, std::size_t n) {
  if (off > size_ || n > size_ - off) return false;
  if (fseeko(f_, static_cast<off_t>(off), SEEK_SET) != 0) {
    fail(std::string("seek failed: ") + std::strerror(errno));
    return false;
  }
  if (std::fread(buf, 1, n, f_) != n) {
    fail(std::ferror(f_) ? std::string("read error: ") + std::strerror(errno)
                         : std::string("file shrank while reading"));
    return false;
  }
  return true;
}

bool LcmLogReader::syncAt(std::uint64_t off) {
  std::uint8_t b[4];
  return readAt(off, b, 4) && be(b, 4) == kSync;
}

bool LcmLogReader::validAt(std::uint64_t off, LcmLogEvent& ev, std::uint32_t& chl, std::uint32_t& dl,
                           std::uint64_t& end) {
  std::uint8_t h[kHeader];
  if (!readAt(off, h, kHeader)) return false;
  if (be(h, 4) != kSync) return false;
  const auto ch = static_cast<std::int32_t>(be(h + 20, 4));
  const auto d = static_cast<std::int32_t>(be(h + 24, 4));
  if (ch < 1 || ch > kMaxChannel || d < 0 || static_cast<std::uint32_t>(d) > max_data_) return false;
  const std::uint64_t left = size_ - off - kHeader;  // readAt succeeded: off + 28 <= size_
  if (static_cast<std::uint64_t>(ch) + static_cast<std::uint64_t>(d) > left) return false;
  end = off + kHeader + static_cast<std::uint64_t>(ch) + static_cast<std::uint64_t>(d);
  if (end != size_ && (size_ - end < 4 || !syncAt(end))) return false;
  char name[kMaxChannel];
  if (!readAt(off + kHeader, name, static_cast<std::size_t>(ch))) return false;
  for (int i = 0; i < ch; ++i) {
    const auto c = static_cast<unsigned char>(name[i]);
    if (c < 0x20 || c == 0x7f) return false;
  }
  ev.eventnum = static_cast<std::int64_t>(be(h + 4, 8));
  ev.timestamp = static_cast<std::int64_t>(be(h + 12, 8));
  ev.channel.assign(name, static_cast<std::size_t>(ch));
  ev.offset = off;
  chl = static_cast<std::uint32_t>(ch);
  dl = static_cast<std::uint32_t>(d);
  return true;
}

std::uint64_t LcmLogReader::findSync(std::uint64_t from) {
  std::uint8_t buf[65536];
  std::uint64_t off = from;
  while (off + 4 <= size_) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(sizeof buf, size_ - off));
    if (!readAt(off, buf, n)) return size_;
    for (std::size_t i = 0; i + 4 <= n; ++i)
      if (be(buf + i, 4) == kSync) return off + i;
    off += n - 3;  // a sync word may straddle the chunks
  }
  return size_;
}

void LcmLogReader::closeRegion(std::uint64_t at, const LcmLogEvent* next) {
  if (at <= good_end_) return;
  if (stats_.regions == 0) stats_.first_bad_offset = good_end_;
  ++stats_.regions;
  const std::uint64_t skipped = at - good_end_;
  stats_.bytes_skipped += skipped;
  // Events lost: the gap in event numbers when it is plausible for the bytes
  // skipped (each event takes >= 29 bytes), else at least one.
  std::uint64_t lost = 1;
  if (next != nullptr && have_last_num_ && next->eventnum > last_num_) {
    // In unsigned arithmetic: the numbers come from the file, and their
    // signed difference can overflow (fuzz_lcmlog: INT64_MIN + 1, then 5).
    const std::uint64_t gap = static_cast<std::uint64_t>(next->eventnum) - static_cast<std::uint64_t>(last_num_) - 1;
    if (gap >= 1 && gap <= skipped / (kHeader + 1) + 1) lost = gap;
  }
  stats_.events_lost += lost;
}

bool LcmLogReader::next(LcmLogEvent& ev) {
  if (f_ == nullptr || !ok()) return false;
  while (pos_ < size_) {
    std::uint32_t chl = 0, dl = 0;
    std::uint64_t end = 0;
    if (!validAt(pos_, ev, chl, dl, end)) {
      if (!ok()) return false;
      pos_ = findSync(pos_ + 1);
      if (!ok()) return false;
      continue;
    }
    ev.data.resize(dl);  // validated: <= max_data and within the file
    if (dl > 0 && !readAt(pos_ + kHeader + chl, ev.data.data(), dl)) return false;
    closeRegion(pos_, &ev);
    pos_ = good_end_ = end;
    have_last_num_ = true;
    last_num_ = ev.eventnum;
    ++stats_.events;
    return true;
  }
  closeRegion(size_, nullptr);
  good_end_ = size_;
  return false;
}

std::string LcmLogReader::summary() const {
  std::string s = std::to_string(stats_.events) + " events";
  if (!stats_.lost()) return s + ", no corruption";
  return s + "; " + std::to_string(stats_.bytes_skipped) + " bytes skipped in " +
         std::to_string(stats_.regions) + " corrupt region(s) (first at byte " +
         std::to_string(stats_.first_bad_offset) + "), about " + std::to_string(stats_.events_lost) +
         " event(s) lost";
}

}  // namespace hoist::io
