// hoist/service/sensor_sequence.hpp -- the sequence rule of one sensor
// channel (HOIST_CAGE_IMU, HOIST_ROPE_LOAD): a sample is accepted when its
// seq comes after the last accepted one.  A seq that goes back is an old or
// replayed sample and is rejected -- unless it goes back by kRestartJump or
// more (the sender restarted), or kResyncAfter samples in a row went back:
// then the stream is taken as restarted at this seq.  The second rule bounds
// what one forged sample with a seq far ahead can do (the genuine sender's
// samples would otherwise all look old until its seq caught up: 500 ahead is
// 5 s of a 100-Hz sensor) to kResyncAfter - 1 lost samples.
#pragma once

#include <cstdint>

namespace hoist::svc {

struct SensorSequence {
  static constexpr std::int64_t kRestartJump = 1000;
  static constexpr int kResyncAfter = 8;
  enum class Verdict : std::uint8_t { Accept, Old, Restart };

  std::int64_t last = -1;  ///< the last accepted seq (-1: none yet)
  int old_run = 0;         ///< samples in a row rejected as old

  Verdict next(std::int64_t seq) {
    if (last >= 0 && seq <= last) {
      if (seq > last - kRestartJump && ++old_run < kResyncAfter) return Verdict::Old;
      old_run = 0;
      last = seq;
      return Verdict::Restart;
    }
    old_run = 0;
    last = seq;
    return Verdict::Accept;
  }
};

}  // namespace hoist::svc
