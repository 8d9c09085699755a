// attack_bytes.hpp -- the exact hostile payloads that once crashed the programs, as
// bytes (shared by codec_test, decode_attack_test, lcm_log_test, tool_attack_test
// and dash_hub_test; fuzz/make_seeds.py writes the same cases as seeds).
//
// Layouts (LCM: big-endian; strings = int32 length incl. NUL, bytes, NUL):
//   alarm_ack_t: fp(8) utime(8) kind(str) level(1) action(1) shelve_duration(8) user(str)
//   health_t:    fp(8) ... n_reasons(int32) reject_reason[n](str) rejected[n](int64) ...
//   guide_shape_t: fp(8) utime(8) t(8) l(8) h(8) n(int32) x[n] y1[n] y2[n]
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/health_t.hpp"

namespace hoist::test::attack {

using Bytes = std::vector<std::uint8_t>;

inline void be(Bytes& b, std::uint64_t v, int n) {
  for (int i = n - 1; i >= 0; --i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

/// 37 bytes: a valid alarm_ack_t fingerprint, `kind` with the length field
/// `kind_len` and no bytes, then level, action, shelve_duration and user "ab".
/// kind_len 0 killed hoist-twind (basic_string::_M_replace escaped the LCM
/// callback), 0x80000000 segfaulted it (out-of-bounds read).
inline Bytes alarmAckStringLen(std::uint32_t kind_len) {
  Bytes b;
  be(b, static_cast<std::uint64_t>(hoist::alarm_ack_t::getHash()), 8);
  be(b, 1700000000000000ull, 8);  // utime
  be(b, kind_len, 4);             // kind: length field only
  b.push_back(0);                 // level
  b.push_back(2);                 // action = SHELVE
  be(b, 0x40AC200000000000ull, 8);  // shelve_duration = 3600.0
  be(b, 3, 4);                    // user "ab"
  b.push_back('a');
  b.push_back('b');
  b.push_back(0);
  return b;  // 37 bytes
}

/// A valid health_t (one reason) whose n_reasons field is then overwritten
/// with `n` (huge or negative): lcm-gen's decode resize()d before checking.
inline Bytes healthCount(std::int32_t n) {
  hoist::health_t h{};
  h.clock = "wall";
  h.n_reasons = 1;
  h.reject_reason = {"decode"};
  h.rejected = {1};
  Bytes b(static_cast<std::size_t>(h.getEncodedSize()));
  h.encode(b.data(), 0, static_cast<int>(b.size()));
  // offset of n_reasons: fp 8, utime 8, instance_id 8, uptime 8, t 8,
  // clock 4+5, rate 8, window 8, ticks/steps/misses 24, 6 doubles 48,
  // input_age 8, accepted/seq_gaps/rejected_total 24
  const std::size_t off = 8 + 8 + 8 + 8 + 8 + 9 + 8 + 8 + 24 + 48 + 8 + 24;
  for (int i = 0; i < 4; ++i) b[off + i] = static_cast<std::uint8_t>(static_cast<std::uint32_t>(n) >> (8 * (3 - i)));
  return b;
}

/// A guide_shape_t header with count `n` and no samples: 44 bytes (the
/// 70-byte event that took 780 MB is this plus the log-event header).
inline Bytes guideShapeCount(std::int32_t n) {
  Bytes b;
  be(b, static_cast<std::uint64_t>(hoist::guide_shape_t::getHash()), 8);
  be(b, 1700000000000000ull, 8);
  for (int i = 0; i < 3; ++i) be(b, 0, 8);  // t, l, h
  be(b, static_cast<std::uint32_t>(n), 4);
  return b;
}

/// A valid alarm_t whose `kind` string length field is then overwritten with
/// `kind_len` (0, 0x80000000, ...): the same string attack on the daemon's
/// output type, which hoist-monitor, hoist-dash and hoist-mqtt decode.
inline Bytes alarmStringLen(std::uint32_t kind_len) {
  hoist::alarm_t a{};
  a.kind = "KINDKINDKIND";
  a.message = "m";
  a.user = "u";
  Bytes b(static_cast<std::size_t>(a.getEncodedSize()));
  a.encode(b.data(), 0, static_cast<int>(b.size()));
  const std::string needle = a.kind;
  std::size_t off = 0;
  for (std::size_t i = 4; i + needle.size() <= b.size(); ++i)
    if (std::equal(needle.begin(), needle.end(), b.begin() + static_cast<std::ptrdiff_t>(i))) {
      off = i - 4;
      break;
    }
  for (int i = 0; i < 4; ++i) b[off + i] = static_cast<std::uint8_t>(kind_len >> (8 * (3 - i)));
  return b;
}

/// One LCM log event (lcm-logger format): sync word 0xEDA1DA01, event number,
/// timestamp, channel length, data length, channel, data.  `datalen` may lie.
inline Bytes logEvent(std::int64_t num, std::int64_t ts, const std::string& channel, const Bytes& data,
                      std::int64_t datalen = -1) {
  Bytes b;
  be(b, 0xEDA1DA01u, 4);
  be(b, static_cast<std::uint64_t>(num), 8);
  be(b, static_cast<std::uint64_t>(ts), 8);
  be(b, channel.size(), 4);
  be(b, static_cast<std::uint64_t>(datalen < 0 ? static_cast<std::int64_t>(data.size()) : datalen), 4);
  b.insert(b.end(), channel.begin(), channel.end());
  b.insert(b.end(), data.begin(), data.end());
  return b;
}

}  // namespace hoist::test::attack
