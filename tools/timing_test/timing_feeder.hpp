// hoist-timing-test's feeder: the input side of the run (timing_run.cpp).
//
//   Ring       publish times of one shaft's inputs, indexed by seq
//              (preallocated; the feeder writes, the listener reads: atomics
//              only, no lock).
//   RoundTrip  the paper's trapezoid trip down and back up, repeated.
//   Feeder     publishes HOIST_WINDER for every prefix on an absolute
//              CLOCK_MONOTONIC schedule from its own thread (own LCM
//              instance, publish only), records each publish time in the
//              shaft's Ring before publishing, counts what was sent; its
//              lateness histogram is read after the join.
//
// Who calls: runTimingTest (timing_run.cpp) builds the rings, the trip and
// one Feeder, runs Feeder::run on a thread and sets `stop` to end it early.
// Lifetimes: the options, the LCM instance, the trip and the rings are the
// caller's and outlive the feeder.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>
#include <vector>

#include "hoist/bus/channels.hpp"
#include "hoist/profile.hpp"
#include "timing_test.hpp"

namespace hoist::replay {

/// CLOCK_MONOTONIC [ns].
std::int64_t monotonicNs();

/// Publish times of one shaft's inputs, indexed by seq (preallocated; the
/// feeder writes, the listener reads).
class Ring {
 public:
  explicit Ring(std::size_t size_pow2) : slots_(new Slot[size_pow2]), mask_(size_pow2 - 1) {}
  void put(std::int64_t seq, std::int64_t utime) {
    Slot& s = slots_[static_cast<std::size_t>(seq) & mask_];
    s.seq.store(-1, std::memory_order_relaxed);
    s.utime.store(utime, std::memory_order_relaxed);
    s.seq.store(seq, std::memory_order_release);
  }
  bool get(std::int64_t seq, std::int64_t& utime) const {
    if (seq < 0) return false;
    const Slot& s = slots_[static_cast<std::size_t>(seq) & mask_];
    if (s.seq.load(std::memory_order_acquire) != seq) return false;
    utime = s.utime.load(std::memory_order_relaxed);
    return s.seq.load(std::memory_order_acquire) == seq;
  }
  std::size_t size() const { return mask_ + 1; }

 private:
  struct Slot {
    std::atomic<std::int64_t> seq{-1};
    std::atomic<std::int64_t> utime{0};
  };
  std::unique_ptr<Slot[]> slots_;
  std::size_t mask_;
};

/// The paper's trapezoid trip (hoist::HoistProfile::trapezoid) down `travel`
/// and back up, repeated: the cage never rests (it reverses at each end).
class RoundTrip {
 public:
  RoundTrip(double l0, double travel, double vmax, double amax);
  Kinematics at(double t) const { return profile_.at(std::fmod(t, 2.0 * trip_)); }
  double tripTime() const { return trip_; }

 private:
  double trip_ = 0.0;
  HoistProfile profile_;
};

struct Feeder {
  const TimingTestOptions& o;
  lcm::LCM& lcm;
  const RoundTrip& trip;
  std::vector<std::string> channels;
  std::vector<Ring>& rings;
  std::unique_ptr<std::atomic<std::int64_t>[]> sent;
  std::vector<std::int64_t> failed;
  Histogram late;
  std::int64_t skipped = 0;
  std::atomic<bool> stop{false}, done{false};
  std::atomic<std::int64_t> last_utime{0};
  std::int64_t start_ns = 0, end_ns = 0;

  Feeder(const TimingTestOptions& opt, lcm::LCM& l, const RoundTrip& rt, std::vector<Ring>& r)
      : o(opt), lcm(l), trip(rt), rings(r), sent(new std::atomic<std::int64_t>[opt.prefixes.size()]),
        failed(opt.prefixes.size(), 0) {
    for (std::size_t i = 0; i < o.prefixes.size(); ++i) {
      channels.push_back(hoist::bus::channel(o.prefixes[i], hoist::bus::kChannelWinder));
      sent[i].store(0);
    }
  }

  /// Sleep until `deadline` (CLOCK_MONOTONIC ns), in slices of at most
  /// 100 ms so that a stop request is seen; false if stopped.
  bool sleepUntil(std::int64_t deadline);
  /// The feed: o.duration * o.rate inputs per shaft on the absolute
  /// schedule (its own thread); sets `done` at the end.
  void run();
};

}  // namespace hoist::replay
