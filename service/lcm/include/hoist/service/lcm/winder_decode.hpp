// hoist/service/lcm/winder_decode.hpp -- raw HOIST_WINDER bytes -> WinderSample,
// exactly as hoist-twind decodes them (header-only: needs the lcm-gen'd
// hoist/winder_t.hpp, i.e. link hoist_msgs).
//
// Bounded work: the bytes are validated by hoist::msg::checkedDecode (the
// generated walker of hoist_msgs_codec: fingerprint, exact size 8 + 41 bytes)
// before lcm-gen's decode sees them; winder_t has no strings or arrays, so
// nothing is allocated.  Link hoist_msgs_codec.  Used by the daemon, the
// hardening tests and the LCM-input fuzzer.
#pragma once

#include <cstdint>

#include "hoist/service/core/input_validator.hpp"
#include "hoist/msg/codec.hpp"
#include "hoist/winder_t.hpp"

namespace hoist::service::inline lcm {

enum class WinderDecode : std::uint8_t {
  Ok,
  Empty,      ///< zero bytes
  Malformed,  ///< bad fingerprint (another type) or truncated
  Trailing,   ///< a valid winder_t followed by extra bytes (oversized)
};

inline const char* describe(WinderDecode d) {
  switch (d) {
    case WinderDecode::Ok: return "ok";
    case WinderDecode::Empty: return "empty payload";
    case WinderDecode::Malformed: return "not a hoist.winder_t (bad fingerprint or truncated)";
    case WinderDecode::Trailing: return "trailing bytes after a hoist.winder_t";
  }
  return "?";
}

/// Decode `size` bytes at `data` into `out` using `scratch` (no allocation).
inline WinderDecode decodeWinder(const void* data, std::int64_t size, hoist::winder_t& scratch,
                                 WinderSample& out) {
  if (size <= 0 || data == nullptr) return WinderDecode::Empty;
  switch (hoist::msg::checkedDecode(data, static_cast<std::size_t>(size), scratch)) {
    case hoist::msg::DecodeStatus::ok: break;
    case hoist::msg::DecodeStatus::too_large: return WinderDecode::Trailing;
    default: return WinderDecode::Malformed;
  }
  out.utime = scratch.utime;
  out.seq = scratch.seq;
  out.v = scratch.v;
  out.a = scratch.a;
  out.has_length = scratch.has_length != 0;
  out.length = scratch.length;
  return WinderDecode::Ok;
}

}  // namespace hoist::service::lcm
