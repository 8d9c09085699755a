// Rendering figures with gnuplot: see plots.hpp.
#include "plots.hpp"

#include <cstdio>

namespace hoist::study::cli {

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

}  // namespace hoist::study::cli
