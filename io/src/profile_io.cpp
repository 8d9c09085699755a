// Hoist profiles from CSV and SPEC strings.  See hoist/io/profile.hpp.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <istream>
#include <map>
#include <ostream>
#include <sstream>
#include <sys/stat.h>

#include "hoist/plausibility.hpp"
#include "hoist/io/profile.hpp"
#include "hoist/io/results.hpp"
#include "csv_text.hpp"

namespace hoist::io {

using csv::parseDouble;
using csv::shortened;
using csv::splitComma;
using csv::trim;

HoistProfile readProfileCsv(std::istream& in, const std::string& source, double l0, const ProfileLimits& lim) {
  std::string line;
  int lineno = 0;
  int col_t = -1, col_l = -1, col_v = -1, col_a = -1;
  std::size_t ncols = 0;
  bool have_header = false;
  std::vector<double> t, l, v, a;
  int last_line = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (const std::string bad = csv::checkLine(line, lineno, "profile CSV"); !bad.empty())
      throw ProfileError(source, lineno, "", bad);
    const std::string tl = trim(line);
    if (tl.empty() || tl[0] == '#') continue;
    const auto fields = splitComma(tl);
    if (!have_header) {
      have_header = true;
      ncols = fields.size();
      for (std::size_t i = 0; i < fields.size(); ++i) {
        int* slot = nullptr;
        if (fields[i] == "t") slot = &col_t;
        else if (fields[i] == "l") slot = &col_l;
        else if (fields[i] == "v") slot = &col_v;
        else if (fields[i] == "a") slot = &col_a;
        else if (fields[i].empty()) throw ProfileError(source, lineno, "", "empty column name in the header");
        if (slot) {
          if (*slot >= 0) throw ProfileError(source, lineno, fields[i], "column appears twice in the header");
          *slot = static_cast<int>(i);
        }
      }
      const char* missing = col_t < 0 ? "t" : col_v < 0 ? "v" : col_a < 0 ? "a" : nullptr;
      if (missing) {
        double dummy;
        const bool numeric = parseDouble(fields[0], dummy);
        throw ProfileError(source, lineno, missing,
                           std::string("required column missing") +
                               (numeric ? " (the first line must be a header naming the columns: t,v,a and optionally l)"
                                        : "; the header must name t, v and a (l optional), got '" + shortened(tl) + "'"));
      }
      continue;
    }
    if (fields.size() != ncols)
      throw ProfileError(source, lineno, "",
                         "expected " + std::to_string(ncols) + " fields like the header, got " + std::to_string(fields.size()));
    auto get = [&](int col, const char* name) {
      double x;
      const std::string& f = fields[static_cast<std::size_t>(col)];
      if (!parseDouble(f, x)) throw ProfileError(source, lineno, name, "not a number: '" + shortened(f) + "'");
      if (!std::isfinite(x)) throw ProfileError(source, lineno, name, "must be finite, got '" + f + "'");
      return x;
    };
    const double ti = get(col_t, "t"), vi = get(col_v, "v"), ai = get(col_a, "a");
    if (!t.empty() && !(ti > t.back()))
      throw ProfileError(source, lineno, "t",
                         "time must increase strictly (previous row t = " + std::to_string(t.back()) + ", this row " +
                             std::to_string(ti) + ")");
    if (!t.empty() && ti - t.back() > lim.max_gap)
      throw ProfileError(source, lineno, "t",
                         "gap of " + std::to_string(ti - t.back()) + " s since the previous row exceeds " +
                             std::to_string(lim.max_gap) + " s");
    if (std::abs(vi) > lim.max_speed)
      throw ProfileError(source, lineno, "v", "|v| = " + std::to_string(std::abs(vi)) + " m/s exceeds " +
                                                  std::to_string(lim.max_speed) + " m/s");
    if (std::abs(ai) > lim.max_accel)
      throw ProfileError(source, lineno, "a", "|a| = " + std::to_string(std::abs(ai)) + " m/s^2 exceeds " +
                                                  std::to_string(lim.max_accel) + " m/s^2");
    if (col_l >= 0) {
      const double li = get(col_l, "l");
      if (!(li > 0)) throw ProfileError(source, lineno, "l", "rope length must be > 0, got " + std::to_string(li));
      l.push_back(li);
    }
    t.push_back(ti);
    v.push_back(vi);
    a.push_back(ai);
    last_line = lineno;
    if (t.size() > lim.max_rows)
      throw ProfileError(source, lineno, "", "more than " + std::to_string(lim.max_rows) + " rows");
  }
  if (in.bad()) throw ProfileError(source, lineno, "", "read error");
  if (!have_header) throw ProfileError(source, 0, "", "empty file: expected a header t,v,a[,l] and rows");
  if (t.size() < 2)
    throw ProfileError(source, last_line, "", "a profile needs at least two rows, got " + std::to_string(t.size()));
  if (col_l < 0) {
    if (!(l0 > 0) || !std::isfinite(l0))
      throw ProfileError(source, 0, "l", "no l column and no valid initial length to integrate v from");
    return HoistProfile::fromVelocity(t, v, a, l0);
  }
  std::vector<ProfileSample> s(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) s[i] = {t[i], Kinematics{l[i], v[i], a[i]}};
  return HoistProfile(std::move(s));
}

