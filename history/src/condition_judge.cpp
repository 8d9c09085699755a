// The shaft's condition alarms over its trip records: see condition_judge.hpp.
#include "hoist/history/condition_judge.hpp"

#include <algorithm>

#include "hoist/history/judged_history.hpp"

namespace hoist::history {

namespace {
void addOnce(std::vector<std::string>& alarms, const char* name) {
  if (std::find(alarms.begin(), alarms.end(), name) == alarms.end()) alarms.emplace_back(name);
}
}  // namespace

ConditionJudge::ConditionJudge(const ConditionSettings& cond) : cond_(cond), trend_(cond), finger_(cond) {}

std::int64_t ConditionJudge::seed(Store& db, const std::string& shaft) {
  JudgedHistory h = readJudgedHistory(db, shaft, cond_);
  // The baseline before the window feeds the fingerprint only (the trend
  // forgets it: judged_history.hpp).
  primeFingerprint(h.baseline, h.trips, h.marks, finger_);
  for (const auto& r : h.trips) add(r);
  stored_last_ = h.last_trip;
  windowed_ = h.windowed;
  trips_ += static_cast<std::int64_t>(h.baseline.size());
  return static_cast<std::int64_t>(h.baseline.size() + h.trips.size());
}

void ConditionJudge::judge(TripRecord& r) {
  add(r);
  if (r.mismatch) addOnce(r.alarms, "MODEL_MISMATCH");
  if (trend_.decision().level != ConditionLevel::None) addOnce(r.alarms, "GUIDE_PRELOAD_LOW");
  if (finger_.decision().active) addOnce(r.alarms, "SHAFT_FINGERPRINT");
}

std::string ConditionJudge::summary() const {
  const auto d = trend_.decision();
  std::string s = d.text;
  const auto fd = finger_.decision();
  if (fd.active) s += (s.empty() ? "" : "; ") + fd.text;
  return s;
}

void ConditionJudge::add(const TripRecord& r) {
  trend_.add(r);
  finger_.add(r);
  ++trips_;
  last_trip_ = std::max(last_trip_, r.trip);
}

}  // namespace hoist::history
