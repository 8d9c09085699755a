// The history schema's tables (hoist/history/schema.hpp).
#include "hoist/history/schema.hpp"

#include <cmath>
#include <stdexcept>

namespace hoist::history {

namespace {

Value real(double v) { return Value{Kind::Real, v, 0, {}}; }
Value integer(std::int64_t v) { return Value{Kind::Integer, 0.0, v, {}}; }
Value boolean(bool v) { return Value{Kind::Boolean, 0.0, v ? 1 : 0, {}}; }
Value text(std::string v) { return Value{Kind::Text, 0.0, 0, std::move(v)}; }

// One row per column: R (real), I (integer), B (boolean), T (text) of the
// member expression `m` of the record `r`.
#define HR(col, m) TripField{col, Kind::Real, 1, [](const TripRecord& r) { return real(r.m); }, \
                             [](TripRecord& r, const Value& v) { r.m = v.real; }}
#define HI(col, m) TripField{col, Kind::Integer, 1, [](const TripRecord& r) { return integer(r.m); }, \
                             [](TripRecord& r, const Value& v) { r.m = static_cast<decltype(r.m)>(v.integer); }}
#define HB(col, m) TripField{col, Kind::Boolean, 1, [](const TripRecord& r) { return boolean(r.m); }, \
                             [](TripRecord& r, const Value& v) { r.m = v.integer != 0; }}
#define HT(col, m) TripField{col, Kind::Text, 1, [](const TripRecord& r) { return text(r.m); }, \
                             [](TripRecord& r, const Value& v) { r.m = v.text; }}
#define BR(m) BinField{#m, Kind::Real, 1, [](const DepthBinStats& b) { return real(b.m); }, \
                       [](DepthBinStats& b, const Value& v) { b.m = v.real; }}

const std::vector<TripField>& tripTable() {
  static const std::vector<TripField> t = {
      HI("wall_start_us", wall_start_us), HI("wall_end_us", wall_end_us),
      HR("t_start", t_start), HR("t_end", t_end),
      TripField{"direction", Kind::Integer, 1,
                [](const TripRecord& r) { return integer(static_cast<int>(r.direction)); },
                [](TripRecord& r, const Value& v) {
                  r.direction = v.integer < 0 ? TripDirection::Up : TripDirection::Down;
                }},
      HR("depth_start", depth_start), HR("depth_end", depth_end),
      HR("peak_speed", peak_speed), HR("peak_accel", peak_accel),
      HR("fa_start", Fa_start), HR("sigma_fa_start", sigma_Fa_start),
      HR("fa_end", Fa_end), HR("sigma_fa_end", sigma_Fa_end),
      HR("moment_start", moment_start), HR("sigma_moment_start", sigma_moment_start),
      HR("moment_end", moment_end), HR("sigma_moment_end", sigma_moment_end),
      HR("b_start", b_start), HR("sigma_b_start", sigma_b_start),
      HR("b_end", b_end), HR("sigma_b_end", sigma_b_end),
      HR("nis_peak", nis_peak), HR("constancy_peak", constancy_peak), HB("mismatch", mismatch),
      HR("min_clearance", min_clearance), HR("min_clearance_depth", min_clearance_depth),
      HR("lambda0_min", lambda0_min), HR("lambda0_max", lambda0_max),
      HR("lambda_guide_max", lambda_guide_max),
      TripField{"alarms", Kind::Text, 1, [](const TripRecord& r) { return text(joinAlarms(r.alarms)); },
                [](TripRecord& r, const Value& v) { r.alarms = splitAlarms(v.text); }},
      HR("depth_bin", depth_bin),
      HB("id_attempted", id.attempted), HR("id_scale", id.scale), HR("id_sigma_scale", id.sigma_scale),
      HR("id_moment", id.moment), HR("id_sigma_moment", id.sigma_moment),
      HR("id_imbalance", id.imbalance), HR("id_sigma_imbalance", id.sigma_imbalance),
      HB("id_informative", id.informative), HR("id_loss30_separation", id.loss30_separation),
      HR("id_chi2", id.chi2), HI("id_dof", id.dof), HR("id_cpu_seconds", id.cpu_seconds),
      HT("id_note", id.note),
  };
  return t;
}

const std::vector<BinField>& binTable() {
  static const std::vector<BinField> t = {
      BR(depth_lo),
      BinField{"samples", Kind::Integer, 1, [](const DepthBinStats& b) { return integer(b.samples); },
               [](DepthBinStats& b, const Value& v) { b.samples = static_cast<int>(v.integer); }},
      BR(fy_mean), BR(fy_rms), BR(fy_hf_rms), BR(resid_mean), BR(resid_rms),
      BR(y_c_mean), BR(y_c_rms), BR(theta_mean), BR(theta_rms),
  };
  return t;
}

#undef HR
#undef HI
#undef HB
#undef HT
#undef BR

const char* sqlType(Kind k) {
  switch (k) {
    case Kind::Real: return "DOUBLE PRECISION NOT NULL";
    case Kind::Integer:
    case Kind::Boolean: return "BIGINT NOT NULL";
    case Kind::Text: return "TEXT NOT NULL";
  }
  return "TEXT";
}

template <class F>
std::string columnDefs(std::span<const F> fields) {
  std::string s;
  for (const auto& f : fields) {
    s += ", ";
    s += f.column;
    s += ' ';
    s += sqlType(f.kind);
  }
  return s;
}

template <class F>
std::string columns(std::span<const F> fields) {
  std::string s;
  for (const auto& f : fields) {
    if (!s.empty()) s += ',';
    s += f.column;
  }
  return s;
}