HoistProfile readProfileCsvFile(const std::string& path, double l0, const ProfileLimits& limits) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ProfileError(path, 0, "", "cannot open the profile file");
  return readProfileCsv(in, path, l0, limits);
}

namespace {

struct SpecKind {
  const char* name;
  std::vector<std::string> keys;
};

const std::vector<SpecKind>& specKinds() {
  static const std::vector<SpecKind> k = {
      {"paper", {"l0"}},
      {"trapezoid", {"vmax", "amax", "travel", "t_end", "dt", "l0"}},
      {"scurve", {"vmax", "amax", "jmax", "travel", "t_end", "dt", "l0"}},
      {"estop", {"vmax", "t_stop", "decel", "t_end", "dt", "l0"}},
      {"rest", {"t_end", "dt", "l0"}},
  };
  return k;
}

}  // namespace

bool isProfileSpec(const std::string& arg) {
  const std::string name = arg.substr(0, arg.find(':'));
  for (const auto& k : specKinds())
    if (name == k.name) return true;
  return false;
}

HoistProfile profileFromSpec(const std::string& spec, double l0) {
  const std::string src = "profile spec '" + shortened(spec) + "'";
  const std::size_t colon = spec.find(':');
  const std::string name = spec.substr(0, colon);
  const SpecKind* kind = nullptr;
  for (const auto& k : specKinds())
    if (name == k.name) kind = &k;
  if (!kind) {
    std::vector<std::string> names;
    for (const auto& k : specKinds()) names.emplace_back(k.name);
    const std::string m = closestMatch(name, names);
    throw ProfileError(src, 0, "",
                       "unknown profile '" + shortened(name) + "'" + (m.empty() ? "" : " (did you mean '" + m + "'?)") +
                           "; expected a CSV file or one of paper, trapezoid, scurve, estop, rest");
  }
  std::map<std::string, double> kv;
  if (colon != std::string::npos) {
    std::string rest = spec.substr(colon + 1);
    for (const std::string& item : splitComma(rest)) {
      if (item.empty()) continue;
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos)
        throw ProfileError(src, 0, name, "expected key=value, got '" + shortened(item) + "'");
      const std::string key = trim(item.substr(0, eq)), val = trim(item.substr(eq + 1));
      if (std::find(kind->keys.begin(), kind->keys.end(), key) == kind->keys.end()) {
        std::string all;
        for (const auto& k : kind->keys) all += (all.empty() ? "" : ", ") + k;
        const std::string m = closestMatch(key, kind->keys);
        throw ProfileError(src, 0, name + "." + key,
                           "unknown parameter" + (m.empty() ? "" : " (did you mean '" + m + "'?)") + "; " + name +
                               " takes " + all);
      }
      double x;
      if (!parseDouble(val, x) || !std::isfinite(x))
        throw ProfileError(src, 0, name + "." + key, "expected a finite number, got '" + shortened(val) + "'");
      if (kv.count(key)) throw ProfileError(src, 0, name + "." + key, "given twice");
      kv[key] = x;
    }
  }
  auto get = [&](const char* k, double def) { return kv.count(k) ? kv[k] : def; };
  const double L0 = get("l0", l0);
  const double dt = get("dt", 0.01);
  const double t_end = get("t_end", name == "scurve" ? 70.0 : name == "estop" ? 30.0 : 60.0);
  if (!(dt > 0) || dt > 1.0) throw ProfileError(src, 0, name + ".dt", "must be in (0, 1] s");
  if (!(t_end > 0) || t_end / dt > 5e7) throw ProfileError(src, 0, name + ".t_end", "must be > 0 and at most 5e7 samples");
  if (!(L0 > 0)) throw ProfileError(src, 0, name + ".l0", "initial rope length must be > 0");
  try {
    if (name == "paper") return HoistProfile::trapezoid(L0);
    if (name == "trapezoid")
      return HoistProfile::trapezoid(L0, get("vmax", 5.0), get("amax", 1.0), get("travel", 250.0), t_end, dt);
    if (name == "scurve")
      return HoistProfile::sCurve(L0, get("vmax", 5.0), get("amax", 1.0), get("jmax", 0.5), get("travel", 250.0),
                                  t_end, dt);
    if (name == "estop")
      return HoistProfile::emergencyStop(L0, get("vmax", 5.0), get("t_stop", 20.0), get("decel", 3.0), t_end, dt);
    // rest
    const auto n = static_cast<std::size_t>(std::llround(t_end / dt));
    std::vector<ProfileSample> s(n + 1);
    for (std::size_t i = 0; i <= n; ++i) s[i] = {static_cast<double>(i) * dt, Kinematics{L0, 0.0, 0.0}};
    return HoistProfile(std::move(s));
  } catch (const std::invalid_argument& e) {
    throw ProfileError(src, 0, name, e.what());
  }
}

