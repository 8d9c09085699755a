// The preload advisor subcommand: see advise.hpp.
#include "advise.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <tuple>

#include "hoist/study/advisor.hpp"
#include "output.hpp"

namespace fs = std::filesystem;

namespace hoist::study::cli {

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
  std::fprintf(stderr,
               "hoist-study advise: searching Tb1 + Tb2 in [%g, %g] N, split in [%g, %g] (n = %d, initial = %s, "
               "static correction %s)\n",
               o.total_min, o.total_max, o.split_min, o.split_max, base.n, toString(base.initial),
               base.static_correction ? "on" : "off");
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

}  // namespace hoist::study::cli
