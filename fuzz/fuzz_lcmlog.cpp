// libFuzzer target: hoist::io::LcmLogReader (hoist-log2csv, hoist-replay
// --lcm-log) on arbitrary file contents, each event's payload then through
// the checked decoder of its type (as hoist-log2csv does).  No input may
// crash, leak, allocate beyond the file size, or loop: the reader must end,
// every byte is either in a returned event or counted as skipped.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "hoist/io/lcm_log.hpp"
#include "hoist/msg/codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const int fd = memfd_create("fuzz_lcmlog", 0);
  if (fd < 0) std::abort();
  if (ftruncate(fd, 0) != 0 || (size > 0 && pwrite(fd, data, size, 0) != static_cast<ssize_t>(size))) std::abort();
  static const std::string path = "/proc/self/fd/" + std::to_string(fd);
  hoist::io::LcmLogReader r(path, 1u << 20);
  if (!r.ok()) std::abort();
  hoist::io::LcmLogEvent ev;
  std::uint64_t in_events = 0, n = 0;
  while (r.next(ev)) {
    if (++n > size) std::abort();  // each event takes >= 29 bytes: no loops
    in_events += hoist::io::LcmLogReader::kHeader + ev.channel.size() + ev.data.size();
    if (const auto* t = hoist::msg::findByFingerprint(ev.data.data(), ev.data.size())) {
      nlohmann::json j;
      hoist::msg::DecodeStatus st{};
      if (t->bytesToJson(ev.data.data(), ev.data.size(), j, st)) (void)j.dump();
    }
  }
  if (!r.ok()) std::abort();
  if (in_events + r.stats().bytes_skipped != size) std::abort();  // every byte accounted for
  return 0;
}
