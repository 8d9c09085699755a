// The figure catalogue: see figures.hpp.
#include "figures.hpp"

#include <cstdio>

#include "cli.hpp"

namespace hoist::study::cli {

std::string runFile(std::size_t i) { return "runs/run" + std::to_string(i + 1) + ".csv"; }

namespace {

out::Panel signalPanel(const Study& s, const std::string& col, const std::string& ylabel, double scale) {
  out::Panel p;
  p.ylabel = ylabel;
  for (std::size_t i = 0; i < s.runs.size(); ++i)
    p.series.push_back({runFile(i), "\"t\":(column(\"" + col + "\")*" + fmtg(scale) + ")",
                        s.runs.size() == 1 ? col : s.runs[i].label});
  return p;
}

}  // namespace

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

}  // namespace hoist::study::cli