std::string values(std::size_t n, bool numbered) {
  std::string s;
  for (std::size_t i = 1; i <= n; ++i) {
    if (i > 1) s += ',';
    if (numbered) s.append("$").append(std::to_string(i));
    else s += '?';
  }
  return s;
}

std::string setVersion(int v) { return "UPDATE schema_version SET version = " + std::to_string(v); }

}  // namespace

std::span<const TripField> tripFields() { return tripTable(); }
std::span<const BinField> binFields() { return binTable(); }

std::vector<std::string> schemaSteps(int to) {
  switch (to) {
    case 1:
      return {
          "CREATE TABLE schema_version (version BIGINT NOT NULL)",
          "CREATE TABLE trips (shaft TEXT NOT NULL, trip BIGINT NOT NULL" + columnDefs(tripFields()) +
              ", PRIMARY KEY (shaft, trip))",
          "CREATE TABLE bins (shaft TEXT NOT NULL, trip BIGINT NOT NULL, idx BIGINT NOT NULL" +
              columnDefs(binFields()) +
              ", PRIMARY KEY (shaft, trip, idx), FOREIGN KEY (shaft, trip) REFERENCES trips (shaft, trip) "
              "ON DELETE CASCADE)",
          "INSERT INTO schema_version (version) VALUES (1)",
      };
    case 2:
      return {
          "CREATE TABLE baseline (shaft TEXT NOT NULL, trip BIGINT NOT NULL, marked_us BIGINT NOT NULL, "
          "PRIMARY KEY (shaft, trip), FOREIGN KEY (shaft, trip) REFERENCES trips (shaft, trip) ON DELETE CASCADE)",
          "CREATE INDEX trips_wall_end ON trips (wall_end_us)",
          setVersion(2),
      };
    default:
      throw std::out_of_range("history schema: no version " + std::to_string(to));
  }
}

std::string tripColumnList() { return "shaft,trip," + columns(tripFields()); }
std::string binColumnList() { return columns(binFields()); }

std::string insertTripSql(bool numbered) {
  return "INSERT INTO trips (" + tripColumnList() + ") VALUES (" + values(tripFields().size() + 2, numbered) +
         ") ON CONFLICT (shaft, trip) DO NOTHING";
}

std::string insertBinSql(bool numbered) {
  return "INSERT INTO bins (shaft,trip,idx," + binColumnList() + ") VALUES (" +
         values(binFields().size() + 3, numbered) + ")";
}

std::string valueError(std::string_view column, Kind kind, const Value& v) {
  if (v.kind != kind) {
    static const char* names[] = {"a real number", "an integer", "a boolean (0/1)", "text"};
    return "expected " + std::string(names[static_cast<int>(kind)]) + ", found " +
           names[static_cast<int>(v.kind)];
  }
  switch (kind) {
    case Kind::Real:
      if (!std::isfinite(v.real)) return "not a finite number";
      break;
    case Kind::Boolean:
      if (v.integer != 0 && v.integer != 1) return "a boolean must be 0 or 1, found " + std::to_string(v.integer);
      break;
    case Kind::Integer:
      if (column == "direction" && v.integer != 1 && v.integer != -1)
        return "must be 1 (down) or -1 (up), found " + std::to_string(v.integer);
      if ((column == "samples" || column == "id_dof") && (v.integer < 0 || v.integer > 1000000000))
        return "count out of range: " + std::to_string(v.integer);
      break;
    case Kind::Text:
      if (v.text.size() > kMaxText) return "text longer than " + std::to_string(kMaxText) + " bytes";
      break;
  }
  return {};
}

std::string recordError(const TripRecord& r) {
  if (r.shaft.size() > 128) return "shaft: name longer than 128 bytes";
  for (char c : r.shaft)
    if (static_cast<unsigned char>(c) < 0x20) return "shaft: control character in the name";
  if (r.trip < 0) return "trip: negative trip number " + std::to_string(r.trip);
  for (const auto& f : tripFields())
    if (auto e = valueError(f.column, f.kind, f.get(r)); !e.empty()) return std::string(f.column) + ": " + e;
  for (const auto& a : r.alarms)
    if (a.empty() || a.find(';') != std::string::npos) return "alarms: empty name or ';' in '" + a + "'";
  if (r.bins.size() > kMaxBins) return "bins: more than " + std::to_string(kMaxBins);
  for (std::size_t i = 0; i < r.bins.size(); ++i) {
    for (const auto& f : binFields())
      if (auto e = valueError(f.column, f.kind, f.get(r.bins[i])); !e.empty())
        return "bins[" + std::to_string(i) + "]." + std::string(f.column) + ": " + e;
    if (i > 0 && !(r.bins[i].depth_lo > r.bins[i - 1].depth_lo))
      return "bins[" + std::to_string(i) + "].depth_lo: bins not in increasing depth order";
  }
  return {};
}

std::string joinAlarms(const std::vector<std::string>& alarms) {
  std::string s;
  for (const auto& a : alarms) {
    if (!s.empty()) s += ';';
    s += a;
  }
  return s;
}

std::vector<std::string> splitAlarms(std::string_view s) {
  std::vector<std::string> out;
  while (!s.empty()) {
    const auto p = s.find(';');
    if (p != 0) out.emplace_back(s.substr(0, p));
    if (p == std::string_view::npos) break;
    s.remove_prefix(p + 1);
  }
  return out;
}

}  // namespace hoist::history
