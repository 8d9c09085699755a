// libFuzzer target: every LCM type of msgs/ through hoist_msgs_codec, as every
// program of the project decodes them (hoist-twind, hoist-monitor,
// hoist-log2csv, hoist-replay, hoist-dash, hoist-mqtt).
//
// Input: byte 0 selects the type (byte % number of types) and, with bit 7
// set, writes that type's fingerprint over the next 8 bytes (so the fuzzer
// gets past the fingerprint at once); the rest is the LCM payload.
// Built with -DHOIST_FUZZ_ONE_TYPE=<type> (the fuzz_msg_<type> targets, one
// per decoded type): the same input format and seeds, but byte 0 no longer
// selects, only that type's decoder runs, so the whole budget goes to it.
// Checked for every input:
//   * checkedDecode never crashes, leaks or allocates more than the type's
//     largest valid encoding implies (ASan, -rss_limit_mb, -malloc_limit_mb);
//   * ok  => lcm-gen's encode of the result reproduces the bytes exactly, the
//            JSON dumps without throwing and fromJson(toJson(m)) re-encodes to
//            the same bytes;
//   * not ok => lcm-gen's decode is not even reached (nothing to check), but
//            the status is one of the enum's values;
//   * findByFingerprint and bytesToJson agree with checkedDecode.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "hoist/msg/codec.hpp"

using namespace hoist::msg;

namespace {

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_msgs: %s\n", what);
  std::abort();
}

template <class T>
void check(const std::uint8_t* data, std::size_t size) {
  T m;
  const DecodeStatus st = checkedDecode(data, size, m);
  const TypeInfo* info = findByFingerprint(data, size);
  nlohmann::json j;
  DecodeStatus st2{};
  const bool ok2 = info != nullptr && info->bytesToJson(data, size, j, st2);
  if (st != DecodeStatus::ok) {
    if (static_cast<int>(st) < 0 || static_cast<int>(st) > static_cast<int>(DecodeStatus::exception)) fail("status");
    if (st == DecodeStatus::exception) fail("lcm-gen decode threw after validation");
    return;
  }
  if (!ok2 || st2 != DecodeStatus::ok) fail("bytesToJson disagrees");
  std::vector<std::uint8_t> b(size);
  if (m.encode(b.data(), 0, static_cast<int>(size)) != static_cast<int>(size) ||
      std::memcmp(b.data(), data, size) != 0)
    fail("re-encoding differs");
  const nlohmann::json mine = toJson(m);
  if (mine != j && mine.dump() != j.dump()) fail("toJson differs");
  (void)mine.dump();  // must not throw (valid UTF-8)
  // JSON round trip: equal as JSON (an LCM boolean byte of 2 is `true` and
  // comes back as 1, and NaN dumps as null, so compare the dumped JSON).
  T back;
  std::string err;
  if (!fromJson(mine, back, err)) {
    // Only legitimate refusal: a string with invalid UTF-8 grew past the
    // byte cap when each bad byte became U+FFFD (3 bytes).
    if (err.find("longer than") == std::string::npos) fail("fromJson(toJson(m)) rejected");
    return;
  }
  if (toJson(back).dump() != mine.dump()) fail("JSON round trip differs");
  // (Re-encoded sizes may differ: invalid UTF-8 became U+FFFD in the JSON.)
  std::vector<std::uint8_t> b2(static_cast<std::size_t>(back.getEncodedSize()));
  if (back.encode(b2.data(), 0, static_cast<int>(b2.size())) != static_cast<int>(b2.size())) fail("re-encode");
  T again;
  if (checkedDecode(b2.data(), b2.size(), again) != DecodeStatus::ok) fail("JSON round trip not decodable");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  std::vector<std::uint8_t> buf(data + 1, data + size);
#ifdef HOIST_FUZZ_ONE_TYPE
  const auto fp = static_cast<std::uint64_t>(hoist::HOIST_FUZZ_ONE_TYPE::getHash());
#else
  const auto& types = allTypes();
  const std::size_t k = data[0] % types.size();
  const auto fp = static_cast<std::uint64_t>(types[k].fingerprint);
#endif
  if ((data[0] & 0x80) != 0 && buf.size() >= 8) {
    for (int i = 0; i < 8; ++i) buf[i] = static_cast<std::uint8_t>(fp >> (8 * (7 - i)));
  }
  // `buf` holds exactly the payload, so ASan sees any overread.
  static const std::uint8_t empty = 0;
  const std::uint8_t* p = buf.empty() ? &empty : buf.data();
#ifdef HOIST_FUZZ_ONE_TYPE
  check<hoist::HOIST_FUZZ_ONE_TYPE>(p, buf.size());
#else
  // Every type's decoder sees the bytes (only the matching one gets past the
  // fingerprint).
#define HOIST_FUZZ_TYPE(T) check<hoist::T>(p, buf.size());
  HOIST_MSG_FOR_EACH_TYPE(HOIST_FUZZ_TYPE)
#undef HOIST_FUZZ_TYPE
#endif
  return 0;
}
