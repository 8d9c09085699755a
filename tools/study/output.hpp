// output.hpp -- hoist-study's I/O: CSV files and gnuplot scripts/PNGs.
#pragma once

#include <string>
#include <vector>

#include "hoist/study/advisor.hpp"
#include "hoist/study/sweep.hpp"

namespace hoist::study::out {

/// Throws std::runtime_error naming the file on failure.
void writeTraceCsv(const std::string& path, const Trace& tr);
/// Columns t,x,y1,y2 (hoist-sim's shape file) for every shape.
void writeShapesCsv(const std::string& path, const std::vector<Shape>& shapes);
/// One row per run: identification columns, then every metric.
void writeSummaryCsv(const std::string& path, const Study& study,
                     const std::vector<RunResult>& runs, const std::vector<MetricSet>& metrics);
void writeAdvisorCsv(const std::string& path, const std::vector<AdvisorPoint>& pts);

/// One curve of a panel: `file` (relative to the script), gnuplot `using`.
struct Series {
  std::string file, using_, title, style = "lines";
};
struct Panel {
  std::string ylabel, xlabel = "t [s]";
  std::vector<Series> series;
  std::string extra;  ///< raw gnuplot lines set before this panel's plot (e.g. logscale, arrows)
};
struct Figure {
  std::string name;   ///< file stem: name.gp, name.png
  std::string title;
  std::vector<Panel> panels;
  int cols = 1;       ///< multiplot columns
  int width = 800, height = 500;
  std::string key = "outside right top";  ///< gnuplot "set key" arguments
};

/// Writes dir/name.gp (renders dir/name.png when run with cwd = dir).
void writeGnuplotScript(const std::string& dir, const Figure& fig);

/// Path of a gnuplot executable on PATH, or "" if none.
std::string findGnuplot();
/// Runs `gnuplot script` with cwd = dir as a subprocess; returns false (and
/// fills `err`) on failure.
bool runGnuplot(const std::string& gnuplot, const std::string& dir, const std::string& script,
                std::string& err);

}  // namespace hoist::study::out
