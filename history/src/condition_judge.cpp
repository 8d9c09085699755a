// The shaft's condition alarms over its trip records: see condition_judge.hpp.
#include "hoist/history/condition_judge.hpp"

#include <algorithm>

namespace hoist::history {

namespace {
void addOnce(std::vector<std::string>& alarms, const char* name) {
  if (std::find(alarms.begin(), alarms.end(), name) == alarms.end()) alarms.emplace_back(name);
}
}  // namespace

ConditionJudge::ConditionJudge(const ConditionSettings& cond) : trend_(cond), finger_(cond) {}

std::int64_t ConditionJudge::seed(Store& db, const std::string& shaft) {
  ListFilter f;
  f.shaft = shaft;
  f.with_bins = true;
  const auto old = db.list(f);
  const auto marks = db.baseline(shaft);
  for (const auto& r : old)
    if (std::binary_search(marks.begin(), marks.end(), r.trip)) finger_.markBaseline(r);
  for (const auto& r : old) add(r);
  return static_cast<std::int64_t>(old.size());
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
