// TripRecord <-> JSON (hoist/history/record_json.hpp).
#include "hoist/history/record_json.hpp"

#include <stdexcept>

#include "hoist/history/schema.hpp"

namespace hoist::history {

namespace {

nlohmann::json toJson(const Value& v) {
  switch (v.kind) {
    case Kind::Real: return v.real;
    case Kind::Integer: return v.integer;
    case Kind::Boolean: return v.integer != 0;
    case Kind::Text: return v.text;
  }
  return nullptr;
}

Value fromJson(const nlohmann::json& j, Kind want, const std::string& name) {
  Value v;
  v.kind = want;
  if (want == Kind::Real && j.is_number()) v.real = j.get<double>();
  else if (want == Kind::Integer && j.is_number_integer()) v.integer = j.get<std::int64_t>();
  else if (want == Kind::Boolean && j.is_boolean()) v.integer = j.get<bool>() ? 1 : 0;
  else if (want == Kind::Text && j.is_string()) v.text = j.get<std::string>();
  else throw std::invalid_argument(name + ": wrong type (" + std::string(j.type_name()) + ")");
  if (auto e = valueError(name, want, v); !e.empty()) throw std::invalid_argument(name + ": " + e);
  return v;
}

const nlohmann::json& member(const nlohmann::json& j, std::string_view key, const std::string& where) {
  auto it = j.find(key);
  if (it == j.end()) throw std::invalid_argument(where + std::string(key) + ": missing");
  return *it;
}

}  // namespace

nlohmann::json recordToJson(const TripRecord& r) {
  nlohmann::json j = nlohmann::json::object();
  j["shaft"] = r.shaft;
  j["trip"] = r.trip;
  for (const auto& f : tripFields()) j[std::string(f.column)] = toJson(f.get(r));
  auto bins = nlohmann::json::array();
  for (const auto& b : r.bins) {
    nlohmann::json o = nlohmann::json::object();
    for (const auto& f : binFields()) o[std::string(f.column)] = toJson(f.get(b));
    bins.push_back(std::move(o));
  }
  j["bins"] = std::move(bins);
  return j;
}

TripRecord recordFromJson(const nlohmann::json& j) {
  if (!j.is_object()) throw std::invalid_argument("trip record: not a JSON object");
  TripRecord r;
  r.shaft = fromJson(member(j, "shaft", ""), Kind::Text, "shaft").text;
  r.trip = fromJson(member(j, "trip", ""), Kind::Integer, "trip").integer;
  for (const auto& f : tripFields()) {
    const std::string name(f.column);
    f.set(r, fromJson(member(j, name, ""), f.kind, name));
  }
  const auto& bins = member(j, "bins", "");
  if (!bins.is_array()) throw std::invalid_argument("bins: not an array");
  if (bins.size() > kMaxBins) throw std::invalid_argument("bins: more than " + std::to_string(kMaxBins));
  r.bins.resize(bins.size());
  for (std::size_t i = 0; i < bins.size(); ++i) {
    const std::string where = "bins[" + std::to_string(i) + "].";
    for (const auto& f : binFields())
      f.set(r.bins[i], fromJson(member(bins[i], f.column, where), f.kind, where + std::string(f.column)));
  }
  if (auto e = recordError(r); !e.empty()) throw std::invalid_argument(e);
  return r;
}

}  // namespace hoist::history
