// The byte format of hoist-mqtt's journal: see journal_format.hpp.
#include "journal_format.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>

namespace hoist::mqtt {

namespace journal_format {

using Clock = std::chrono::steady_clock;

std::int64_t wallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

void put16(std::string& s, std::uint16_t v) {
  for (int i = 0; i < 2; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void put32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void put64(std::string& s, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
std::uint64_t get(const unsigned char* p, int n) {
  std::uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

std::string header() {
  std::string h(kMagic, sizeof kMagic);
  put16(h, Journal::kVersion);
  put16(h, static_cast<std::uint16_t>(Journal::kHeaderBytes));
  put32(h, Journal::crc32(h.data(), h.size()));
  return h;
}

/// Prefix (length, CRC) + body.
std::string frame(const std::string& body) {
  std::string r;
  r.reserve(Journal::kRecordPrefix + body.size());
  put32(r, static_cast<std::uint32_t>(body.size()));
  put32(r, Journal::crc32(body.data(), body.size()));
  r += body;
  return r;
}

std::string consumedRecord(std::uint64_t seq) {
  std::string b;
  b.push_back(static_cast<char>(kTypeConsumed));
  b.append(3, '\0');
  put64(b, seq);
  return frame(b);
}

/// Reads exactly n bytes at offset (false on EOF or error).
bool readAt(int fd, std::uint64_t offset, void* buf, std::size_t n) {
  auto* p = static_cast<unsigned char*>(buf);
  while (n > 0) {
    const ssize_t r = ::pread(fd, p, n, static_cast<off_t>(offset));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    p += r;
    n -= static_cast<std::size_t>(r);
    offset += static_cast<std::uint64_t>(r);
  }
  return true;
}

/// A message body decoded (fields checked); "" or why not.
std::string decodeMessage(const std::string& body, OutMsg& m, std::uint64_t& seq) {
  const auto* p = reinterpret_cast<const unsigned char*>(body.data());
  if (body.size() < Journal::kMessageFixed) return "message record shorter than its fixed fields";
  const unsigned cls = p[1], qos = p[2], flags = p[3];
  if (cls > 2) return "message class " + std::to_string(cls) + " is not 0..2";
  if (qos > 2) return "QoS " + std::to_string(qos) + " is not 0..2";
  if (flags & ~3u) return "unknown flags " + std::to_string(flags);
  seq = get(p + 4, 8);
  const auto utime = static_cast<std::int64_t>(get(p + 12, 8));
  const std::uint64_t topic_len = get(p + 20, 4);
  if (topic_len == 0 || topic_len > body.size() - Journal::kMessageFixed)
    return "topic length " + std::to_string(topic_len) + " does not fit the record";
  m.cls = static_cast<MsgClass>(cls);
  m.qos = static_cast<int>(qos);
  m.retain = flags & 1u;
  m.sparkplug = flags & 2u;
  m.topic.assign(body, Journal::kMessageFixed, topic_len);
  m.payload.assign(body, Journal::kMessageFixed + topic_len, std::string::npos);
  // The queued time back on the steady clock (an age measured across a restart).
  const auto age = std::chrono::microseconds(std::max<std::int64_t>(0, wallUtime() - utime));
  m.queued = Clock::now() - std::chrono::duration_cast<Clock::duration>(age);
  return "";
}

}  // namespace journal_format

using namespace journal_format;

std::uint32_t Journal::crc32(const void* data, std::size_t n) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) c = table[(c ^ p[i]) & 0xffu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

std::string Journal::encodeMessage(const OutMsg& m, std::uint64_t seq, std::int64_t queued_utime) {
  std::string b;
  b.reserve(kMessageFixed + m.topic.size() + m.payload.size());
  b.push_back(static_cast<char>(kTypeMessage));
  b.push_back(static_cast<char>(static_cast<std::uint8_t>(m.cls)));
  b.push_back(static_cast<char>(m.qos));
  b.push_back(static_cast<char>((m.retain ? 1 : 0) | (m.sparkplug ? 2 : 0)));
  put64(b, seq);
  put64(b, static_cast<std::uint64_t>(queued_utime));
  put32(b, static_cast<std::uint32_t>(m.topic.size()));
  b += m.topic;
  b += m.payload;
  return frame(b);
}

}  // namespace hoist::mqtt
