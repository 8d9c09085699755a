// hoist/service/core/input_validator.hpp -- checks every winder input before it
// can reach the model (pure: no I/O, no clock, no allocation).
//
// A winder sample (winder_t) carries utime [us], seq, v [m/s], a [m/s^2] and
// optionally the encoder rope length [m] (docs/model.md: depth down, v > 0
// descending).  check() classifies one sample against the configured limits
// and the last ACCEPTED sample of the current stream; accept() makes it the
// reference.  A stream is restarted with resync() (after the input went
// stale): the next sample is then checked against the limits only, so a
// restarted winder gateway (new seq, new time base) is picked up again.
#pragma once

#include <array>
#include <cstdint>

namespace hoist::service::inline core {

/// Why an input was rejected.  Names (toString) appear in HOIST_HEALTH and logs.
enum class RejectReason : std::uint8_t {
  Decode,         ///< "decode": garbage, truncated, or wrong type fingerprint
  NonFinite,      ///< "non_finite": NaN or infinity in v, a or length
  VelocityLimit,  ///< "v_limit": |v| > max_speed
  AccelLimit,     ///< "a_limit": |a| > max_accel
  DuplicateSeq,   ///< "duplicate_seq": seq equal to or older than the last accepted
  TimeBackwards,  ///< "time_backwards": utime not after the last accepted utime
  TimeJump,       ///< "time_jump": utime more than max_time_step after the last accepted
  LengthRange,    ///< "length_range": encoder length outside the model's valid range [d, L - 2h - d]
  LengthJump,     ///< "length_jump": encoder length off the length integrated from v (across
                  ///< samples without a length too) by > max_length_jump
  ModelDomain,    ///< "model_domain": the kinematics (integrated from v) left the valid range
  AccelMismatch,  ///< "a_mismatch": v changed otherwise than the reported a allows (see InputLimits)
  Implausible,    ///< "implausible_state": a model output beyond the plausibility bound (MODEL_FAULT)
};
inline constexpr int kRejectReasons = 12;
const char* toString(RejectReason r);

/// One winder input, already decoded.
struct WinderSample {
  std::int64_t utime = 0;   ///< [us since the Unix epoch]
  std::int64_t seq = 0;
  double v = 0.0;           ///< [m/s]
  double a = 0.0;           ///< [m/s^2]
  bool has_length = false;
  double length = 0.0;      ///< encoder rope length [m], if has_length
};

struct InputLimits {
  double max_speed = 20.0;       ///< |v| limit [m/s]
  double max_accel = 10.0;       ///< |a| limit [m/s^2]
  double max_length_jump = 0.5;  ///< encoder length vs prediction [m]
  double max_time_step = 1.0;    ///< largest utime step within a stream [s]
  double min_length = 0.0;       ///< exclusive lower bound of l [m]
  double max_length = 384.0;     ///< exclusive upper bound of l (L - 2h) [m]
  /// Cross-sample consistency of v and a: over the samples since a reference
  /// (renewed every consistency_window s), the change of v beyond what the
  /// reported a allows (each interval: anything between dt min(a0, a1) and
  /// dt max(a0, a1), which covers an acceleration step anywhere inside it) must
  /// stay within velocity_tolerance + accel_tolerance x (t - t_ref).
  double accel_tolerance = 1.0;     ///< [m/s^2]
  double velocity_tolerance = 0.02; ///< [m/s]
  double consistency_window = 1.0;  ///< [s]
};

struct Verdict {
  bool ok = true;
  RejectReason reason = RejectReason::Decode;  ///< valid when !ok
  std::int64_t skipped = 0;  ///< sequence numbers missing before this sample (ok only)
  /// ok, checked against the sample before the last accepted one: the last
  /// one had run ahead of the stream (e.g. a forged sample far ahead of its
  /// peers) and accept() replaces it, so it costs the genuine stream at most
  /// one sample instead of everything up to its utime/seq.
  bool replaces_last = false;
};

class InputValidator {
 public:
  explicit InputValidator(const InputLimits& limits = {}) : lim_(limits) {}
  const InputLimits& limits() const { return lim_; }

  /// Classify `s`; does not change state.
  Verdict check(const WinderSample& s) const;
  /// Make `s` the reference for the following samples.
  void accept(const WinderSample& s);
  /// Forget the stream reference (next sample starts a new stream) -- unless
  /// the next sample continues the old one (sequence and utime after the
  /// last accepted sample, within max_time_step): then it is still checked
  /// for consistency against it, so rejected input going stale does not
  /// open the door to the same inconsistent stream.
  void resync() {
    cur_.have_last_ = false;
    cur_.soft_ = true;
    have_prev_ = false;
  }
  /// The rope length integrated from v since the last encoder length (valid
  /// when hasLengthPrediction()).
  bool hasLengthPrediction() const { return cur_.have_lpred_; }
  double lengthPrediction() const { return cur_.l_pred_; }
  bool hasReference() const { return cur_.have_last_; }
  const WinderSample& last() const { return cur_.last_; }
  /// Accepted samples that replaced a last one which had run ahead (Verdict::replaces_last).
  std::int64_t replaced() const { return replaced_; }

 private:
  /// The reference of the stream after one accepted sample.
  struct Ref {
    WinderSample last_;
    bool have_last_ = false;
    bool soft_ = false;  // resynced, last_ kept for a continuing stream
    // consistency reference
    std::int64_t ref_utime_ = 0;
    double dv_excess_ = 0.0;  // accumulated since ref_utime_ [m/s]
    bool have_lpred_ = false;
    double l_pred_ = 0.0;     // length integrated from v since the last encoder length [m]
  };
  Verdict checkAgainst(const Ref& r, const WinderSample& s) const;
  /// Excess of the v change over the a-allowed range for `s` after r.last_.
  double excess(const Ref& r, const WinderSample& s, double dt) const;
  /// After resync(): does `s` continue the old stream?
  bool continues(const Ref& r, const WinderSample& s) const;
  /// `s` lies between the sample before the last and the last one.
  bool lastIsOutlierFor(const WinderSample& s) const;

  InputLimits lim_;
  Ref cur_;   // after the last accepted sample
  Ref prev_;  // before it (valid when have_prev_)
  bool have_prev_ = false;
  std::int64_t replaced_ = 0;
};

/// Accepted/rejected counters by reason (plain integers, no allocation).
struct InputCounters {
  std::int64_t accepted = 0;
  std::int64_t seq_gaps = 0;
  std::array<std::int64_t, kRejectReasons> rejected{};
  void reject(RejectReason r) { ++rejected[static_cast<int>(r)]; }
  std::int64_t rejectedTotal() const {
    std::int64_t n = 0;
    for (auto v : rejected) n += v;
    return n;
  }
  std::int64_t count(RejectReason r) const { return rejected[static_cast<int>(r)]; }
};

}  // namespace hoist::service::core
