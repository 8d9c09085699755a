// Winder input validation: see hoist/service/input_validator.hpp.
#include "hoist/service/input_validator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace hoist::svc {

const char* toString(RejectReason r) {
  switch (r) {
    case RejectReason::Decode: return "decode";
    case RejectReason::NonFinite: return "non_finite";
    case RejectReason::VelocityLimit: return "v_limit";
    case RejectReason::AccelLimit: return "a_limit";
    case RejectReason::DuplicateSeq: return "duplicate_seq";
    case RejectReason::TimeBackwards: return "time_backwards";
    case RejectReason::TimeJump: return "time_jump";
    case RejectReason::LengthRange: return "length_range";
    case RejectReason::LengthJump: return "length_jump";
    case RejectReason::ModelDomain: return "model_domain";
  }
  return "?";
}

Verdict InputValidator::check(const WinderSample& s) const {
  auto reject = [](RejectReason r) {
    Verdict v;
    v.ok = false;
    v.reason = r;
    return v;
  };
  if (!std::isfinite(s.v) || !std::isfinite(s.a) || (s.has_length && !std::isfinite(s.length)))
    return reject(RejectReason::NonFinite);
  if (std::fabs(s.v) > lim_.max_speed) return reject(RejectReason::VelocityLimit);
  if (std::fabs(s.a) > lim_.max_accel) return reject(RejectReason::AccelLimit);
  if (s.has_length && !(s.length > lim_.min_length && s.length < lim_.max_length))
    return reject(RejectReason::LengthRange);

  Verdict ok;
  if (!have_last_) return ok;
  if (s.seq <= last_.seq) return reject(RejectReason::DuplicateSeq);
  if (s.utime <= last_.utime) return reject(RejectReason::TimeBackwards);
  // Difference in double: utimes may be anything an attacker sends.
  const double dt = (static_cast<double>(s.utime) - static_cast<double>(last_.utime)) * 1e-6;
  if (dt > lim_.max_time_step) return reject(RejectReason::TimeJump);
  if (s.has_length && last_.has_length) {
    const double predicted = last_.length + 0.5 * (last_.v + s.v) * dt;
    if (std::fabs(s.length - predicted) > lim_.max_length_jump)
      return reject(RejectReason::LengthJump);
  }
  // seq > last: the difference fits (both int64, s.seq > last_.seq).
  const auto gap = static_cast<std::uint64_t>(s.seq) - static_cast<std::uint64_t>(last_.seq);
  ok.skipped = gap > 1 ? static_cast<std::int64_t>(std::min<std::uint64_t>(gap - 1, INT64_MAX)) : 0;
  return ok;
}

void InputValidator::accept(const WinderSample& s) {
  last_ = s;
  have_last_ = true;
}

}  // namespace hoist::svc
