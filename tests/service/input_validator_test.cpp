// Winder input validation (service/input_validator.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "hoist/service/core/input_validator.hpp"
#include "hoist/service/core/sensor_sequence.hpp"

using namespace hoist::service;

namespace {

InputLimits limits() {
  InputLimits l;
  l.max_speed = 10.0;
  l.max_accel = 2.0;
  l.max_length_jump = 0.5;
  l.max_time_step = 1.0;
  l.max_length = 384.0;
  return l;
}

WinderSample sample(std::int64_t seq, double t, double v = 5.0, double a = 0.0) {
  WinderSample s;
  s.seq = seq;
  s.utime = 1'700'000'000'000'000 + static_cast<std::int64_t>(std::llround(t * 1e6));
  s.v = v;
  s.a = a;
  return s;
}

WinderSample withLength(WinderSample s, double l) {
  s.has_length = true;
  s.length = l;
  return s;
}

}  // namespace

TEST(InputValidator, AcceptsAValidStream) {
  InputValidator v(limits());
  for (int k = 0; k < 10; ++k) {
    const auto s = withLength(sample(k, 0.01 * k), 50.0 + 0.05 * k);
    const Verdict r = v.check(s);
    ASSERT_TRUE(r.ok) << k;
    EXPECT_EQ(r.skipped, 0);
    v.accept(s);
  }
}

TEST(InputValidator, RejectsNonFinite) {
  InputValidator v(limits());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(v.check(sample(0, 0, nan)).reason, RejectReason::NonFinite);
  EXPECT_EQ(v.check(sample(0, 0, 1.0, inf)).reason, RejectReason::NonFinite);
  EXPECT_EQ(v.check(withLength(sample(0, 0), nan)).reason, RejectReason::NonFinite);
  // A NaN length without has_length is ignored.
  auto s = sample(0, 0);
  s.length = nan;
  EXPECT_TRUE(v.check(s).ok);
}

TEST(InputValidator, RejectsOutOfLimits) {
  InputValidator v(limits());
  EXPECT_EQ(v.check(sample(0, 0, 10.5)).reason, RejectReason::VelocityLimit);
  EXPECT_EQ(v.check(sample(0, 0, -10.5)).reason, RejectReason::VelocityLimit);
  EXPECT_TRUE(v.check(sample(0, 0, -10.0)).ok);
  EXPECT_EQ(v.check(sample(0, 0, 1.0, 2.5)).reason, RejectReason::AccelLimit);
  EXPECT_EQ(v.check(withLength(sample(0, 0), 0.0)).reason, RejectReason::LengthRange);
  EXPECT_EQ(v.check(withLength(sample(0, 0), -3.0)).reason, RejectReason::LengthRange);
  EXPECT_EQ(v.check(withLength(sample(0, 0), 384.0)).reason, RejectReason::LengthRange);
  EXPECT_TRUE(v.check(withLength(sample(0, 0), 383.9)).ok);
}

TEST(InputValidator, SequenceNumbers) {
  InputValidator v(limits());
  v.accept(sample(5, 0.0));
  EXPECT_EQ(v.check(sample(5, 0.01)).reason, RejectReason::DuplicateSeq);
  EXPECT_EQ(v.check(sample(4, 0.01)).reason, RejectReason::DuplicateSeq);
  const Verdict r = v.check(sample(9, 0.01));  // 6, 7, 8 lost: accepted, counted
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.skipped, 3);
}

TEST(InputValidator, Time) {
  InputValidator v(limits());
  v.accept(sample(0, 1.0));
  EXPECT_EQ(v.check(sample(1, 1.0)).reason, RejectReason::TimeBackwards);
  EXPECT_EQ(v.check(sample(1, 0.5)).reason, RejectReason::TimeBackwards);
  EXPECT_EQ(v.check(sample(1, 2.5)).reason, RejectReason::TimeJump);
  EXPECT_TRUE(v.check(sample(1, 1.5)).ok);
  // Extreme utimes must not overflow anything.
  auto s = sample(1, 0);
  s.utime = std::numeric_limits<std::int64_t>::max();
  EXPECT_EQ(v.check(s).reason, RejectReason::TimeJump);
  s.utime = std::numeric_limits<std::int64_t>::min();
  EXPECT_EQ(v.check(s).reason, RejectReason::TimeBackwards);
  s = sample(std::numeric_limits<std::int64_t>::max(), 1.01);
  EXPECT_TRUE(v.check(s).ok);
}

