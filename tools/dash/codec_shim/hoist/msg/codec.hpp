// TEMPORARY stand-in for branch `codec`'s hoist/msg/codec.hpp (target
// hoist_msgs_codec), used only while that target does not exist.  It has the
// same shape (checkedDecode, TypeInfo, allTypes, findByFingerprint, fromJson)
// so that hoist-dash compiles unchanged against the real one.  Remove this
// directory once hoist_msgs_codec is merged.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hoist/alarm_ack_t.hpp"
#include "hoist/alarm_t.hpp"
#include "hoist/cage_state_t.hpp"
#include "hoist/guide_shape_t.hpp"
#include "hoist/health_t.hpp"
#include "hoist/winder_t.hpp"

namespace hoist::msg {

enum class DecodeStatus { Ok, TooShort, WrongFingerprint, BadLength, Malformed };

inline const char* toString(DecodeStatus s) {
  switch (s) {
    case DecodeStatus::Ok: return "ok";
    case DecodeStatus::TooShort: return "too_short";
    case DecodeStatus::WrongFingerprint: return "wrong_fingerprint";
    case DecodeStatus::BadLength: return "bad_length";
    case DecodeStatus::Malformed: return "malformed";
  }
  return "?";
}

namespace shim {
// Bounds on variable-length fields before lcm-gen's decode allocates.
inline bool peekInt32At(const void* data, std::size_t size, std::size_t off, std::int32_t& v) {
  if (off + 4 > size) return false;
  const auto* p = static_cast<const unsigned char*>(data) + off;
  v = static_cast<std::int32_t>((std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) |
                                (std::uint32_t(p[2]) << 8) | std::uint32_t(p[3]));
  return true;
}
}  // namespace shim

template <class T>
DecodeStatus checkedDecode(const void* data, std::size_t size, T& out) {
  if (size < 8) return DecodeStatus::TooShort;
  std::int64_t fp = 0;
  const auto* p = static_cast<const unsigned char*>(data);
  for (int i = 0; i < 8; ++i) fp = (fp << 8) | p[i];
  if (fp != T::getHash()) return DecodeStatus::WrongFingerprint;
  if constexpr (std::is_same_v<T, guide_shape_t>) {
    std::int32_t n = 0;  // after fingerprint, utime, t, l, h
    if (!shim::peekInt32At(data, size, 8 + 32, n) || n < 0 || std::size_t(n) * 16 > size) return DecodeStatus::BadLength;
  }
  if constexpr (std::is_same_v<T, health_t>) {
    if (size > 65536) return DecodeStatus::BadLength;
  }
  if (out.decode(data, 0, static_cast<int>(size)) < 0) return DecodeStatus::Malformed;
  return DecodeStatus::Ok;
}

inline nlohmann::json toJson(const winder_t& m) {
  return {{"utime", m.utime}, {"seq", m.seq}, {"v", m.v}, {"a", m.a}, {"has_length", m.has_length != 0}, {"length", m.length}};
}
inline nlohmann::json toJson(const cage_state_t& m) {
  return {{"utime", m.utime}, {"seq", m.seq}, {"instance_id", m.instance_id}, {"input_seq", m.input_seq},
          {"t", m.t}, {"l", m.l}, {"v", m.v}, {"a", m.a}, {"x_c", m.x_c}, {"y_c", m.y_c}, {"theta", m.theta},
          {"lambdas", std::vector<double>(m.lambdas, m.lambdas + 5)}, {"y_top", m.y_top}, {"y_bottom", m.y_bottom},
          {"guide_deflection", m.guide_deflection}, {"clearance_pos_y", m.clearance_pos_y},
          {"clearance_neg_y", m.clearance_neg_y}, {"clearance_guide", m.clearance_guide},
          {"min_clearance", m.min_clearance}, {"alarm_level", m.alarm_level}, {"degraded", m.degraded != 0}};
}
inline nlohmann::json toJson(const guide_shape_t& m) {
  return {{"utime", m.utime}, {"t", m.t}, {"l", m.l}, {"h", m.h}, {"n", m.n}, {"x", m.x}, {"y1", m.y1}, {"y2", m.y2}};
}
inline nlohmann::json toJson(const alarm_t& m) {
  return {{"utime", m.utime}, {"id", m.id}, {"t", m.t}, {"kind", m.kind}, {"level", m.level},
          {"event_type", m.event_type}, {"active", m.active != 0}, {"acked", m.acked != 0}, {"shelved", m.shelved != 0},
          {"latched", m.latched != 0}, {"value", m.value}, {"threshold", m.threshold}, {"shelved_for", m.shelved_for},
          {"message", m.message}, {"user", m.user}};
}
inline nlohmann::json toJson(const alarm_ack_t& m) {
  return {{"utime", m.utime}, {"kind", m.kind}, {"level", m.level}, {"action", m.action},
          {"shelve_duration", m.shelve_duration}, {"user", m.user}};
}
inline nlohmann::json toJson(const health_t& m) {
  return {{"utime", m.utime}, {"instance_id", m.instance_id}, {"uptime", m.uptime}, {"t", m.t}, {"clock", m.clock},
          {"rate", m.rate}, {"window", m.window}, {"ticks", m.ticks}, {"steps", m.steps},
          {"deadline_misses", m.deadline_misses}, {"step_p50_us", m.step_p50_us}, {"step_p99_us", m.step_p99_us},
          {"step_max_us", m.step_max_us}, {"late_p50_us", m.late_p50_us}, {"late_p99_us", m.late_p99_us},
          {"late_max_us", m.late_max_us}, {"input_age", m.input_age}, {"accepted", m.accepted},
          {"seq_gaps", m.seq_gaps}, {"rejected_total", m.rejected_total}, {"n_reasons", m.n_reasons},
          {"reject_reason", m.reject_reason}, {"rejected", m.rejected}, {"alarms_active", m.alarms_active},
          {"alarms_unacked", m.alarms_unacked}, {"alarms_shelved", m.alarms_shelved},
          {"alarm_events", m.alarm_events}, {"model_faults", m.model_faults}, {"model_resets", m.model_resets},
          {"publish_failures", m.publish_failures}, {"nonfinite_blocked", m.nonfinite_blocked},
          {"degraded", m.degraded != 0}};
}

template <class T>
nlohmann::json jsonSchema() {
  // Shim: property names and JSON types only (the real codec documents units).
  T m{};
  const nlohmann::json j = toJson(m);
  nlohmann::json props = nlohmann::json::object();
  for (auto it = j.begin(); it != j.end(); ++it) {
    const auto& v = it.value();
    if (v.is_boolean()) props[it.key()] = {{"type", "boolean"}};
    else if (v.is_number_integer()) props[it.key()] = {{"type", "integer"}};
    else if (v.is_number()) props[it.key()] = {{"type", "number"}};
    else if (v.is_string()) props[it.key()] = {{"type", "string"}};
    else props[it.key()] = {{"type", "array"}};
  }
  return {{"type", "object"}, {"title", std::string("hoist.") + T::getTypeName()}, {"properties", props}};
}

struct TypeInfo {
  std::string name;          // "hoist.cage_state_t"
  std::int64_t fingerprint;  // T::getHash()
  nlohmann::json schema;     // JSON Schema
  bool (*bytesToJson)(const void* data, std::size_t size, nlohmann::json& out, DecodeStatus& status);
};

namespace shim {
template <class T>
bool bytesToJson(const void* data, std::size_t size, nlohmann::json& out, DecodeStatus& status) {
  T m{};
  status = checkedDecode(data, size, m);
  if (status != DecodeStatus::Ok) return false;
  out = toJson(m);
  return true;
}
template <class T>
TypeInfo info() {
  return TypeInfo{std::string("hoist.") + T::getTypeName(), T::getHash(), jsonSchema<T>(), &bytesToJson<T>};
}
}  // namespace shim

inline const std::vector<TypeInfo>& allTypes() {
  static const std::vector<TypeInfo> v{shim::info<alarm_ack_t>(), shim::info<alarm_t>(), shim::info<cage_state_t>(),
                                       shim::info<guide_shape_t>(), shim::info<health_t>(), shim::info<winder_t>()};
  return v;
}

inline const TypeInfo* findByFingerprint(const void* data, std::size_t size) {
  if (size < 8) return nullptr;
  std::int64_t fp = 0;
  const auto* p = static_cast<const unsigned char*>(data);
  for (int i = 0; i < 8; ++i) fp = (fp << 8) | p[i];
  for (const auto& t : allTypes())
    if (t.fingerprint == fp) return &t;
  return nullptr;
}

inline bool fromJson(const nlohmann::json& j, alarm_ack_t& out, std::string& error) {
  try {
    out = alarm_ack_t{};
    out.utime = j.value("utime", std::int64_t{0});
    out.kind = j.at("kind").get<std::string>();
    out.level = static_cast<std::int8_t>(j.value("level", 0));
    out.action = static_cast<std::int8_t>(j.at("action").get<int>());
    out.shelve_duration = j.value("shelve_duration", 0.0);
    out.user = j.value("user", std::string());
    return true;
  } catch (const std::exception& e) {
    error = e.what();
    return false;
  }
}

}  // namespace hoist::msg
