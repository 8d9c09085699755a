// Clearance alarms: see hoist/service/alarms.hpp.
#include "hoist/service/alarms.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hoist::svc {

void AlarmConfig::validate() const {
  auto bad = [](const char* key, const std::string& why) {
    throw std::invalid_argument(std::string("alarms.") + key + ": " + why);
  };
  auto positive = [&](const char* key, double v) {
    if (!std::isfinite(v) || !(v > 0.0)) bad(key, "must be a finite number > 0");
  };
  auto nonneg = [&](const char* key, double v) {
    if (!std::isfinite(v) || v < 0.0) bad(key, "must be a finite number >= 0");
  };
  positive("gap_pos_y", gap_pos_y);
  positive("gap_neg_y", gap_neg_y);
  positive("guide_rope_gap", guide_rope_gap);
  positive("warning_fraction", warning_fraction);
  positive("critical_fraction", critical_fraction);
  if (critical_fraction > 1.0) bad("critical_fraction", "must be <= 1 (a fraction of the gap)");
  if (!(warning_fraction < critical_fraction))
    bad("warning_fraction", "must be below critical_fraction");
  nonneg("deadband", deadband);
  if (!(deadband < warning_fraction)) bad("deadband", "must be below warning_fraction");
  nonneg("on_delay", on_delay);
  nonneg("off_delay", off_delay);
  nonneg("reannounce", reannounce);
  positive("max_shelve", max_shelve);
  positive("slack_fraction", slack_fraction);
  if (!(slack_fraction < 1.0))
    bad("slack_fraction", "must be below 1 (a fraction of the static rope force), got " + std::to_string(slack_fraction));
  positive("overload_fraction", overload_fraction);
  if (!(overload_fraction > 1.0) || overload_fraction > 100.0)
    bad("overload_fraction", "must be in (1, 100] (a multiple of the static rope force), got " +
                                 std::to_string(overload_fraction));
  nonneg("force_deadband", force_deadband);
  if (!(force_deadband < slack_fraction) || !(slack_fraction + force_deadband < 1.0))
    bad("force_deadband", "must be below slack_fraction and 1 - slack_fraction (else ROPE_SLACK could not clear "
                          "at the static force)");
  if (!(force_deadband < overload_fraction - 1.0))
    bad("force_deadband", "must be below overload_fraction - 1 (else ROPE_OVERLOAD could not clear at the static "
                          "force)");
}

// ---- BinaryAlarm -------------------------------------------------------------

void BinaryAlarm::configure(AlarmKind kind, AlarmLevel level, const AlarmSettings& s) {
  kind_ = kind;
  level_ = level;
  s_ = s;
  cond_ = active_ = acked_ = shelved_ = announced_ = pending_valid_ = false;
  pending_since_ = shelved_until_ = last_announce_ = value_ = 0.0;
  // A low alarm's "no value yet" must read as clear (poll() feeds value_ back).
  if (s.low) value_ = std::numeric_limits<double>::max();
}

void BinaryAlarm::emit(AlarmEventType type, double now, AlarmEvents& out) {
  AlarmEvent e;
  e.kind = kind_;
  e.level = level_;
  e.type = type;
  e.t = now;
  e.value = detail_ ? detail_value_ : value_;
  e.threshold = detail_ ? detail_limit_ : s_.threshold;
  e.active = active_;
  e.acked = acked_;
  e.shelved = shelved_;
  e.latched = latched();
  e.shelved_for = shelved_ ? std::max(0.0, shelved_until_ - now) : 0.0;
  out.push(e);
  if (type == AlarmEventType::Raise || type == AlarmEventType::Clear ||
      type == AlarmEventType::Reannounce) {
    announced_ = active_;
    last_announce_ = now;
  }
}

void BinaryAlarm::announce(double now, AlarmEvents& out) {
  if (shelved_ || active_ == announced_) return;
  emit(active_ ? AlarmEventType::Raise : AlarmEventType::Clear, now, out);
}

void BinaryAlarm::expireShelve(double now, AlarmEvents& out) {
  if (shelved_ && now >= shelved_until_) {
    shelved_ = false;
    emit(AlarmEventType::Unshelve, now, out);
    announce(now, out);
  }
}

