// hoist/service/core/sensor_sequence.hpp -- the sequence rule of one sensor
// channel (HOIST_CAGE_IMU, HOIST_ROPE_LOAD): a sample is accepted when its
// seq comes after the last accepted one.  A seq that goes back is an old or
// replayed sample and is rejected -- unless it goes back by kRestartJump or
// more (the sender restarted), or kResyncAfter samples in a row went back:
// then the stream is taken as restarted at this seq.  The second rule bounds
// what one forged sample with a seq far ahead can do (the genuine sender's
// samples would otherwise all look old until its seq caught up: 500 ahead is
// 5 s of a 100-Hz sensor) to kResyncAfter - 1 lost samples.  Negative
// sequence numbers follow the same rules as positive ones.
#pragma once

#include <cstdint>

namespace hoist::service::inline core {

struct SensorSequence {
  static constexpr std::int64_t kRestartJump = 1000;
  static constexpr int kResyncAfter = 8;
  enum class Verdict : std::uint8_t { Accept, Old, Restart };

  std::int64_t last = 0;   ///< the last accepted seq (valid when have)
  bool have = false;       ///< a seq was accepted (any int64, negative ones too)
  int old_run = 0;         ///< samples in a row rejected as old
  Verdict next(std::int64_t seq) {
    if (have && seq <= last) {
      // last - seq >= 0 here; in unsigned arithmetic it cannot overflow.
      const auto back = static_cast<std::uint64_t>(last) - static_cast<std::uint64_t>(seq);
      if (back < static_cast<std::uint64_t>(kRestartJump) && ++old_run < kResyncAfter) return Verdict::Old;
      old_run = 0;
      last = seq;
      return Verdict::Restart;
    }
    old_run = 0;
    last = seq;
    have = true;
    return Verdict::Accept;
  }
};

}  // namespace hoist::service::core
