// hoist/rt/token_bucket.hpp -- the one token bucket: `rate` tokens a second,
// at most `burst` of them; each admitted event takes one.
//
// Pure: no I/O, no clock of its own (the caller passes the time, in seconds
// of any monotonic clock), no allocation; not thread-safe (one owner).  A
// bucket starts full at its first take().  Used by hoist-mqtt's command gate
// (per identity and per shaft) and its command results, and by hoist-dash's
// per-client command rate and per-peer connection rate.
#pragma once

#include <algorithm>

namespace hoist::rt {

class TokenBucket {
 public:
  /// `rate` > 0 tokens per second, `burst` >= 1 tokens at most.
  TokenBucket(double rate, double burst) : rate_(rate), burst_(burst) {}

  /// Takes one token at time `now` [s] if there is one; false (and nothing
  /// taken) otherwise.  A time before the last one counts as no time passed.
  bool take(double now) {
    refill(now);
    if (tokens_ < 1.0) return false;
    tokens_ -= 1.0;
    return true;
  }

  /// True if the bucket would be full at `now` (an idle user: may be forgotten).
  bool full(double now) const { return !started_ || level(now) >= burst_; }

  /// Tokens available at `now`, without taking any.
  double level(double now) const {
    if (!started_) return burst_;
    return std::min(burst_, tokens_ + std::max(0.0, now - last_) * rate_);
  }

  double rate() const { return rate_; }
  double burst() const { return burst_; }

 private:
  void refill(double now) {
    tokens_ = level(now);
    if (!started_ || now > last_) last_ = now;
    started_ = true;
  }

  double rate_, burst_;
  double tokens_ = 0.0;
  double last_ = 0.0;
  bool started_ = false;
};

}  // namespace hoist::rt