void BinaryAlarm::update(double now, double value, AlarmEvents& out) {
  value_ = value;
  expireShelve(now, out);

  // Debounce: deadband below the threshold (above it for a low alarm),
  // then the on/off delay.
  const bool over = !std::isfinite(value) || (s_.low ? value <= s_.threshold : value >= s_.threshold);
  const bool under = std::isfinite(value) &&
                     (s_.low ? value > s_.threshold + s_.deadband : value < s_.threshold - s_.deadband);
  const bool want = cond_ ? !under : over;
  if (want != cond_) {
    if (!pending_valid_) {
      pending_valid_ = true;
      pending_since_ = now;
    }
    const double delay = want ? s_.on_delay : s_.off_delay;
    if (now - pending_since_ >= delay) {
      cond_ = want;
      pending_valid_ = false;
    }
  } else {
    pending_valid_ = false;
  }

  // Condition -> alarm state.
  if (cond_ && !active_) {
    active_ = true;
    acked_ = false;
  } else if (!cond_ && active_ && !(s_.latch && !acked_)) {
    active_ = false;
  }
  announce(now, out);

  if (active_ && !shelved_ && s_.reannounce > 0.0 && announced_ &&
      now - last_announce_ >= s_.reannounce)
    emit(AlarmEventType::Reannounce, now, out);
}

bool BinaryAlarm::acknowledge(double now, AlarmEvents& out) {
  expireShelve(now, out);
  if (!active_ || acked_) return false;
  acked_ = true;
  if (!cond_) active_ = false;  // a latched alarm whose condition is gone clears
  emit(AlarmEventType::Ack, now, out);
  announce(now, out);
  return true;
}

bool BinaryAlarm::shelve(double now, double duration, AlarmEvents& out) {
  if (!std::isfinite(duration) || !(duration > 0.0)) return false;
  // Not effective: already shelved until (about) the same time.
  if (shelved_ && std::fabs(now + duration - shelved_until_) < kReshelveResolution) return false;
  shelved_ = true;
  shelved_until_ = now + duration;
  emit(AlarmEventType::Shelve, now, out);
  return true;
}

bool BinaryAlarm::unshelve(double now, AlarmEvents& out) {
  if (!shelved_) return false;
  shelved_ = false;
  emit(AlarmEventType::Unshelve, now, out);
  announce(now, out);
  return true;
}

// ---- clearance ---------------------------------------------------------------

Clearance computeClearance(double y_c, double theta, double h, double guide_deflection,
                           const AlarmConfig& cfg) {
  Clearance c;
  c.y_top = y_c - h * theta;
  c.y_bottom = y_c + h * theta;
  c.excursion_pos = std::max(c.y_top, c.y_bottom);
  c.excursion_neg = std::max(-c.y_top, -c.y_bottom);
  c.guide_deflection = guide_deflection;
  c.clearance_pos = cfg.gap_pos_y - c.excursion_pos;
  c.clearance_neg = cfg.gap_neg_y - c.excursion_neg;
  c.clearance_guide = cfg.guide_rope_gap - guide_deflection;
  c.min_clearance = std::min({c.clearance_pos, c.clearance_neg, c.clearance_guide});
  return c;
}

// ---- AlarmEngine -------------------------------------------------------------

namespace {
// Slot layout: 0/1 CAGE_POS_Y W/C, 2/3 CAGE_NEG_Y W/C, 4/5 GUIDE_ROPE W/C,
// 6 INPUT_STALE W, 7 MODEL_FAULT C, 8 MODEL_DOMAIN C, 9 DUPLICATE_PUBLISHER W,
// 10 ROPE_SLACK C, 11 ROPE_OVERLOAD C, 12 PREDICTED_CLEARANCE W, 13 PREDICTED_SLACK W.
int slotOf(AlarmKind k, AlarmLevel l) {
  const int crit = l == AlarmLevel::Critical ? 1 : 0;
  switch (k) {
    case AlarmKind::CagePosY: return 0 + crit;
    case AlarmKind::CageNegY: return 2 + crit;
    case AlarmKind::GuideRope: return 4 + crit;
    case AlarmKind::InputStale: return l == AlarmLevel::Warning ? 6 : -1;
    case AlarmKind::ModelFault: return l == AlarmLevel::Critical ? 7 : -1;
    case AlarmKind::ModelDomain: return l == AlarmLevel::Critical ? 8 : -1;
    case AlarmKind::DuplicatePublisher: return l == AlarmLevel::Warning ? 9 : -1;
    case AlarmKind::RopeSlack: return l == AlarmLevel::Critical ? 10 : -1;
    case AlarmKind::RopeOverload: return l == AlarmLevel::Critical ? 11 : -1;
    case AlarmKind::PredictedClearance: return l == AlarmLevel::Warning ? 12 : -1;
    case AlarmKind::PredictedSlack: return l == AlarmLevel::Warning ? 13 : -1;
  }
  return -1;
}
}  // namespace

