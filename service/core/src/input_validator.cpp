// Winder input validation: see hoist/service/core/input_validator.hpp.
#include "hoist/service/core/input_validator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "hoist/profile.hpp"

namespace hoist::service::inline core {

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

Verdict InputValidator::checkAgainst(const Ref& r, const WinderSample& s) const {
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
  if (!r.have_last_ && !continues(r, s)) return ok;
  if (s.seq <= r.last_.seq) return reject(RejectReason::DuplicateSeq);
  if (s.utime <= r.last_.utime) return reject(RejectReason::TimeBackwards);
  // Difference in double: utimes may be anything an attacker sends.
  const double dt = (static_cast<double>(s.utime) - static_cast<double>(r.last_.utime)) * 1e-6;
  if (dt > lim_.max_time_step) return reject(RejectReason::TimeJump);
  // v against a, accumulated since the consistency reference.
  const double total = r.dv_excess_ + excess(r, s, dt);
  const double since_ref = (static_cast<double>(s.utime) - static_cast<double>(r.ref_utime_)) * 1e-6;
  if (!(std::fabs(total) <= lim_.velocity_tolerance + lim_.accel_tolerance * since_ref))
    return reject(RejectReason::AccelMismatch);
  // The encoder length against the length integrated from v since the last
  // encoder length, whatever has_length did in between.
  if (s.has_length && r.have_lpred_) {
    const double predicted = integrateLength(r.l_pred_, r.last_.v, r.last_.a, s.v, s.a, dt);
    if (!(std::fabs(s.length - predicted) <= lim_.max_length_jump)) return reject(RejectReason::LengthJump);
  }
  // seq > last: the difference fits (both int64, s.seq > r.last_.seq).
  const auto gap = static_cast<std::uint64_t>(s.seq) - static_cast<std::uint64_t>(r.last_.seq);
  ok.skipped = gap > 1 ? static_cast<std::int64_t>(std::min<std::uint64_t>(gap - 1, INT64_MAX)) : 0;
  return ok;
}

double InputValidator::excess(const Ref& r, const WinderSample& s, double dt) const {
  const double dv = s.v - r.last_.v;
  const double lo = std::min(r.last_.a, s.a) * dt, hi = std::max(r.last_.a, s.a) * dt;
  return dv - std::clamp(dv, lo, hi);
}

bool InputValidator::continues(const Ref& r, const WinderSample& s) const {
  if (!r.soft_ || s.seq <= r.last_.seq || s.utime <= r.last_.utime) return false;
  const double dt = (static_cast<double>(s.utime) - static_cast<double>(r.last_.utime)) * 1e-6;
  return dt <= lim_.max_time_step;
}

bool InputValidator::lastIsOutlierFor(const WinderSample& s) const {
  // s falls between the sample before the last and the last one: the last
  // one ran ahead of the stream (a forged or misordered sample).
  return have_prev_ && cur_.have_last_ && prev_.have_last_ && s.utime < cur_.last_.utime &&
         s.utime > prev_.last_.utime && s.seq > prev_.last_.seq;
}

Verdict InputValidator::check(const WinderSample& s) const {
  const Verdict v = checkAgainst(cur_, s);
  if (!v.ok && (v.reason == RejectReason::DuplicateSeq || v.reason == RejectReason::TimeBackwards) &&
      lastIsOutlierFor(s)) {
    Verdict w = checkAgainst(prev_, s);
    if (w.ok) {
      w.replaces_last = true;
      return w;
    }
  }
  return v;
}

void InputValidator::accept(const WinderSample& s) {
  // A sample that checked out against the one before the last replaces the
  // last (which ran ahead): the stream goes on from before it.
  if (lastIsOutlierFor(s) && (s.seq <= cur_.last_.seq || s.utime <= cur_.last_.utime)) {
    cur_ = prev_;
    ++replaced_;
  }
  prev_ = cur_;
  have_prev_ = cur_.have_last_;
  Ref& r = cur_;
  if (r.have_last_ || continues(r, s)) {
    const double dt = (static_cast<double>(s.utime) - static_cast<double>(r.last_.utime)) * 1e-6;
    r.dv_excess_ += excess(r, s, dt);
    if (r.have_lpred_ && !s.has_length) r.l_pred_ = integrateLength(r.l_pred_, r.last_.v, r.last_.a, s.v, s.a, dt);
    if ((static_cast<double>(s.utime) - static_cast<double>(r.ref_utime_)) * 1e-6 >= lim_.consistency_window) {
      r.ref_utime_ = s.utime;
      r.dv_excess_ = 0.0;
    }
  } else {
    r.ref_utime_ = s.utime;
    r.dv_excess_ = 0.0;
    r.have_lpred_ = false;
  }
  r.soft_ = false;
  if (s.has_length) {
    r.l_pred_ = s.length;
    r.have_lpred_ = true;
  }
  r.last_ = s;
  r.have_last_ = true;
}

}  // namespace hoist::service::core
