// tests/support/lcm_messages.hpp -- building LCM messages in tests.
#pragma once

#include <cstdint>
#include <vector>

#include "hoist/winder_t.hpp"

namespace hoist::test {

/// The bytes of `m` as LCM would send them.
template <class Msg>
std::vector<std::uint8_t> encode(const Msg& m) {
  std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

/// A winder input with the encoder length (a = 0).
inline hoist::winder_t winder(std::int64_t seq, std::int64_t utime, double v = 0.0, double length = 100.0) {
  hoist::winder_t m{};
  m.utime = utime;
  m.seq = seq;
  m.v = v;
  m.a = 0.0;
  m.has_length = true;
  m.length = length;
  return m;
}

}  // namespace hoist::test
