// [sensors]/[estimator] and the measurement CSV: see hoist/io/estimator_config.hpp.
#include "hoist/io/estimator_config.hpp"

#include <cmath>
#include <fstream>
#include <istream>
#include <stdexcept>

#include "hoist/io/results.hpp"
#include "hoist/io/toml_section.hpp"
#include "csv_text.hpp"

namespace hoist::io {

const std::vector<std::string>& daemonSections() {
  // [history] and [condition] are read by hoist_history (the trip memory);
  // named here so that every tool reading the shaft from hoist-twind's file
  // (hoist-sim, hoist-estimate, hoist-study) accepts a file that has them.
  static const std::vector<std::string> s = {"service",   "alarms",  "forecast", "sensors",
                                             "estimator", "history", "condition"};
  return s;
}

EstimatorConfig estimatorConfigFromToml(const toml::table& tbl, const std::string& source) {
  EstimatorConfig c;
  SectionReader sensors(tbl, "sensors", source);
  SectionReader est(tbl, "estimator", source);
  est.boolean("enabled", c.enabled);
  for (const auto& f : kEstimatorFields) {
    SectionReader& r = f.section == "sensors" ? sensors : est;
    if (f.real) r.number(std::string(f.key), *f.real(c.settings));
    else r.integer(std::string(f.key), *f.integer(c.settings));
  }
  // hoist-twind's own keys of these sections (it reads them itself:
  // service/cfg/src/config_file.cpp).  A tool reading the daemon's file
  // (hoist-estimate, hoist-trips, Python) accepts them, type-checked, and has
  // no use for them: the same file serves live and offline.
  double daemon_only = 0.0;
  sensors.number("max_clock_offset", daemon_only);
  est.number("clear_hold", daemon_only);
  sensors.run();
  est.run();
  try {
    c.settings.validate();
  } catch (const std::invalid_argument& e) {
    rethrowWithLine(e.what(), source, {&sensors, &est}, true);
  }
  return c;
}

double serviceMaxStep(const toml::table& tbl, const std::string& source, double fallback) {
  const toml::node* sec = tbl.get("service");
  if (!sec) return fallback;
  const auto* t = sec->as_table();
  if (!t) throw ConfigError(source, lineOf(*sec), "service", std::string("must be a table [service], got ") + typeName(*sec));
  const toml::node* n = t->get("max_step");
  if (!n) return fallback;
  double v = 0.0;
  if (const auto* i = n->as_integer()) v = static_cast<double>(i->get());
  else if (const auto* f = n->as_floating_point()) v = f->get();
  else throw ConfigError(source, lineOf(*n), "service.max_step", std::string("must be a number, got ") + typeName(*n));
  if (!std::isfinite(v) || v < 0.0 || v > 10.0)
    throw ConfigError(source, lineOf(*n), "service.max_step", "must be in [0, 10] s (0: no substeps)");
  return v;
}

std::string toToml(const EstimatorConfig& c) {
  EstimatorSettings s = c.settings;  // the accessors take a non-const reference
  std::string out;
  std::string_view section;
  for (const auto& f : kEstimatorFields) {
    if (f.section != section) {
      out += (section.empty() ? "[" : "\n[") + std::string(f.section) + "]\n";
      if (f.section == "estimator") out += std::string("enabled = ") + (c.enabled ? "true" : "false") + "\n";
      section = f.section;
    }
    std::string v;
    if (f.real) {
      appendNumber(v, *f.real(s));
      if (v.find_first_of(".eni") == std::string::npos) v += ".0";
    } else {
      v = std::to_string(*f.integer(s));
    }
    out += std::string(f.key) + " = " + v + "   # " + (f.unit.empty() ? "" : std::string(f.unit) + ", ") +
           std::string(f.doc) + "\n";
  }
  return out;
}

// ---- measurement CSV ---------------------------------------------------------

namespace {

enum Col { kT, kL, kV, kA, kFy, kOmega, kRope, kNumCols };
constexpr const char* kColNames[kNumCols] = {"t", "l", "v", "a", "f_y", "omega", "rope_load"};
constexpr unsigned kColBits[kNumCols] = {0, 0, 0, 0, kSensorImuAccel, kSensorImuRate, kSensorRopeLoad};

}  // namespace

std::vector<MeasurementSample> readMeasurementsCsv(std::istream& in, const std::string& source,
                                                   const ProfileLimits& lim, MeasurementColumns* info) {
  std::string line;
  int lineno = 0;
  int col[kNumCols];
  for (int& c : col) c = -1;
  std::size_t ncols = 0;
  bool have_header = false;
  MeasurementColumns cols;
  std::vector<MeasurementSample> out;
  int last_line = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (const std::string bad = csv::checkLine(line, lineno, "measurement CSV"); !bad.empty())
      throw MeasurementError(source, lineno, "", bad);
    const std::string tl = csv::trim(line);
    if (tl.empty() || tl[0] == '#') continue;
    const auto fields = csv::splitComma(tl);
    if (!have_header) {
      have_header = true;
      ncols = fields.size();
      for (std::size_t i = 0; i < fields.size(); ++i) {
        if (fields[i].empty()) throw MeasurementError(source, lineno, "", "empty column name in the header");
        int k = 0;
        while (k < kNumCols && fields[i] != kColNames[k]) ++k;
        if (k == kNumCols) {
          cols.ignored.push_back(csv::shortened(fields[i]));
          continue;
        }
        if (col[k] >= 0) throw MeasurementError(source, lineno, fields[i], "column appears twice in the header");
        col[k] = static_cast<int>(i);
        cols.sensors |= kColBits[k];
      }
      for (int k = kT; k <= kA; ++k) {
        if (col[k] >= 0) continue;
        double dummy;
        const bool numeric = csv::parseDouble(fields[0], dummy);
        throw MeasurementError(
            source, lineno, kColNames[k],
            std::string("required column missing") +
                (numeric ? " (the first line must be a header naming the columns: t,l,v,a and optionally f_y,omega,rope_load)"
                         : "; the header must name t, l, v and a (f_y, omega, rope_load optional), got '" +
                               csv::shortened(tl) + "'"));
      }
      continue;
    }
    if (fields.size() != ncols)
      throw MeasurementError(source, lineno, "",
                             "expected " + std::to_string(ncols) + " fields like the header, got " +
                                 std::to_string(fields.size()));
    // Validate the whole row before it is stored.
    double v[kNumCols] = {};
    unsigned present = 0;
    for (int k = 0; k < kNumCols; ++k) {
      if (col[k] < 0) continue;
      const std::string& f = fields[static_cast<std::size_t>(col[k])];
      if (f.empty()) {
        if (kColBits[k] == 0) throw MeasurementError(source, lineno, kColNames[k], "empty field (required column)");
        continue;  // this sensor has no sample in this row
      }
      if (!csv::parseDouble(f, v[k]))
        throw MeasurementError(source, lineno, kColNames[k], "not a number: '" + csv::shortened(f) + "'");
      if (!std::isfinite(v[k]))
        throw MeasurementError(source, lineno, kColNames[k],
                               "must be finite, got '" + csv::shortened(f) + "'" +
                                   (kColBits[k] ? " (leave the field empty for a missing sample)" : ""));
      present |= kColBits[k];
    }
    if (!out.empty() && !(v[kT] > out.back().t))
      throw MeasurementError(source, lineno, "t",
                             "time must increase strictly (previous row t = " + std::to_string(out.back().t) +
                                 ", this row " + std::to_string(v[kT]) + ")");
    if (!out.empty() && v[kT] - out.back().t > lim.max_gap)
      throw MeasurementError(source, lineno, "t",
                             "gap of " + std::to_string(v[kT] - out.back().t) + " s since the previous row exceeds " +
                                 std::to_string(lim.max_gap) + " s");
    if (!(v[kL] > 0)) throw MeasurementError(source, lineno, "l", "rope length must be > 0, got " + std::to_string(v[kL]));
    if (std::abs(v[kV]) > lim.max_speed)
      throw MeasurementError(source, lineno, "v", "|v| = " + std::to_string(std::abs(v[kV])) + " m/s exceeds " +
                                                      std::to_string(lim.max_speed) + " m/s");
    if (std::abs(v[kA]) > lim.max_accel)
      throw MeasurementError(source, lineno, "a", "|a| = " + std::to_string(std::abs(v[kA])) + " m/s^2 exceeds " +
                                                      std::to_string(lim.max_accel) + " m/s^2");
    if (out.size() >= lim.max_rows)
      throw MeasurementError(source, lineno, "", "more than " + std::to_string(lim.max_rows) + " rows");
    MeasurementSample m;
    m.t = v[kT];
    m.k = Kinematics{v[kL], v[kV], v[kA]};
    m.z = SensorValues{v[kFy], v[kOmega], v[kRope]};
    m.present = present;
    out.push_back(m);
    last_line = lineno;
  }
  if (in.bad()) throw MeasurementError(source, lineno, "", "read error");
  if (!have_header)
    throw MeasurementError(source, 0, "", "empty file: expected a header t,l,v,a[,f_y,omega,rope_load] and rows");
  if (out.size() < 2)
    throw MeasurementError(source, last_line, "",
                           "a measurement file needs at least two rows, got " + std::to_string(out.size()));
  if (info) *info = std::move(cols);
  return out;
}

std::vector<MeasurementSample> readMeasurementsCsvFile(const std::string& path, const ProfileLimits& limits,
                                                       MeasurementColumns* info) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MeasurementError(path, 0, "", "cannot open the measurement file");
  return readMeasurementsCsv(in, path, limits, info);
}

void appendMeasurementRow(std::string& s, const MeasurementSample& m) {
  appendNumber(s, m.t);
  s += ',';
  appendNumber(s, m.k.l);
  s += ',';
  appendNumber(s, m.k.v);
  s += ',';
  appendNumber(s, m.k.a);
  s += ',';
  if (m.present & kSensorImuAccel) appendNumber(s, m.z.f_y);
  s += ',';
  if (m.present & kSensorImuRate) appendNumber(s, m.z.omega);
  s += ',';
  if (m.present & kSensorRopeLoad) appendNumber(s, m.z.rope_load);
  s += '\n';
}

}  // namespace hoist::io
