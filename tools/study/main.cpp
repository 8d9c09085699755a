// hoist-study -- the paper's Section 3 studies (Figs. 2-13) in one command,
// any parameter sweep, and the preload advisor.  A thin shell around the
// hoist_study library: options, files, gnuplot, progress.
//
//   hoist-study NAME [--out-dir DIR] [--config FILE] [--profile FILE|SPEC]
//                    [--modes N] [--dt S] [--max-step S] [--initial rest|static|config]
//                    [--jobs N] [--no-plots]
//   NAME: response | preload | tension-difference | eccentric-load | mass | all
//         | sweep --param KEY --values V1,V2,... | advise --clearance M ...
//
// Exit status: 0 success, 1 a run failed or a file could not be written,
// 2 usage or configuration error, 3 (advise) target infeasible in the range.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hoist/study/advisor.hpp"
#include "hoist/study/sweep.hpp"
#include "output.hpp"

#include "hoist/io/config.hpp"
#include "hoist/io/profile.hpp"

namespace fs = std::filesystem;
using namespace hoist;
using namespace hoist::study;

namespace {

std::string fmtg0(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Common {
  std::string out_dir = "study-out";
  std::string config;
  std::string profile;
  int modes = 0;
  double dt = 0.01;
  double max_step = 0.0025;
  std::string initial;  // "" -> rest for the studies, config for advise
  int jobs = 0;
  bool no_plots = false;
};

/// Readable replacements for CLI::PositiveNumber / NonNegativeNumber (whose
/// messages print DBL_MAX).
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
          return "must be " + std::string(inclusive ? ">= " : "> ") + fmtg0(lo) + ", got " + in;
        return {};
      },
      inclusive ? "NUMBER >= 0" : "NUMBER > 0");
}

void addCommon(CLI::App* sub, Common& c, bool advisor) {
  sub->add_option("--out-dir", c.out_dir, "Directory for CSVs, scripts and PNGs (created)")
      ->capture_default_str();
  sub->add_option("--config", c.config,
                  "Shaft configuration (TOML, INTERFACES.md); default: the paper's values");
  sub->add_option("--profile", c.profile,
                  "Hoist profile CSV (t,v,a[,l]) or SPEC; default: the paper's Fig. 2 trapezoid");
  sub->add_option("--modes", c.modes, "Assumed modes per rope (overrides model.modes)")
      ->check(CLI::Range(1, kMaxModes));
  sub->add_option("--dt", c.dt, "Output step [s]")->capture_default_str()->check(numberAbove(0, false));
  sub->add_option("--max-step", c.max_step, "Largest integration step [s] (0: --dt)")
      ->capture_default_str()
      ->check(numberAbove(0, true));
  sub->add_option("--initial", c.initial,
                  std::string("Initial state: rest (q = 0, the eccentric load as a step: the free vibration "
                              "of the paper's figures), static (equilibrium), config (model.initial); default: ") +
                      (advisor ? "config" : "rest"))
      ->check(CLI::IsMember({"rest", "static", "config"}));
  sub->add_option("--jobs,-j", c.jobs, "Parallel runs (default: hardware concurrency)")
      ->check(numberAbove(0, true));
  sub->add_flag("--no-plots", c.no_plots, "Write CSVs and gnuplot scripts but do not run gnuplot");
}

