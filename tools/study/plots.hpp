// plots.hpp -- rendering the figures with gnuplot (when it is installed) and
// saying what was and was not rendered.
#pragma once

#include <string>
#include <vector>

#include "output.hpp"

namespace hoist::study::cli {

struct PlotState {
  bool enabled = true;
  std::string gnuplot;
  int rendered = 0, failed = 0, skipped = 0;
};

/// Write each figure's .gp script in `dir` and render it if gnuplot is there.
void renderFigures(const std::string& dir, const std::vector<out::Figure>& figs, PlotState& ps);
/// One line on stderr about plots skipped or failed.
void reportPlots(const PlotState& ps);

}  // namespace hoist::study::cli