TEST(InputValidator, AForgedSampleFarAheadCostsTheGenuineStreamAtMostOneSample) {
  // Issue 33: one forged winder sample 0.9 s ahead (utime and seq) cost the
  // genuine stream 0.3-0.4 s (every sample up to its utime was
  // time_backwards).  Now the next genuine sample replaces it.
  for (const std::int64_t forged_seq : {std::int64_t{11}, std::int64_t{100000}}) {
    InputValidator v(limits());
    int accepted = 0, rejected = 0;
    auto feed = [&](const WinderSample& s) {
      const Verdict r = v.check(s);
      if (r.ok) {
        v.accept(s);
        ++accepted;
      } else {
        ++rejected;
      }
      return r;
    };
    for (int k = 0; k <= 10; ++k) ASSERT_TRUE(feed(sample(k, 0.01 * k)).ok);
    ASSERT_TRUE(feed(sample(forged_seq, 0.10 + 0.9)).ok) << "consistent and within max_time_step: accepted";
    accepted = rejected = 0;
    const Verdict r = feed(sample(11, 0.11));
    EXPECT_TRUE(r.ok) << "seq " << forged_seq;
    EXPECT_TRUE(r.replaces_last);
    for (int k = 12; k < 100; ++k) EXPECT_TRUE(feed(sample(k, 0.01 * k)).ok) << k;
    EXPECT_EQ(rejected, 0);
    EXPECT_EQ(v.replaced(), 1);
    EXPECT_EQ(v.last().seq, 99);
  }
}

TEST(InputValidator, DuplicatesAndReplaysAreStillRejected) {
  InputValidator v(limits());
  for (int k = 0; k <= 10; ++k) v.accept(sample(k, 0.01 * k));
  // The last sample again, and an older one: no replacement.
  EXPECT_EQ(v.check(sample(10, 0.10)).reason, RejectReason::DuplicateSeq);
  EXPECT_EQ(v.check(sample(9, 0.09)).reason, RejectReason::DuplicateSeq);
  EXPECT_EQ(v.check(sample(8, 0.095)).reason, RejectReason::DuplicateSeq);
  // A sample between the last two, but inconsistent with the one before: rejected.
  v.accept(sample(11, 0.9));
  EXPECT_FALSE(v.check(sample(11, 0.2, 9.0)).ok);
  // Only one step back: after two samples ahead the stream is theirs.
  v.accept(sample(12, 0.91));
  EXPECT_FALSE(v.check(sample(11, 0.11)).ok);
}

TEST(InputValidator, LengthJumpAgainstTheSpeedPrediction) {
  InputValidator v(limits());
  v.accept(withLength(sample(0, 0.0, 5.0), 100.0));
  // After 0.1 s at 5 m/s the length should be 100.5 m.
  EXPECT_TRUE(v.check(withLength(sample(1, 0.1, 5.0), 100.5)).ok);
  EXPECT_TRUE(v.check(withLength(sample(1, 0.1, 5.0), 100.9)).ok);
  EXPECT_EQ(v.check(withLength(sample(1, 0.1, 5.0), 101.1)).reason, RejectReason::LengthJump);
  EXPECT_EQ(v.check(withLength(sample(1, 0.1, 5.0), 99.9)).reason, RejectReason::LengthJump);
}

TEST(InputValidator, ResyncStartsANewStream) {
  InputValidator v(limits());
  v.accept(withLength(sample(1000, 100.0), 300.0));
  const auto restarted = withLength(sample(0, 0.0), 50.0);
  EXPECT_FALSE(v.check(restarted).ok);
  v.resync();
  EXPECT_TRUE(v.check(restarted).ok);
}

