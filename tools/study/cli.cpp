// hoist-study's command line: see cli.hpp.
#include "cli.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "hoist/io/config.hpp"
#include "hoist/io/daemon_shaft.hpp"
#include "hoist/io/profile.hpp"
#include "hoist/simulator.hpp"

namespace hoist::study::cli {

CLI::Validator numberAbove(double lo, bool inclusive) {
  return CLI::Validator(
      [lo, inclusive](std::string& in) -> std::string {
        double v = 0;
        std::size_t pos = 0;
        try {
          v = std::stod(in, &pos);
        } catch (...) {
          return "'" + in + "' is not a number";
        }
        if (pos != in.size() || !std::isfinite(v)) return "'" + in + "' is not a finite number";
        if (inclusive ? v < lo : v <= lo)
          return "must be " + std::string(inclusive ? ">= " : "> ") + fmtg(lo) + ", got " + in;
        return {};
      },
      inclusive ? "NUMBER >= 0" : "NUMBER > 0");
}
CLI::Validator numberAtMost(double hi) {
  return CLI::Validator(
      [hi](std::string& in) -> std::string {
        double v = 0;
        std::size_t pos = 0;
        try {
          v = std::stod(in, &pos);
        } catch (...) {
          return "'" + in + "' is not a number";
        }
        if (pos != in.size() || !std::isfinite(v)) return "'" + in + "' is not a finite number";
        if (v > hi) return "must be <= " + fmtg(hi) + ", got " + in;
        return {};
      },
      "NUMBER");
}
void addCommon(CLI::App* sub, Common& c, [[maybe_unused]] bool advisor, bool paper) {
  sub->add_option("--out-dir", c.out_dir, "Directory for CSVs, scripts and PNGs (created)")
      ->capture_default_str();
  sub->add_option("--config", c.config,
                  "Shaft configuration (TOML, README / docs/model.md); default: the paper's values");
  sub->add_option("--profile", c.profile,
                  "Hoist profile CSV (t,v,a[,l]) or SPEC; default: the paper's Fig. 2 trapezoid");
  sub->add_option("--modes", c.modes, "Assumed modes per rope (overrides model.modes)")
      ->check(CLI::Range(1, kMaxModes));
  sub->add_option("--dt", c.dt, "Output step [s], as hoist-sim: 1e-6 .. 1")
      ->capture_default_str()
      ->check(numberAbove(1e-6, true))
      ->check(numberAtMost(1.0));
  sub->add_option("--max-step", c.max_step, "Largest integration step [s] (0: --dt)")
      ->capture_default_str()
      ->check(numberAbove(0, true));
  // --initial: the same values, meaning and default as in hoist-sim.
  sub->add_option("--initial", c.initial,
                  "initial state: static (equilibrium at t = 0), rest (q = 0: the eccentric load acts as a step, as in the "
                  "paper's figures) or config (the config's model.initial, static unless set); default: config")
      ->check(CLI::IsMember({"rest", "static", "config"}));
  sub->add_option("--static-correction", c.static_correction,
                  std::string("Residual flexibility of the guide ropes (overrides model.static_correction); "
                              "default: ") +
                      (paper ? "off: the paper's truncation, which its figures show"
                             : "model.static_correction (on unless the config says false)"))
      ->check(CLI::IsMember({"on", "off"}));
  sub->add_option("--jobs,-j", c.jobs, "Parallel runs (default: hardware concurrency)")
      ->check(numberAbove(0, true));
  sub->add_flag("--no-plots", c.no_plots, "Write CSVs and gnuplot scripts but do not run gnuplot");
}
std::string fmtg(double v, const char* f) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::vector<double> parseValues(const std::string& s) {
  auto num = [&](const std::string& tok) {
    std::size_t pos = 0;
    double v = 0;
    try {
      v = std::stod(tok, &pos);
    } catch (...) {
      pos = 0;
    }
    while (pos < tok.size() && std::isspace(static_cast<unsigned char>(tok[pos]))) ++pos;
    if (tok.empty() || pos != tok.size() || !std::isfinite(v))
      throw UsageError("--values: '" + tok + "' is not a number (in '" + s + "')");
    return v;
  };
  std::vector<double> out;
  if (s.find(':') != std::string::npos) {
    std::vector<std::string> p;
    std::stringstream ss(s);
    for (std::string t; std::getline(ss, t, ':');) p.push_back(t);
    if (p.size() != 3) throw UsageError("--values: range must be START:STOP:COUNT, got '" + s + "'");
    const double a = num(p[0]), b = num(p[1]), c = num(p[2]);
    if (c < 2 || c != std::floor(c) || c > 1000)
      throw UsageError("--values: COUNT must be an integer in [2, 1000], got '" + p[2] + "'");
    for (int i = 0; i < static_cast<int>(c); ++i) out.push_back(a + (b - a) * i / (c - 1));
    return out;
  }
  std::stringstream ss(s);
  for (std::string t; std::getline(ss, t, ',');) out.push_back(num(t));
  if (out.empty()) throw UsageError("--values: empty list");
  return out;
}

std::pair<double, double> parseRange(const std::string& opt, const std::string& s) {
  const auto c = s.find(':');
  if (c == std::string::npos) throw UsageError(opt + ": expected MIN:MAX, got '" + s + "'");
  try {
    std::size_t p1 = 0, p2 = 0;
    const double a = std::stod(s.substr(0, c), &p1), b = std::stod(s.substr(c + 1), &p2);
    if (p1 != c || p2 != s.size() - c - 1 || !std::isfinite(a) || !std::isfinite(b)) throw 0;
    return {a, b};
  } catch (...) {
    throw UsageError(opt + ": expected MIN:MAX with numbers, got '" + s + "'");
  }
}

namespace {

// hoist_io's errors (ConfigError) already name file:line:key.
ShaftParams studyLoadConfig(const std::string& path) {
  try {
    // A daemon configuration is a shaft file plus hoist-twind's sections:
    // accept every one, use the shaft, say once what is ignored.
    std::string note;
    ShaftParams p = hoist::io::loadDaemonShaft(path, "hoist-study", &note);
    static bool said = false;
    if (!note.empty() && !said) std::cerr << note << "\n";
    said = true;
    return p;
  } catch (const std::exception& e) {
    throw UsageError(std::string("--config: ") + e.what());
  }
}

}  // namespace

ShaftParams loadParams(const Common& c) {
  ShaftParams p;
  if (!c.config.empty()) p = studyLoadConfig(c.config);  // throws UsageError naming file:line:key
  if (c.modes > 0) p.n = c.modes;
  if (c.initial == "rest") p.initial = InitialState::Rest;
  else if (c.initial == "static") p.initial = InitialState::Static;
  if (c.static_correction == "on") p.static_correction = true;
  else if (c.static_correction == "off") p.static_correction = false;
  try {
    p.validate();
  } catch (const ParamError& e) {
    throw UsageError(std::string("invalid parameter ") + e.what());
  }
  return p;
}

HoistProfile loadProfile(const Common& c, const ShaftParams& p) {
  if (c.profile.empty() || c.profile == "paper" || c.profile == "trapezoid")
    return HoistProfile::trapezoid(p.l0);
  try {
    return hoist::io::loadProfile(c.profile, p.l0);
  } catch (const std::exception& e) {
    throw UsageError(std::string("--profile: ") + e.what());
  }
}

void checkTraceSize(const Common& c, const HoistProfile& profile, std::size_t runs) {
  const double span = profile.endTime() - profile.startTime();
  const double rows = std::floor(span / c.dt) + 2.0;
  if (!(rows <= kMaxRunRows))
    throw UsageError("--dt: " + fmtg(c.dt) + " s gives " + fmtg(rows, "%.3g") + " output rows per run over the " +
                     fmtg(span) + " s profile, more than " + fmtg(kMaxRunRows, "%.0e") +
                     " (each run's trace is held in memory, 96 B a row); raise --dt or shorten the profile");
  if (!(rows * static_cast<double>(runs) <= kMaxStudyRows))
    throw UsageError("--dt: " + fmtg(c.dt) + " s gives " + fmtg(rows, "%.3g") + " output rows per run, " +
                     std::to_string(runs) + " runs hold " + fmtg(rows * static_cast<double>(runs), "%.3g") +
                     " rows in memory, more than " + fmtg(kMaxStudyRows, "%.0e") +
                     "; raise --dt or give fewer --values");
}

RunOptions runOptions(const Common& c, const ShaftParams& p) {
  RunOptions o;
  o.sim.dt = c.dt;
  o.sim.max_step = c.max_step;
  o.sim.initial = p.initial;
  try {
    (void)substepsFor(o.sim);
  } catch (const std::exception& e) {
    throw UsageError(std::string("--max-step: ") + e.what());
  }
  return o;
}

}  // namespace hoist::study::cli