HoistProfile loadProfile(const std::string& arg, double l0, const ProfileLimits& limits) {
  struct stat st {};
  if (::stat(arg.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw ProfileError(arg, 0, "", "is a directory, expected a profile CSV");
    return readProfileCsvFile(arg, l0, limits);
  }
  if (isProfileSpec(arg)) return profileFromSpec(arg, l0);
  if (arg.find('/') != std::string::npos || arg.find(".csv") != std::string::npos)
    throw ProfileError(arg, 0, "", "no such profile file");
  return profileFromSpec(arg, l0);  // explains the unknown name
}

void checkProfileInShaft(const HoistProfile& profile, const ShaftParams& p, const std::string& source) {
  // The model's valid range (hoist/plausibility.hpp): the sleeves stay on the
  // guide ropes, and a documented distance from both shaft ends.
  const LengthRange r = validLengthRange(p);
  for (const auto& s : profile.samples()) {
    if (!(s.k.l >= r.lo) || !(s.k.l <= r.hi)) {
      std::ostringstream os;
      os << "at t = " << s.t << " s the rope length l = " << s.k.l
         << " m leaves the shaft: valid rope lengths are [" << r.lo << ", " << r.hi
         << "] m (the cage's sleeves on the guide ropes, " << r.lo << " m clear of both ends of (0, L - 2h) = (0, "
         << p.maxRopeLength() << ") m; docs/model.md)";
      throw ProfileError(source, 0, "l", os.str());
    }
  }
}

void writeProfileCsv(CheckedFile& out, const HoistProfile& profile) {
  std::string s = "t,l,v,a\n";
  for (const auto& p : profile.samples()) {
    appendNumber(s, p.t);
    s += ',';
    appendNumber(s, p.k.l);
    s += ',';
    appendNumber(s, p.k.v);
    s += ',';
    appendNumber(s, p.k.a);
    s += '\n';
    if (s.size() >= 65536) {
      out.write(s);
      s.clear();
    }
  }
  out.write(s);
}

void writeProfileCsv(std::ostream& out, const HoistProfile& profile) {
  out << "t,l,v,a\n";
  std::string s;
  for (const auto& p : profile.samples()) {
    s.clear();
    appendNumber(s, p.t);
    s += ',';
    appendNumber(s, p.k.l);
    s += ',';
    appendNumber(s, p.k.v);
    s += ',';
    appendNumber(s, p.k.a);
    s += '\n';
    out << s;
  }
}

const char* profileSpecHelp() {
  return "A profile is a CSV file (header t,v,a[,l]; '#' comments) or a SPEC:\n"
         "  paper                                   the paper's Fig. 2 trip: l0 -> l0+250 m, vmax 5, amax 1, 60 s\n"
         "  trapezoid:vmax=5,amax=1,travel=250,t_end=60,dt=0.01\n"
         "  scurve:vmax=5,amax=1,jmax=0.5,travel=250,t_end=70,dt=0.01\n"
         "  estop:vmax=5,t_stop=20,decel=3,t_end=30,dt=0.01\n"
         "  rest:t_end=60,dt=0.01\n"
         "All take l0=<m> (default: hoisting_rope.initial_length); travel<0 (or vmax<0 for estop) hoists up.";
}

}  // namespace hoist::io