TEST(InputCounters, CountByReason) {
  InputCounters c;
  c.reject(RejectReason::Decode);
  c.reject(RejectReason::Decode);
  c.reject(RejectReason::LengthJump);
  EXPECT_EQ(c.count(RejectReason::Decode), 2);
  EXPECT_EQ(c.rejectedTotal(), 3);
  EXPECT_STREQ(toString(RejectReason::LengthJump), "length_jump");
}

// A sensor channel's sequence (HOIST_CAGE_IMU, HOIST_ROPE_LOAD): old samples
// are rejected; a sender that restarts (a jump back of kRestartJump or more)
// is followed at once; one forged sample far ahead costs the genuine sender
// at most kResyncAfter - 1 samples, not the whole gap.
TEST(SensorSequence, NegativeSequenceNumbersAreHandledLikePositiveOnes) {
  // Issue 33: a negative seq disabled the rule (last < 0 meant "none yet"),
  // so duplicates went through.
  using V = SensorSequence::Verdict;
  for (const std::int64_t base : {std::int64_t{-50}, std::int64_t{10}, INT64_MIN + 5, INT64_MAX - 20}) {
    SensorSequence s;
    EXPECT_EQ(s.next(base), V::Accept) << base;
    EXPECT_EQ(s.next(base + 1), V::Accept) << base;
    EXPECT_EQ(s.next(base + 1), V::Old) << "a repeat, base " << base;
    EXPECT_EQ(s.next(base), V::Old) << "a replayed sample, base " << base;
    EXPECT_EQ(s.next(base + 3), V::Accept) << base;
  }
  // Across zero, and a restart from far below.
  SensorSequence s;
  EXPECT_EQ(s.next(-2), V::Accept);
  EXPECT_EQ(s.next(-1), V::Accept);
  EXPECT_EQ(s.next(0), V::Accept);
  EXPECT_EQ(s.next(0), V::Old);
  EXPECT_EQ(s.next(-1), V::Old);
  EXPECT_EQ(s.next(INT64_MIN), V::Restart) << "far back: the sender restarted (no overflow)";
  EXPECT_EQ(s.next(INT64_MIN), V::Old);
}

TEST(SensorSequence, OldRejectedRestartFollowedForgeryBounded) {
  using V = SensorSequence::Verdict;
  SensorSequence s;
  EXPECT_EQ(s.next(10), V::Accept) << "the first sample";
  EXPECT_EQ(s.next(11), V::Accept);
  EXPECT_EQ(s.next(11), V::Old) << "a repeat";
  EXPECT_EQ(s.next(5), V::Old) << "a replayed sample";
  EXPECT_EQ(s.next(14), V::Accept) << "gaps are fine";
  EXPECT_EQ(s.next(0), V::Old);
  s = SensorSequence{};
  EXPECT_EQ(s.next(5000), V::Accept);
  EXPECT_EQ(s.next(3), V::Restart) << "the sender restarted";
  EXPECT_EQ(s.next(4), V::Accept);
  // One forged sample 500 ahead of the genuine stream (seq 5, 6, ...).
  EXPECT_EQ(s.next(504), V::Accept);
  int lost = 0;
  std::int64_t seq = 5;
  while (s.next(seq) == V::Old) {
    ++lost;
    ++seq;
    ASSERT_LT(lost, 100) << "the genuine sender stays locked out";
  }
  EXPECT_EQ(lost, SensorSequence::kResyncAfter - 1);
  EXPECT_EQ(s.last, seq);
  EXPECT_EQ(s.next(seq + 1), V::Accept) << "and is followed from then on";
  // Isolated old samples in a good stream do not add up to a resync.
  for (int i = 0; i < 3 * SensorSequence::kResyncAfter; ++i) {
    EXPECT_EQ(s.next(s.last - 1), V::Old);
    EXPECT_EQ(s.next(s.last + 1), V::Accept);
  }
}
