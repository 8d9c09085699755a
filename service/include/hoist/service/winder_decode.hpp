// hoist/service/winder_decode.hpp -- raw HOIST_WINDER bytes -> WinderSample,
// exactly as hoist-twind decodes them (header-only: needs the lcm-gen'd
// hoist/winder_t.hpp, i.e. link hoist_msgs).
//
// Bounded work: winder_t has a fixed size (8-byte fingerprint + 41 bytes), so
// decoding reads at most that many bytes whatever `size` is; a payload of
// another size is rejected before or after decoding without touching the
// rest.  Used by the daemon, the hardening tests and the LCM-input fuzzer.
#pragma once

#include <cstdint>

#include "hoist/service/input_validator.hpp"
#include "hoist/winder_t.hpp"

namespace hoist::svc {

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
  // winder_t is fixed-size: anything longer than INT32_MAX cannot be one, and
  // LCM's int-sized decode must not see a truncated length.
  const int n = size > 0x7fffffff ? 0x7fffffff : static_cast<int>(size);
  const int used = scratch.decode(data, 0, n);
  if (used < 0) return WinderDecode::Malformed;
  if (used != size) return WinderDecode::Trailing;
  out.utime = scratch.utime;
  out.seq = scratch.seq;
  out.v = scratch.v;
  out.a = scratch.a;
  out.has_length = scratch.has_length != 0;
  out.length = scratch.length;
  return WinderDecode::Ok;
}

}  // namespace hoist::svc
