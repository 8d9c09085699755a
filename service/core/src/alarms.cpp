// Clearance alarms: see hoist/service/core/alarms.hpp.
#include "hoist/service/core/alarms.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hoist::service::inline core {

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
  cond_ = active_ = acked_ = shelved_ = announced_ = pending_valid_ = touched_ = raised_ = false;
  pending_since_ = shelved_until_ = last_announce_ = value_ = 0.0;
  // A low alarm's "no value yet" must read as clear (poll() feeds value_ back).
  if (s.low) value_ = std::numeric_limits<double>::max();
}

AlarmEvent BinaryAlarm::event(AlarmEventType type, double now) const {
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
  return e;
}

void BinaryAlarm::emit(AlarmEventType type, double now, AlarmEvents& out) {
  out.push(event(type, now));
  touched_ = true;
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
    raised_ = true;
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
  // Active and unacknowledged, or returned to normal unacknowledged (ISA-18.2
  // RTN UNACK: the row stays listed until this acknowledgement).
  if (acked_ || !(active_ || raised_)) return false;
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

/// How a slot's settings follow from the [alarms] section.
enum class Rule : std::uint8_t {
  Clearance,    ///< excursion against warning_/critical_fraction x its gap, deadband x gap, on/off delay;
                ///< the CRITICAL one latches with latch_critical
  Flag,         ///< a 0/1 condition (threshold 0.5), no delays, never latched
  FaultFlag,    ///< a flag that always latches (a model fault is an instant)
  LatchedFlag,  ///< a flag that latches with latch_critical
  RopeLow,      ///< lambda_0 at or below slack_fraction x the static force (low alarm), force_deadband
  RopeHigh,     ///< lambda_0 at or above overload_fraction x the static force, force_deadband
  Prediction,   ///< a flag raised at once with the forecast, cleared after off_delay, never latched
};

/// One binary alarm of the engine; its slot is its row.
struct SlotRow {
  AlarmKind kind;
  AlarmLevel level;
  Rule rule;
  double AlarmConfig::*gap;  ///< Rule::Clearance: the gap it is a fraction of; else nullptr
};

/// The alarm slots: the one place that says which (kind, level) alarms exist,
/// in the order of AlarmEngine::alarms().  A new alarm is one row here (and
/// its kind in hoist/contract/alarm_vocabulary.hpp, its setter below).
constexpr std::array<SlotRow, AlarmEngine::kSlots> kSlotTable{{
    {AlarmKind::CagePosY, AlarmLevel::Warning, Rule::Clearance, &AlarmConfig::gap_pos_y},
    {AlarmKind::CagePosY, AlarmLevel::Critical, Rule::Clearance, &AlarmConfig::gap_pos_y},
    {AlarmKind::CageNegY, AlarmLevel::Warning, Rule::Clearance, &AlarmConfig::gap_neg_y},
    {AlarmKind::CageNegY, AlarmLevel::Critical, Rule::Clearance, &AlarmConfig::gap_neg_y},
    {AlarmKind::GuideRope, AlarmLevel::Warning, Rule::Clearance, &AlarmConfig::guide_rope_gap},
    {AlarmKind::GuideRope, AlarmLevel::Critical, Rule::Clearance, &AlarmConfig::guide_rope_gap},
    {AlarmKind::InputStale, AlarmLevel::Warning, Rule::Flag, nullptr},
    {AlarmKind::ModelFault, AlarmLevel::Critical, Rule::FaultFlag, nullptr},
    {AlarmKind::ModelDomain, AlarmLevel::Critical, Rule::LatchedFlag, nullptr},
    {AlarmKind::DuplicatePublisher, AlarmLevel::Warning, Rule::Flag, nullptr},
    {AlarmKind::RopeSlack, AlarmLevel::Critical, Rule::RopeLow, nullptr},
    {AlarmKind::RopeOverload, AlarmLevel::Critical, Rule::RopeHigh, nullptr},
    {AlarmKind::PredictedClearance, AlarmLevel::Warning, Rule::Prediction, nullptr},
    {AlarmKind::PredictedSlack, AlarmLevel::Warning, Rule::Prediction, nullptr},
    {AlarmKind::ModelMismatch, AlarmLevel::Warning, Rule::Flag, nullptr},
    {AlarmKind::SensorFault, AlarmLevel::Warning, Rule::Flag, nullptr},
    {AlarmKind::GuidePreloadLow, AlarmLevel::Warning, Rule::Flag, nullptr},
    {AlarmKind::GuidePreloadLow, AlarmLevel::Critical, Rule::LatchedFlag, nullptr},
    {AlarmKind::ShaftFingerprint, AlarmLevel::Warning, Rule::Flag, nullptr},
}};

/// The slot of (kind, level), or -1 if there is no such alarm.
constexpr int slotOf(AlarmKind k, AlarmLevel l) {
  for (std::size_t i = 0; i < kSlotTable.size(); ++i)
    if (kSlotTable[i].kind == k && kSlotTable[i].level == l) return static_cast<int>(i);
  return -1;
}

/// The table is whole: every kind has an alarm, no (kind, level) twice, a
/// gap exactly for the clearance rows.
constexpr bool slotTableIsWhole() {
  for (int k = 0; k < kAlarmKinds; ++k) {
    const auto kind = static_cast<AlarmKind>(k);
    if (slotOf(kind, AlarmLevel::Warning) < 0 && slotOf(kind, AlarmLevel::Critical) < 0) return false;
  }
  for (std::size_t i = 0; i < kSlotTable.size(); ++i) {
    if (slotOf(kSlotTable[i].kind, kSlotTable[i].level) != static_cast<int>(i)) return false;
    if (kSlotTable[i].level == AlarmLevel::None) return false;
    if ((kSlotTable[i].rule == Rule::Clearance) != (kSlotTable[i].gap != nullptr)) return false;
  }
  return true;
}
static_assert(slotTableIsWhole(), "kSlotTable: every alarm kind once per level, a gap exactly for clearance rows");

/// The slot of an alarm the engine sets by name (checked at compile time).
constexpr int slot(AlarmKind k, AlarmLevel l) {
  const int s = slotOf(k, l);
  return s >= 0 ? s : throw "no such alarm in kSlotTable";
}
constexpr int kInputStale = slot(AlarmKind::InputStale, AlarmLevel::Warning);
constexpr int kModelFault = slot(AlarmKind::ModelFault, AlarmLevel::Critical);
constexpr int kModelDomain = slot(AlarmKind::ModelDomain, AlarmLevel::Critical);
constexpr int kDuplicatePublisher = slot(AlarmKind::DuplicatePublisher, AlarmLevel::Warning);
constexpr int kRopeSlack = slot(AlarmKind::RopeSlack, AlarmLevel::Critical);
constexpr int kRopeOverload = slot(AlarmKind::RopeOverload, AlarmLevel::Critical);
constexpr int kPredictedClearance = slot(AlarmKind::PredictedClearance, AlarmLevel::Warning);
constexpr int kPredictedSlack = slot(AlarmKind::PredictedSlack, AlarmLevel::Warning);
constexpr int kModelMismatch = slot(AlarmKind::ModelMismatch, AlarmLevel::Warning);
constexpr int kSensorFault = slot(AlarmKind::SensorFault, AlarmLevel::Warning);
constexpr int kPreloadLowWarning = slot(AlarmKind::GuidePreloadLow, AlarmLevel::Warning);
constexpr int kPreloadLowCritical = slot(AlarmKind::GuidePreloadLow, AlarmLevel::Critical);
constexpr int kShaftFingerprint = slot(AlarmKind::ShaftFingerprint, AlarmLevel::Warning);

/// The settings of `row` under `cfg`.
AlarmSettings settingsOf(const SlotRow& row, const AlarmConfig& cfg) {
  AlarmSettings s;
  s.reannounce = cfg.reannounce;
  switch (row.rule) {
    case Rule::Clearance: {
      const double gap = cfg.*row.gap;
      const bool critical = row.level == AlarmLevel::Critical;
      s.threshold = (critical ? cfg.critical_fraction : cfg.warning_fraction) * gap;
      s.deadband = cfg.deadband * gap;
      s.on_delay = cfg.on_delay;
      s.off_delay = cfg.off_delay;
      s.latch = critical && cfg.latch_critical;
      break;
    }
    case Rule::Flag: s.threshold = 0.5; break;
    case Rule::FaultFlag:
      s.threshold = 0.5;
      s.latch = true;
      break;
    case Rule::LatchedFlag:
      s.threshold = 0.5;
      s.latch = cfg.latch_critical;
      break;
    case Rule::RopeLow:
    case Rule::RopeHigh:
      // Thresholds follow the static force (updateRopeForce); until the
      // first update they sit at the fractions of a unit force.
      s.on_delay = cfg.on_delay;
      s.off_delay = cfg.off_delay;
      s.latch = cfg.latch_critical;
      s.low = row.rule == Rule::RopeLow;
      s.threshold = s.low ? cfg.slack_fraction : cfg.overload_fraction;
      s.deadband = cfg.force_deadband;
      break;
    case Rule::Prediction:
      // Raised with the forecast that predicts (no on-delay), cleared after
      // off_delay without one, never latched.
      s.threshold = 0.5;
      s.off_delay = cfg.off_delay;
      break;
  }
  return s;
}

}  // namespace

