// Running one study: see run_study.hpp.
#include "run_study.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

#include "figures.hpp"
#include "hoist/study/stages.hpp"
#include "output.hpp"
#include "progress.hpp"

namespace fs = std::filesystem;

namespace hoist::study::cli {

namespace {

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

}  // namespace

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
  const bool corr = s.runs.front().params.static_correction;
  std::printf("  static correction %s%s\n", corr ? "on" : "off",
              corr ? "" : " (the paper's truncation: reproduces its figures; --static-correction on for the converged model)");
  if (failed == 0) renderFigures(dir.string(), figuresFor(s), ps);
  std::printf("  -> %s/ (summary.csv, runs/*.csv, *.gp%s)\n", dir.string().c_str(),
              ps.enabled && !ps.gnuplot.empty() ? ", *.png" : "");
  return failed ? 1 : 0;
}

}  // namespace hoist::study::cli
