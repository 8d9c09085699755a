// A sensor sample applied at its own time: see hoist/sensor_alignment.hpp.
#include "hoist/sensor_alignment.hpp"

#include <algorithm>

namespace hoist {

PredictionHistory::PredictionHistory(std::size_t capacity) : ring_(std::max<std::size_t>(capacity, 2)) {}

const SensorPrediction& PredictionHistory::get(std::size_t i) const {
  const std::size_t cap = ring_.size();
  return ring_[(head_ + cap - count_ + i) % cap];
}

double PredictionHistory::oldest() const { return count_ ? get(0).t : 0.0; }
double PredictionHistory::newest() const { return count_ ? get(count_ - 1).t : 0.0; }

void PredictionHistory::push(const SensorPrediction& p) {
  if (count_ > 0 && !(p.t > newest())) count_ = 0;  // time went back: a new stream
  ring_[head_] = p;
  head_ = (head_ + 1) % ring_.size();
  count_ = std::min(count_ + 1, ring_.size());
}

namespace {
SensorValues lerp(const SensorValues& a, const SensorValues& b, double u) {
  return {a.f_y + u * (b.f_y - a.f_y), a.omega + u * (b.omega - a.omega),
          a.rope_load + u * (b.rope_load - a.rope_load)};
}
}  // namespace

bool PredictionHistory::at(double ts, SensorPrediction& out) const {
  if (count_ == 0 || !(ts >= oldest()) || !(ts <= newest())) return false;
  if (ts == newest()) {  // the current step: exactly its prediction (no shift)
    out = get(count_ - 1);
    return true;
  }
  // Binary search for the last entry at or before ts.
  std::size_t lo = 0, hi = count_ - 1;
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    if (get(mid).t <= ts) lo = mid;
    else hi = mid;
  }
  const SensorPrediction& a = get(lo);
  if (count_ == 1 || ts <= a.t) {
    out = a;
    out.t = ts;
    return true;
  }
  const SensorPrediction& b = get(hi);
  const double u = (ts - a.t) / (b.t - a.t);
  out.t = ts;
  out.base = lerp(a.base, b.base, u);
  out.h = lerp(a.h, b.h, u);
  return true;
}

SensorValues alignToNow(const SensorValues& z, const SensorPrediction& then, const SensorPrediction& now, double dFa,
                        double dM) {
  SensorValues r;
  r.f_y = z.f_y + (now.base.f_y - then.base.f_y) + dM * (now.h.f_y - then.h.f_y);
  r.omega = z.omega + (now.base.omega - then.base.omega) + dM * (now.h.omega - then.h.omega);
  r.rope_load = z.rope_load + (now.base.rope_load - then.base.rope_load) + dFa * (now.h.rope_load - then.h.rope_load);
  return r;
}

}  // namespace hoist