AlarmEngine::AlarmEngine(const AlarmConfig& cfg) : cfg_(cfg) {
  cfg_.validate();
  for (std::size_t i = 0; i < kSlotTable.size(); ++i)
    alarms_[i].configure(kSlotTable[i].kind, kSlotTable[i].level, settingsOf(kSlotTable[i], cfg_));
}

void AlarmEngine::setModelFaultDetail(double value, double limit) { alarms_[kModelFault].setDetail(value, limit); }

void AlarmEngine::updateRopeForce(double now, double lambda0, double static_force, AlarmEvents& out) {
  updateRopeForce(now, lambda0, lambda0, static_force, out);
}

void AlarmEngine::updateRopeForce(double now, double lambda0_slack, double lambda0_overload, double static_force,
                                  AlarmEvents& out) {
  if (std::isfinite(static_force) && static_force > 0.0) {
    const double db = cfg_.force_deadband * static_force;
    alarms_[kRopeSlack].setThreshold(cfg_.slack_fraction * static_force, db);
    alarms_[kRopeOverload].setThreshold(cfg_.overload_fraction * static_force, db);
  }
  alarms_[kRopeSlack].update(now, lambda0_slack, out);
  alarms_[kRopeOverload].update(now, lambda0_overload, out);
}

double AlarmEngine::ropeSlackThreshold() const { return alarms_[kRopeSlack].settings().threshold; }
double AlarmEngine::ropeOverloadThreshold() const { return alarms_[kRopeOverload].settings().threshold; }