AlarmEngine::AlarmEngine(const AlarmConfig& cfg) : cfg_(cfg) {
  cfg_.validate();
  auto clearanceAlarm = [&](AlarmKind k, double gap) {
    AlarmSettings w;
    w.threshold = cfg_.warning_fraction * gap;
    w.deadband = cfg_.deadband * gap;
    w.on_delay = cfg_.on_delay;
    w.off_delay = cfg_.off_delay;
    w.reannounce = cfg_.reannounce;
    AlarmSettings c = w;
    c.threshold = cfg_.critical_fraction * gap;
    c.latch = cfg_.latch_critical;
    alarms_[slotOf(k, AlarmLevel::Warning)].configure(k, AlarmLevel::Warning, w);
    alarms_[slotOf(k, AlarmLevel::Critical)].configure(k, AlarmLevel::Critical, c);
  };
  clearanceAlarm(AlarmKind::CagePosY, cfg_.gap_pos_y);
  clearanceAlarm(AlarmKind::CageNegY, cfg_.gap_neg_y);
  clearanceAlarm(AlarmKind::GuideRope, cfg_.guide_rope_gap);
  AlarmSettings flag;
  flag.threshold = 0.5;
  flag.reannounce = cfg_.reannounce;
  alarms_[6].configure(AlarmKind::InputStale, AlarmLevel::Warning, flag);
  flag.latch = true;  // a model fault is an instant: keep it until acknowledged
  alarms_[7].configure(AlarmKind::ModelFault, AlarmLevel::Critical, flag);
  flag.latch = cfg_.latch_critical;
  alarms_[8].configure(AlarmKind::ModelDomain, AlarmLevel::Critical, flag);
  flag.latch = false;
  alarms_[9].configure(AlarmKind::DuplicatePublisher, AlarmLevel::Warning, flag);
  // Rope force: thresholds follow the static force (updateRopeForce); until
  // the first update they sit at the fractions of a unit force.
  AlarmSettings rope;
  rope.on_delay = cfg_.on_delay;
  rope.off_delay = cfg_.off_delay;
  rope.reannounce = cfg_.reannounce;
  rope.latch = cfg_.latch_critical;
  rope.low = true;
  rope.threshold = cfg_.slack_fraction;
  rope.deadband = cfg_.force_deadband;
  alarms_[10].configure(AlarmKind::RopeSlack, AlarmLevel::Critical, rope);
  rope.low = false;
  rope.threshold = cfg_.overload_fraction;
  alarms_[11].configure(AlarmKind::RopeOverload, AlarmLevel::Critical, rope);
  // Predictions: raised with the forecast that predicts (no on-delay),
  // cleared after off_delay without one, never latched.
  AlarmSettings pred = flag;
  pred.off_delay = cfg_.off_delay;
  alarms_[12].configure(AlarmKind::PredictedClearance, AlarmLevel::Warning, pred);
  alarms_[13].configure(AlarmKind::PredictedSlack, AlarmLevel::Warning, pred);
}

void AlarmEngine::updateRopeForce(double now, double lambda0, double static_force, AlarmEvents& out) {
  if (std::isfinite(static_force) && static_force > 0.0) {
    const double db = cfg_.force_deadband * static_force;
    alarms_[10].setThreshold(cfg_.slack_fraction * static_force, db);
    alarms_[11].setThreshold(cfg_.overload_fraction * static_force, db);
  }
  alarms_[10].update(now, lambda0, out);
  alarms_[11].update(now, lambda0, out);
}

double AlarmEngine::ropeSlackThreshold() const { return alarms_[10].settings().threshold; }
double AlarmEngine::ropeOverloadThreshold() const { return alarms_[11].settings().threshold; }

