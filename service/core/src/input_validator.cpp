// Winder input validation: see hoist/service/input_validator.hpp.
#include "hoist/service/input_validator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "hoist/profile.hpp"

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
    case RejectReason::AccelMismatch: return "a_mismatch";
    case RejectReason::Implausible: return "implausible_state";
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
  if (!have_last_ && !continues(s)) return ok;
  if (s.seq <= last_.seq) return reject(RejectReason::DuplicateSeq);
  if (s.utime <= last_.utime) return reject(RejectReason::TimeBackwards);
  // Difference in double: utimes may be anything an attacker sends.
  const double dt = (static_cast<double>(s.utime) - static_cast<double>(last_.utime)) * 1e-6;
  if (dt > lim_.max_time_step) return reject(RejectReason::TimeJump);
  // v against a, accumulated since the consistency reference.
  const double total = dv_excess_ + excess(s, dt);
  const double since_ref = (static_cast<double>(s.utime) - static_cast<double>(ref_utime_)) * 1e-6;
  if (!(std::fabs(total) <= lim_.velocity_tolerance + lim_.accel_tolerance * since_ref))
    return reject(RejectReason::AccelMismatch);
  // The encoder length against the length integrated from v since the last
  // encoder length, whatever has_length did in between.
  if (s.has_length && have_lpred_) {
    const double predicted = integrateLength(l_pred_, last_.v, last_.a, s.v, s.a, dt);
    if (!(std::fabs(s.length - predicted) <= lim_.max_length_jump)) return reject(RejectReason::LengthJump);
  }
  // seq > last: the difference fits (both int64, s.seq > last_.seq).
  const auto gap = static_cast<std::uint64_t>(s.seq) - static_cast<std::uint64_t>(last_.seq);
  ok.skipped = gap > 1 ? static_cast<std::int64_t>(std::min<std::uint64_t>(gap - 1, INT64_MAX)) : 0;
  return ok;
}

double InputValidator::excess(const WinderSample& s, double dt) const {
  const double dv = s.v - last_.v;
  const double lo = std::min(last_.a, s.a) * dt, hi = std::max(last_.a, s.a) * dt;
  return dv - std::clamp(dv, lo, hi);
}

bool InputValidator::continues(const WinderSample& s) const {
  if (!soft_ || s.seq <= last_.seq || s.utime <= last_.utime) return false;
  const double dt = (static_cast<double>(s.utime) - static_cast<double>(last_.utime)) * 1e-6;
  return dt <= lim_.max_time_step;
}

void InputValidator::accept(const WinderSample& s) {
  if (have_last_ || continues(s)) {
    const double dt = (static_cast<double>(s.utime) - static_cast<double>(last_.utime)) * 1e-6;
    dv_excess_ += excess(s, dt);
    if (have_lpred_ && !s.has_length) l_pred_ = integrateLength(l_pred_, last_.v, last_.a, s.v, s.a, dt);
    if ((static_cast<double>(s.utime) - static_cast<double>(ref_utime_)) * 1e-6 >= lim_.consistency_window) {
      ref_utime_ = s.utime;
      dv_excess_ = 0.0;
    }
  } else {
    ref_utime_ = s.utime;
    dv_excess_ = 0.0;
    have_lpred_ = false;
  }
  soft_ = false;
  if (s.has_length) {
    l_pred_ = s.length;
    have_lpred_ = true;
  }
  last_ = s;
  have_last_ = true;
}

}  // namespace hoist::svc