void AlarmEngine::updateClearance(double now, const Clearance& c, AlarmEvents& out) {
  // The WARNING alarms first, then the CRITICAL ones (the order of their events).
  for (const AlarmLevel level : {AlarmLevel::Warning, AlarmLevel::Critical})
    for (std::size_t i = 0; i < kSlotTable.size(); ++i) {
      const SlotRow& row = kSlotTable[i];
      if (row.rule != Rule::Clearance || row.level != level) continue;
      const double value = row.kind == AlarmKind::CagePosY   ? c.excursion_pos
                           : row.kind == AlarmKind::CageNegY ? c.excursion_neg
                                                             : c.guide_deflection;
      alarms_[i].update(now, value, out);
    }
}

void AlarmEngine::setInputStale(double now, bool stale, AlarmEvents& out) {
  alarms_[kInputStale].update(now, stale ? 1.0 : 0.0, out);
}

void AlarmEngine::setModelFault(double now, bool fault, AlarmEvents& out) {
  alarms_[kModelFault].update(now, fault ? 1.0 : 0.0, out);
}

void AlarmEngine::setModelDomain(double now, bool outside, double l, double limit, AlarmEvents& out) {
  if (outside) alarms_[kModelDomain].setDetail(l, limit);
  alarms_[kModelDomain].update(now, outside ? 1.0 : 0.0, out);
}

void AlarmEngine::setDuplicatePublisher(double now, bool seen, double other_id, AlarmEvents& out) {
  if (seen) alarms_[kDuplicatePublisher].setDetail(other_id, 0.0);
  alarms_[kDuplicatePublisher].update(now, seen ? 1.0 : 0.0, out);
}

void AlarmEngine::setPredictedClearance(double now, bool predicted, double seconds, double horizon,
                                        AlarmEvents& out) {
  if (predicted) alarms_[kPredictedClearance].setDetail(seconds, horizon);
  alarms_[kPredictedClearance].update(now, predicted ? 1.0 : 0.0, out);
}

void AlarmEngine::setPredictedSlack(double now, bool predicted, double seconds, double horizon, AlarmEvents& out) {
  if (predicted) alarms_[kPredictedSlack].setDetail(seconds, horizon);
  alarms_[kPredictedSlack].update(now, predicted ? 1.0 : 0.0, out);
}

void AlarmEngine::setModelMismatch(double now, bool mismatch, double statistic, double bound, AlarmEvents& out) {
  if (mismatch) alarms_[kModelMismatch].setDetail(statistic, bound);
  alarms_[kModelMismatch].update(now, mismatch ? 1.0 : 0.0, out);
}

void AlarmEngine::setSensorFault(double now, bool fault, double value, double limit, AlarmEvents& out) {
  if (fault) alarms_[kSensorFault].setDetail(value, limit);
  alarms_[kSensorFault].update(now, fault ? 1.0 : 0.0, out);
}

void AlarmEngine::setGuidePreloadLow(double now, AlarmLevel level, double upper95, double warning, double critical,
                                     AlarmEvents& out) {
  const bool warn = level != AlarmLevel::None;
  const bool crit = level == AlarmLevel::Critical;
  alarms_[kPreloadLowWarning].setDetail(upper95, warning);
  alarms_[kPreloadLowCritical].setDetail(upper95, critical);
  alarms_[kPreloadLowWarning].update(now, warn ? 1.0 : 0.0, out);
  alarms_[kPreloadLowCritical].update(now, crit ? 1.0 : 0.0, out);
}

void AlarmEngine::setShaftFingerprint(double now, bool active, double z, double limit, AlarmEvents& out) {
  alarms_[kShaftFingerprint].setDetail(z, limit);
  alarms_[kShaftFingerprint].update(now, active ? 1.0 : 0.0, out);
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

int AlarmEngine::reannounce(double now, std::optional<AlarmKind> kind, AlarmLevel level, AlarmEvents& out) {
  return forMatching(kind, level, [&](BinaryAlarm& a) {
    if (!a.hasState()) return false;
    a.reportState(now, out);
    return true;
  });
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

}  // namespace hoist::service::core