void AlarmEngine::updateClearance(double now, const Clearance& c, AlarmEvents& out) {
  for (int i = 0; i < 2; ++i) {
    alarms_[0 + i].update(now, c.excursion_pos, out);
    alarms_[2 + i].update(now, c.excursion_neg, out);
    alarms_[4 + i].update(now, c.guide_deflection, out);
  }
}

void AlarmEngine::setInputStale(double now, bool stale, AlarmEvents& out) {
  alarms_[6].update(now, stale ? 1.0 : 0.0, out);
}

void AlarmEngine::setModelFault(double now, bool fault, AlarmEvents& out) {
  alarms_[7].update(now, fault ? 1.0 : 0.0, out);
}

void AlarmEngine::setModelDomain(double now, bool outside, double l, double limit, AlarmEvents& out) {
  if (outside) alarms_[8].setDetail(l, limit);
  alarms_[8].update(now, outside ? 1.0 : 0.0, out);
}

void AlarmEngine::setDuplicatePublisher(double now, bool seen, double other_id, AlarmEvents& out) {
  if (seen) alarms_[9].setDetail(other_id, 0.0);
  alarms_[9].update(now, seen ? 1.0 : 0.0, out);
}

void AlarmEngine::setPredictedClearance(double now, bool predicted, double seconds, double horizon,
                                        AlarmEvents& out) {
  if (predicted) alarms_[12].setDetail(seconds, horizon);
  alarms_[12].update(now, predicted ? 1.0 : 0.0, out);
}

void AlarmEngine::setPredictedSlack(double now, bool predicted, double seconds, double horizon, AlarmEvents& out) {
  if (predicted) alarms_[13].setDetail(seconds, horizon);
  alarms_[13].update(now, predicted ? 1.0 : 0.0, out);
}

void AlarmEngine::poll(double now, AlarmEvents& out) {
  for (auto& a : alarms_) a.update(now, a.value(), out);
}

template <class F>
int AlarmEngine::forMatching(std::optional<AlarmKind> kind, AlarmLevel level, F&& f) {
  int n = 0;
  for (auto& a : alarms_) {
    if (kind && a.kind() != *kind) continue;
    if (level != AlarmLevel::None && a.level() != level) continue;
    if (f(a)) ++n;
  }
  return n;
}

int AlarmEngine::acknowledge(double now, std::optional<AlarmKind> kind, AlarmLevel level,
                             AlarmEvents& out) {
  return forMatching(kind, level, [&](BinaryAlarm& a) { return a.acknowledge(now, out); });
}

int AlarmEngine::shelve(double now, std::optional<AlarmKind> kind, AlarmLevel level,
                        double duration, AlarmEvents& out) {
  if (!std::isfinite(duration) || !(duration > 0.0)) return 0;
  duration = std::min(duration, cfg_.max_shelve);
  return forMatching(kind, level, [&](BinaryAlarm& a) { return a.shelve(now, duration, out); });
}

int AlarmEngine::unshelve(double now, std::optional<AlarmKind> kind, AlarmLevel level,
                          AlarmEvents& out) {
  return forMatching(kind, level, [&](BinaryAlarm& a) { return a.unshelve(now, out); });
}

AlarmLevel AlarmEngine::highestActive() const {
  AlarmLevel top = AlarmLevel::None;
  for (const auto& a : alarms_)
    if (a.active() && !a.shelved() && a.level() > top) top = a.level();
  return top;
}

int AlarmEngine::activeCount() const {
  return static_cast<int>(std::count_if(alarms_.begin(), alarms_.end(),
                                        [](const BinaryAlarm& a) { return a.active(); }));
}

int AlarmEngine::unackedCount() const {
  return static_cast<int>(std::count_if(alarms_.begin(), alarms_.end(), [](const BinaryAlarm& a) {
    return a.active() && !a.acked();
  }));
}

int AlarmEngine::shelvedCount() const {
  return static_cast<int>(std::count_if(alarms_.begin(), alarms_.end(),
                                        [](const BinaryAlarm& a) { return a.shelved(); }));
}

const BinaryAlarm* AlarmEngine::find(AlarmKind kind, AlarmLevel level) const {
  const int s = slotOf(kind, level);
  return s < 0 ? nullptr : &alarms_[s];
}

}  // namespace hoist::svc
