// Network strings for log lines: see log_safe.hpp.
#include "log_safe.hpp"

#include "hoist/msg/codec.hpp"

namespace hoist::dash {

namespace {
// The code point of the bidi control whose UTF-8 encoding starts at s[i], or 0.
unsigned bidiAt(std::string_view s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  if (i + 1 < s.size() && b(0) == 0xD8 && b(1) == 0x9C) return 0x061C;
  if (i + 2 >= s.size() || b(0) != 0xE2) return 0;
  const unsigned cp = 0x2000u + ((b(1) & 0x3Fu) << 6) + (b(2) & 0x3Fu);
  if (b(1) < 0x80 || b(1) > 0x81) return 0;
  if (cp == 0x200E || cp == 0x200F || (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069)) return cp;
  return 0;
}
}  // namespace

std::string logSafe(std::string_view s, std::size_t max_bytes) {
  static const char* hex = "0123456789abcdef";
  const std::string t = msg::terminalSafe(s, max_bytes);
  std::string out;
  out.reserve(t.size());
  for (std::size_t i = 0; i < t.size();) {
    if (const unsigned cp = bidiAt(t, i); cp != 0) {
      out += "\\u";
      for (int sh = 12; sh >= 0; sh -= 4) out += hex[(cp >> sh) & 15];
      i += cp == 0x061C ? 2 : 3;
    } else {
      out += t[i++];
    }
  }
  return out;
}

}  // namespace hoist::dash