std::string fmtg(double v, const char* f = "%g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// "1,2,3" or "start:stop:count" (evenly spaced, count >= 2).
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

// hoist_io's errors (ConfigError) already name file:line:key.
ShaftParams studyLoadConfig(const std::string& path) {
  try {
    // A daemon configuration is a shaft file plus [service]/[alarms]: accept it.
    return hoist::io::shaftParamsFromToml(hoist::io::loadTomlFile(path), path, {"service", "alarms"});
  } catch (const std::exception& e) {
    throw UsageError(std::string("--config: ") + e.what());
  }
}

HoistProfile studyLoadProfile(const std::string& spec, const ShaftParams& p) {
  try {
    return hoist::io::loadProfile(spec, p.l0);
  } catch (const std::exception& e) {
    throw UsageError(std::string("--profile: ") + e.what());
  }
}

ShaftParams loadParams(const Common& c) {
  ShaftParams p;
  if (!c.config.empty()) {
    p = studyLoadConfig(c.config);  // throws UsageError naming file:line:key
  }
  if (c.modes > 0) p.n = c.modes;
  if (c.initial == "rest") p.initial = InitialState::Rest;
  else if (c.initial == "static") p.initial = InitialState::Static;
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
  return studyLoadProfile(c.profile, p);  // throws UsageError
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

/// Progress on stderr when it is a terminal (one line, rewritten).
class Progress {
 public:
  explicit Progress(std::string what) : what_(std::move(what)), tty_(::isatty(STDERR_FILENO) != 0) {}
  void operator()(double f) {
    if (!tty_) return;
    std::lock_guard<std::mutex> lk(m_);
    const int pct = static_cast<int>(f * 100.0);
    if (pct == last_) return;
    last_ = pct;
    std::fprintf(stderr, "\r%s %3d%%", what_.c_str(), pct);
    std::fflush(stderr);
  }
  ~Progress() {
    if (tty_ && last_ >= 0) std::fprintf(stderr, "\r%s done\n", what_.c_str());
  }

 private:
  std::string what_;
  bool tty_;
  int last_ = -1;
  std::mutex m_;
};

// ---- figures ----------------------------------------------------------------------

std::string runFile(std::size_t i) { return "runs/run" + std::to_string(i + 1) + ".csv"; }

out::Panel signalPanel(const Study& s, const std::string& col, const std::string& ylabel, double scale) {
  out::Panel p;
  p.ylabel = ylabel;
  for (std::size_t i = 0; i < s.runs.size(); ++i)
    p.series.push_back({runFile(i), "\"t\":(column(\"" + col + "\")*" + fmtg(scale) + ")",
                        s.runs.size() == 1 ? col : s.runs[i].label});
  return p;
}

std::vector<out::Figure> figuresFor(const Study& s) {
  std::vector<out::Figure> f;
  auto disp = [&](const std::string& name, const std::string& title) {
    out::Figure fig{name, title, {signalPanel(s, "y_c", "y_c [mm]", 1e3), signalPanel(s, "theta", "theta [mrad]", 1e3)}};
    f.push_back(fig);
  };
  auto lambdas = [&](const std::string& name, const std::string& title, std::vector<int> ks) {
    out::Figure fig{name, title, {}};
    for (int k : ks) fig.panels.push_back(signalPanel(s, "lambda_" + std::to_string(k), "lambda_" + std::to_string(k) + " [N]", 1.0));
    if (ks.size() == 4) fig.cols = 2;
    f.push_back(fig);
  };
  if (s.name == "response") {
    f.push_back({"fig02_profile", "Fig. 2: hoist profile (descending)",
                 {signalPanel(s, "l", "l [m]", 1), signalPanel(s, "v", "v [m/s]", 1), signalPanel(s, "a", "a [m/s^2]", 1)}});
    f.push_back({"fig03_cage", "Fig. 3: cage longitudinal, lateral and torsional displacement",
                 {signalPanel(s, "x_c", "x_c [mm]", 1e3), signalPanel(s, "y_c", "y_c [mm]", 1e3),
                  signalPanel(s, "theta", "theta [mrad]", 1e3)},
                 1, 800, 650});
    out::Figure shape{"fig04_guide_rope", "Fig. 4: lateral displacement of guide rope 1 (rope 2 dashed)", {}};
    out::Panel p;
    p.xlabel = "depth x [m]";
    p.ylabel = "y [mm]";
    int color = 0;
    for (double t : {18.0, 36.0, 60.0}) {
      const std::string lc = " lc " + std::to_string(++color);
      const std::string sel = "(column(\"t\")==" + fmtg(t) + "?column(\"%s\")*1e3:NaN)";
      char u1[200], u2[200];
      std::snprintf(u1, sizeof u1, ("\"x\":" + sel).c_str(), "y1");
      std::snprintf(u2, sizeof u2, ("\"x\":" + sel).c_str(), "y2");
      p.series.push_back({"shapes.csv", u1, "t = " + fmtg(t) + " s", "lines" + lc});
      p.series.push_back({"shapes.csv", u2, "", "lines dt 2" + lc});
    }
    shape.panels.push_back(p);
    f.push_back(shape);
    out::Figure lam{"fig05_sleeve_forces", "Fig. 5: guide-sleeve constraint forces", {}};
    out::Panel q;
    q.ylabel = "lambda_k [N]";
    for (int k = 1; k <= 4; ++k)
      q.series.push_back({runFile(0), "\"t\":\"lambda_" + std::to_string(k) + "\"", "lambda_" + std::to_string(k),
                          k % 2 ? "lines" : "lines dt 2"});
    lam.panels.push_back(q);
    f.push_back(lam);
  } else if (s.name == "preload") {
    disp("fig06_displacements", "Fig. 6: cage lateral and torsional displacement vs total preload (Tb1 = Tb2)");
    lambdas("fig07_lambda1", "Fig. 7: constraint force lambda_1 vs total preload", {1});
  } else if (s.name == "tension-difference") {
    disp("fig08_displacements", "Fig. 8: displacements vs tension difference dT = Tb2 - Tb1 (Tb1 + Tb2 = 6e4 N)");
    lambdas("fig09_sleeve_forces", "Fig. 9: constraint forces vs tension difference", {1, 2, 3, 4});
    f.back().height = 650;
  } else if (s.name == "eccentric-load") {
    disp("fig10_displacements", "Fig. 10: displacements vs eccentric load Fa");
    lambdas("fig11_sleeve_forces", "Fig. 11: constraint forces lambda_1, lambda_3 vs eccentric load", {1, 3});
  } else if (s.name == "mass") {
    disp("fig12_displacements", "Fig. 12: displacements vs cage mass (J in proportion)");
    lambdas("fig13_lambda1", "Fig. 13: constraint force lambda_1 vs cage mass", {1});
  } else {
    disp("sweep_displacements", "displacements, sweep of " + s.key);
    lambdas("sweep_sleeve_forces", "constraint forces, sweep of " + s.key, {1, 2, 3, 4});
    f.back().height = 650;
    out::Figure pk{"sweep_peaks", "peaks vs " + s.key, {}};
    out::Panel a, b;
    a.xlabel = b.xlabel = s.key;
    a.ylabel = "peak [mm]";
    a.series = {{"summary.csv", "\"value\":(column(\"peak_y_c\")*1e3)", "|y_c|", "linespoints"},
                {"summary.csv", "\"value\":(column(\"peak_excursion\")*1e3)", "excursion |y_c -+ h theta|", "linespoints"}};
    b.ylabel = "peak |theta| [mrad]";
    b.series = {{"summary.csv", "\"value\":(column(\"peak_theta\")*1e3)", "|theta|", "linespoints"}};
    pk.panels = {a, b};
    pk.key = "inside top right";
    f.push_back(pk);
  }
  return f;
}

struct PlotState {
  bool enabled = true;
  std::string gnuplot;
  int rendered = 0, failed = 0, skipped = 0;
};

void renderFigures(const std::string& dir, const std::vector<out::Figure>& figs, PlotState& ps) {
  for (const auto& fig : figs) {
    out::writeGnuplotScript(dir, fig);
    if (!ps.enabled || ps.gnuplot.empty()) {
      ++ps.skipped;
      continue;
    }
    std::string err;
    if (out::runGnuplot(ps.gnuplot, dir, fig.name + ".gp", err)) ++ps.rendered;
    else {
      ++ps.failed;
      std::fprintf(stderr, "hoist-study: warning: %s\n", err.c_str());
    }
  }
}

void reportPlots(const PlotState& ps) {
  if (!ps.enabled) {
    std::fprintf(stderr, "hoist-study: --no-plots: wrote %d gnuplot scripts (.gp), no PNGs\n", ps.skipped);
  } else if (ps.gnuplot.empty()) {
    std::fprintf(stderr,
                 "hoist-study: gnuplot not found on PATH: plots SKIPPED (%d .gp scripts written).\n"
                 "  Install it with:  sudo apt-get install gnuplot-nox   then re-run, or render a\n"
                 "  script with:  cd DIR && gnuplot NAME.gp\n",
                 ps.skipped);
  } else if (ps.failed) {
    std::fprintf(stderr, "hoist-study: %d of %d plots failed (see warnings above)\n", ps.failed,
                 ps.failed + ps.rendered);
  }
}

/// A short table of the key metrics on stdout.
void printSummary(const Study& s, const std::vector<RunResult>& runs, const std::vector<MetricSet>& ms) {
  std::printf("%s (paper Figs. %s): %s\n", s.name.c_str(), s.figures.empty() ? "-" : s.figures.c_str(), s.title.c_str());
  std::printf("  %-28s %9s %9s %9s %9s %9s %9s %9s %9s\n", "run", "|y_c|", "|theta|", "excursn",
              "|lam1|", "f_y_c", "fc_theta", "fzc_y_c", "fzc_th");
  std::printf("  %-28s %9s %9s %9s %9s %9s %9s %9s %9s\n", "", "mm", "mrad", "mm", "N", "Hz 5-50s",
              "Hz 5-50s", "Hz 50-60s", "Hz 50-60s");
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (!runs[i].ok()) {
      std::printf("  %-28s FAILED: %s\n", runs[i].spec.label.c_str(), runs[i].error.c_str());
      continue;
    }
    const auto& m = ms[i];
    auto w = [&](const char* name) { return m.has(name) ? m.get(name) : std::nan(""); };
    std::printf("  %-28s %9.4f %9.5f %9.4f %9.3f %9.4f %9.4f %9.4f %9.4f\n", runs[i].spec.label.c_str(),
                w("peak_y_c") * 1e3, w("peak_theta") * 1e3, w("peak_excursion") * 1e3, w("peak_lambda_1"),
                w("f_y_c_uniform"), w("fc_theta_uniform"), w("fzc_y_c_decel"), w("fzc_theta_decel"));
  }
}

int runStudy(const Study& s, const Common& c, const ShaftParams& base, const HoistProfile& profile,
             PlotState& ps) {
  (void)base;
  const fs::path dir = fs::path(c.out_dir) / s.name;
  fs::create_directories(dir / "runs");
  RunOptions opt = runOptions(c, s.runs.front().params);
  if (s.name == "response") opt.shape_times = {18.0, 36.0, 60.0};
  std::vector<RunResult> res;
  {
    Progress prog("hoist-study " + s.name + " (" + std::to_string(s.runs.size()) + " runs)");
    res = runAll(s.runs, profile, opt, c.jobs, std::ref(prog));
  }
  const auto windows = stageWindows(profile);
  std::vector<MetricSet> ms(res.size());
  int failed = 0;
  for (std::size_t i = 0; i < res.size(); ++i) {
    if (!res[i].ok()) {
      ++failed;
      std::fprintf(stderr, "hoist-study: %s: run '%s' failed: %s\n", s.name.c_str(), res[i].spec.label.c_str(),
                   res[i].error.c_str());
      continue;
    }
    ms[i] = runMetrics(res[i], windows);
    out::writeTraceCsv((dir / runFile(i)).string(), res[i].trace);
  }
  out::writeSummaryCsv((dir / "summary.csv").string(), s, res, ms);
  if (!res.empty() && !res.front().shapes.empty())
    out::writeShapesCsv((dir / "shapes.csv").string(), res.front().shapes);
  printSummary(s, res, ms);
  if (failed == 0) renderFigures(dir.string(), figuresFor(s), ps);
  std::printf("  -> %s/ (summary.csv, runs/*.csv, *.gp%s)\n", dir.string().c_str(),
              ps.enabled && !ps.gnuplot.empty() ? ", *.png" : "");
  return failed ? 1 : 0;
}

// ---- advisor ------------------------------------------------------------------------

struct AdviseArgs {
  double clearance = 0.0;
  double max_force = 0.0;
  std::string split_range = "0.3:0.7";
  std::string total_range = "1e4:5e5";
  int samples = 12;
};

int runAdvisor(const AdviseArgs& a, const Common& c, const ShaftParams& base, const HoistProfile& profile,
               PlotState& ps) {
  AdvisorOptions o;
  o.clearance = a.clearance;
  if (a.max_force > 0.0) o.max_sleeve_force = a.max_force;
  std::tie(o.split_min, o.split_max) = parseRange("--split-range", a.split_range);
  std::tie(o.total_min, o.total_max) = parseRange("--total-range", a.total_range);
  o.samples = a.samples;
  o.jobs = c.jobs;
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const RunOptions ro = runOptions(c, base);
  const fs::path dir = fs::path(c.out_dir) / "advise";
  fs::create_directories(dir);
  std::fprintf(stderr, "hoist-study advise: searching Tb1 + Tb2 in [%g, %g] N, split in [%g, %g] (n = %d, initial = %s)\n",
               o.total_min, o.total_max, o.split_min, o.split_max, base.n, toString(base.initial));
  AdvisorResult r = advisePreload(simulationEvaluator(base, profile, ro.sim), o);
  out::writeAdvisorCsv((dir / "advise_curve.csv").string(), r.curve);
  out::writeAdvisorCsv((dir / "advise_split.csv").string(), r.split_scan);
  {
    AdvisorPoint rec{r.total, r.split, r.achieved, r.feasible};
    out::writeAdvisorCsv((dir / "advise_recommended.csv").string(), {rec});
  }
  out::Figure fig{"advise", "preload advisor: peak cage excursion and sleeve force vs total preload", {}};
  out::Panel pe, pf;
  pe.xlabel = pf.xlabel = "total preload Tb1 + Tb2 [kN]";
  pe.ylabel = "peak excursion [mm]";
  pe.extra = "set logscale xy";
  pe.series = {{"advise_curve.csv", "(column(\"total\")/1e3):(column(\"peak_excursion\")*1e3)",
                "max |y_c -+ h theta| (split " + fmtg(std::clamp(0.5, o.split_min, o.split_max)) + ")", "linespoints pt 7 ps 0.6"},
               {"advise_curve.csv", "(column(\"total\")/1e3):(" + fmtg(o.clearance * 1e3) + ")", "clearance", "lines dt 2 lc rgb 'red'"}};
  if (r.feasible)
    pe.series.push_back({"advise_recommended.csv", "(column(\"total\")/1e3):(column(\"peak_excursion\")*1e3)",
                         "recommended", "points pt 9 ps 1.5 lc rgb 'dark-green'"});
  pf.ylabel = "peak |lambda_1..4| [N]";
  pf.extra = "set logscale x";
  pf.series = {{"advise_curve.csv", "(column(\"total\")/1e3):\"peak_sleeve_force\"", "peak sleeve force", "linespoints pt 7 ps 0.6"}};
  if (std::isfinite(o.max_sleeve_force))
    pf.series.push_back({"advise_curve.csv", "(column(\"total\")/1e3):(" + fmtg(o.max_sleeve_force) + ")", "limit", "lines dt 2 lc rgb 'red'"});
  fig.panels = {pe, pf};
  fig.height = 650;
  fig.key = "inside top right";
  renderFigures(dir.string(), {fig}, ps);

  std::printf("preload advisor (clearance %.4g mm", o.clearance * 1e3);
  if (std::isfinite(o.max_sleeve_force)) std::printf(", sleeve force limit %.4g N", o.max_sleeve_force);
  std::printf("; %d simulations)\n", r.evaluations);
  if (!r.feasible) {
    std::printf("  %s\n", r.message.c_str());
    std::printf("  -> %s/ (advise_curve.csv, advise.gp%s)\n", dir.string().c_str(),
                ps.enabled && !ps.gnuplot.empty() ? ", advise.png" : "");
    return 3;
  }
  std::printf("  recommended: Tb1 = %.6g N, Tb2 = %.6g N (total %.6g N, split Tb1/(Tb1+Tb2) = %.3f)\n", r.Tb1,
              r.Tb2, r.total, r.split);
  std::printf("  achieved:    peak excursion %.4g mm, peak sleeve force %.4g N, peak |y_c| %.4g mm, peak |theta| %.4g mrad\n",
              r.achieved.excursion * 1e3, r.achieved.sleeve_force, r.achieved.y_c * 1e3, r.achieved.theta * 1e3);
  std::printf("  %s\n", r.message.c_str());
  std::printf("  -> %s/ (advise_curve.csv, advise_split.csv, advise.gp%s)\n", dir.string().c_str(),
              ps.enabled && !ps.gnuplot.empty() ? ", advise.png" : "");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "hoist-study: the studies of Wang et al. (2016), Section 3 (Figs. 2-13), parameter sweeps and\n"
      "a guide-rope preload advisor, on the hoist-twin model.  Each study writes one CSV per run\n"
      "(t,l,v,a,x_c,y_c,theta,lambda_0..4), a summary.csv of per-run metrics (peaks, RMS, dominant\n"
      "frequencies of y_c/theta/lambda_1 in the uniform-velocity and deceleration/rest stages) and\n"
      "PNG figures rendered by gnuplot (with the .gp script next to each PNG).\n"
      "Exit status: 0 ok, 1 run or file failure, 2 usage/config error, 3 advise: infeasible."};
  app.require_subcommand(1, 1);
  app.fallthrough(false);
  Common c;
  std::vector<std::pair<CLI::App*, std::string>> studies;
  for (const auto& [name, help] : std::vector<std::pair<std::string, std::string>>{
           {"response", "baseline run: Figs. 2 (profile), 3 (x_c, y_c, theta), 4 (guide-rope shapes at 18/36/60 s), 5 (lambda_1..4)"},
           {"preload", "total preload 4.8e4/5.4e4/6e4 N, Tb1 = Tb2: Figs. 6-7"},
           {"tension-difference", "Tb1 + Tb2 = 6e4 N, dT = Tb2 - Tb1 = 0/5000/10000 N: Figs. 8-9"},
           {"eccentric-load", "Fa = 1000/2000/3000 N: Figs. 10-11"},
           {"mass", "(m, J) = (800, 870), (1200, 1305), (1600, 1740): Figs. 12-13"},
           {"all", "all of the paper's studies (response, preload, tension-difference, eccentric-load, mass)"}}) {
    auto* sub = app.add_subcommand(name, help);
    addCommon(sub, c, false);
    studies.emplace_back(sub, name);
  }
  std::string key, values;
  auto* sweep = app.add_subcommand("sweep", "sweep one config key over values (same outputs as a paper study)");
  sweep->add_option("--param", key, "Dotted config key, one of:\n" + parameterHelp())->required();
  sweep->add_option("--values", values, "Comma-separated values, or START:STOP:COUNT")->required();
  addCommon(sweep, c, false);
  AdviseArgs aa;
  auto* advise = app.add_subcommand(
      "advise",
      "preload advisor: smallest total preload Tb1 + Tb2 and best split keeping the cage's peak lateral\n"
      "excursion max|y_c -+ h theta| within --clearance (and peak |lambda_1..4| within --max-sleeve-force)");
  advise->add_option("--clearance", aa.clearance, "Allowed peak lateral excursion of the cage [m]")
      ->required()
      ->check(numberAbove(0, false));
  advise->add_option("--max-sleeve-force", aa.max_force, "Allowed peak sleeve force |lambda_1..4| [N]")
      ->check(numberAbove(0, false));
  advise->add_option("--split-range", aa.split_range, "Range of Tb1 / (Tb1 + Tb2) searched")->capture_default_str();
  advise->add_option("--total-range", aa.total_range, "Range of Tb1 + Tb2 searched [N]")->capture_default_str();
  advise->add_option("--samples", aa.samples, "Log-spaced totals sampled (curve, monotonicity check)")
      ->capture_default_str()
      ->check(CLI::Range(2, 200));
  addCommon(advise, c, true);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  if (c.initial.empty()) c.initial = advise->parsed() ? "config" : "rest";
  PlotState ps;
  ps.enabled = !c.no_plots;
  ps.gnuplot = ps.enabled ? out::findGnuplot() : "";
  try {
    const ShaftParams base = loadParams(c);
    const HoistProfile profile = loadProfile(c, base);
    if (advise->parsed()) {
      const int rc = runAdvisor(aa, c, base, profile, ps);
      reportPlots(ps);
      return rc;
    }
    std::vector<Study> todo;
    if (sweep->parsed()) {
      try {
        todo.push_back(sweepStudy(key, parseValues(values), base));
      } catch (const ParamError& e) {
        throw UsageError(std::string("--param/--values: ") + e.what());
      }
    } else {
      for (const auto& [sub, name] : studies) {
        if (!sub->parsed()) continue;
        if (name == "all") {
          for (const auto& n : paperStudyNames()) todo.push_back(*paperStudy(n, base));
        } else {
          todo.push_back(*paperStudy(name, base));
        }
      }
    }
    int rc = 0;
    for (const auto& s : todo) rc = std::max(rc, runStudy(s, c, base, profile, ps));
    reportPlots(ps);
    return rc;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "hoist-study: error: %s\n", e.what());
    return 2;
  } catch (const ParamError& e) {
    std::fprintf(stderr, "hoist-study: error: invalid parameter %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hoist-study: error: %s\n", e.what());
    return 1;
  }
}
