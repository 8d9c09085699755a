// hoist-trips trend and depth-map (trips.hpp): gnuplot PNGs, as hoist-study
// makes its figures (docs/studies.md).  Beside FILE.png go FILE.dat (the
// data) and FILE.gp (the script: `gnuplot FILE.gp` re-renders it).  Without
// gnuplot the data and script are written and the command fails naming the
// package to install.
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "hoist/history/condition_config.hpp"
#include "hoist/io/checked_file.hpp"
#include "hoist/io/config.hpp"
#include "hoist/preload_trend.hpp"
#include "trips.hpp"

extern char** environ;

namespace hoist::trips {

namespace {

struct PlotFiles {
  std::string png, dat, gp;
};

PlotFiles plotFiles(const std::string& out) {
  if (out.size() < 5 || out.compare(out.size() - 4, 4, ".png") != 0)
    throw UsageError("--out: '" + out + "' must name a .png file");
  if (auto why = io::outputPathError(out, "--out"); !why.empty()) throw UsageError(why);
  const std::string stem = out.substr(0, out.size() - 4);
  return {out, stem + ".dat", stem + ".gp"};
}

std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q += "''";
    else if (c == '\n') q += "' . \"\\n\" . '";  // a line break in a title
    else if (static_cast<unsigned char>(c) >= 0x20) q += c;
  }
  return q + "'";
}

/// `s` with line breaks at spaces so that no line is longer than `width`.
std::string wrap(const std::string& s, std::size_t width) {
  std::string out, line;
  std::istringstream in(s);
  for (std::string w; in >> w;) {
    if (!line.empty() && line.size() + 1 + w.size() > width) out += line + "\n", line.clear();
    line += (line.empty() ? "" : " ") + w;
  }
  return out + line;
}

std::string header(const PlotFiles& f, int w, int h) {
  std::ostringstream s;
  s << "# Written by hoist-trips; re-render with: gnuplot " << f.gp << "\n"
    << "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n  set terminal pngcairo size " << w << "," << h
    << " font ',9'\n} else {\n  set terminal png size " << w << "," << h << "\n}\nset termoption noenhanced\n"
    << "set output " << quoted(std::filesystem::absolute(f.png).string()) << "\n";
  return s.str();
}

/// Runs gnuplot on the script; throws std::runtime_error when it is missing
/// or fails, or wrote no image.
void render(const PlotFiles& f) {
  std::string gnuplot;
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(ss, dir, ':');)
    if (!dir.empty() && ::access((dir + "/gnuplot").c_str(), X_OK) == 0) {
      gnuplot = dir + "/gnuplot";
      break;
    }
  if (gnuplot.empty())
    throw std::runtime_error("gnuplot not found (sudo apt-get install gnuplot-nox); the data and script are in " +
                             f.dat + " and " + f.gp);
  std::filesystem::remove(f.png);
  const std::string script = std::filesystem::absolute(f.gp).string();
  char* argv[] = {const_cast<char*>("gnuplot"), const_cast<char*>(script.c_str()), nullptr};
  pid_t pid = -1;
  if (posix_spawn(&pid, gnuplot.c_str(), nullptr, nullptr, argv, environ) != 0)
    throw std::runtime_error("cannot run " + gnuplot);
  int st = 0;
  while (::waitpid(pid, &st, 0) < 0) {
  }
  struct stat sb {};
  if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) throw std::runtime_error("gnuplot " + f.gp + " failed");
  if (::stat(f.png.c_str(), &sb) != 0 || sb.st_size == 0) throw std::runtime_error("gnuplot " + f.gp + " wrote no image");
}

}  // namespace

int runTrend(const Options& o) {
  const PlotFiles f = plotFiles(o.out);
  auto db = openDb(o, true);
  const auto recs = selected(*db, o, false);
  // The combined estimate (the daemon's GUIDE_PRELOAD_LOW filter, hoist/preload_trend.hpp) after each trip.
  ConditionSettings cond;
  if (!o.config.empty()) cond = history::conditionSettingsFromToml(io::loadTomlFile(o.config), o.config);
  PreloadTrend trend(cond);
  io::CheckedFile dat(f.dat, "--out (data)");
  dat.write("# trip informative s sigma_s s_lo95 s_hi95 trend trend_lo95 trend_hi95 (hoist-trips trend, " +
            db->describe() + ")\n");
  int informative = 0, attempted = 0;
  for (const auto& r : recs) {
    trend.add(r);
    if (!r.id.attempted || r.id.sigma_scale < 0) continue;
    ++attempted;
    informative += r.id.informative;
    const double s = r.id.scale, sg = r.id.sigma_scale;
    const double ts = trend.valid() ? trend.scale() : std::nan(""), tsg = trend.sigma();
    dat.printf("%lld %d %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", static_cast<long long>(r.trip), r.id.informative ? 1 : 0,
               s, sg, s - 1.96 * sg, s + 1.96 * sg, ts, ts - 1.96 * tsg, ts + 1.96 * tsg);
  }
  dat.close();
  const double warn = o.warning >= 0 ? o.warning : cond.preload_warning;
  const double crit = o.critical >= 0 ? o.critical : cond.preload_critical;
  const auto decision = trend.decision();
  io::CheckedFile gp(f.gp, "--out (script)");
  gp.write(header(f, 1000, 560));
  const std::string d = quoted(std::filesystem::absolute(f.dat).string());
  gp.printf("set title %s\n", quoted("Guide-rope preload scale, shaft " + (o.shaft.empty() ? std::string("(default)") : o.shaft) +
                                     ": " + std::to_string(informative) + " of " + std::to_string(attempted) +
                                     " identified trips informative\n" + wrap(decision.text, 130)).c_str());
  gp.write("set xlabel 'trip'\nset ylabel 'preload scale s (1 = configured)'\nset grid\nset key bottom left\n"
           "set yrange [0:1.3]\n");
  gp.printf("set arrow from graph 0, first %.6g to graph 1, first %.6g nohead dt 2 lc rgb '#d08000' lw 2\n", warn, warn);
  gp.printf("set arrow from graph 0, first %.6g to graph 1, first %.6g nohead dt 2 lc rgb '#c00000' lw 2\n", crit, crit);
  gp.printf("set label 'preload_warning %.2f' at graph 0.01, first %.6g offset 0,0.6 tc rgb '#d08000' front\n", warn, warn);
  gp.printf("set label 'preload_critical %.2f' at graph 0.01, first %.6g offset 0,0.6 tc rgb '#c00000' front\n", crit, crit);
  if (attempted == 0) {
    gp.write("set label 'no trip with an identified preload' at graph 0.5, graph 0.5 center\n"
             "set xrange [0:1]\nplot 1 with lines lc rgb '#808080' title 'nominal'\n");
  } else {
    gp.printf("plot %s using 1:8:9 with filledcurves lc rgb '#c8d8f0' "
              "title 'combined estimate: 95 %% band', \\\n"
              "     %s using 1:7 with lines lw 2 lc rgb '#1f4e9c' title 'combined estimate (weighted by information)', \\\n"
              "     %s using 1:($2 > 0 ? $3 : NaN):4 with yerrorbars pt 7 ps 0.7 lc rgb '#1f4e9c' "
              "title 'trip: s +- sigma (informative)', \\\n"
              "     %s using 1:($2 > 0 ? NaN : $3) with points pt 6 lc rgb '#909090' "
              "title 'not informative (sigma above max_sigma)', \\\n"
              "     1 with lines lc rgb '#808080' dt 3 title 'nominal'\n",
              d.c_str(), d.c_str(), d.c_str(), d.c_str());
  }
  gp.close();
  render(f);
  if (!o.quiet)
    std::cerr << "hoist-trips: trend of " << attempted << " trip(s) (" << informative << " informative) in " << f.png
              << " (data " << f.dat << ", script " << f.gp << "). " << decision.text << "\n";
  return 0;
}

int runDepthMap(const Options& o) {
  const PlotFiles f = plotFiles(o.out);
  auto db = openDb(o, true);
  const auto recs = selected(*db, o, true);
  // The grid: every trip x every bin depth seen; a cell without data is NaN
  // (gnuplot leaves it blank).
  std::set<long long> depths_mm;
  double bin = 10.0;
  for (const auto& r : recs) {
    bin = r.depth_bin;
    for (const auto& b : r.bins) depths_mm.insert(std::llround(b.depth_lo * 1000.0));
  }
  io::CheckedFile dat(f.dat, "--out (data)");
  dat.write("# trip depth_mid " + o.value + " (hoist-trips depth-map, " + db->describe() + ")\n");
  for (const auto& r : recs) {
    std::map<long long, const DepthBinStats*> by;
    for (const auto& b : r.bins) by[std::llround(b.depth_lo * 1000.0)] = &b;
    for (long long mm : depths_mm) {
      const auto it = by.find(mm);
      double v = std::nan("");
      if (it != by.end() && it->second->samples > 0)
        v = o.value == "resid_mean" ? it->second->resid_mean
            : o.value == "fy_rms"   ? it->second->fy_rms
            : o.value == "fy_hf_rms" ? it->second->fy_hf_rms
                                     : it->second->resid_rms;
      dat.printf("%lld %.6g %.9g\n", static_cast<long long>(r.trip), mm / 1000.0 + 0.5 * r.depth_bin, v);
    }
    dat.write("\n");
  }
  dat.close();
  io::CheckedFile gp(f.gp, "--out (script)");
  gp.write(header(f, 1000, 700));
  const std::string shaft = o.shaft.empty() ? std::string("(default)") : o.shaft;
  gp.printf("set title %s\n", quoted("Depth x trip: " + o.value + " of the lateral acceleration f_y, shaft " + shaft + ", " +
                                     std::to_string(recs.size()) + " trips, bins of " + num(bin, 4) + " m").c_str());
  gp.write("set xlabel 'trip'\nset ylabel 'depth l [m]'\nset yrange [*:*] reverse\nset cblabel " +
           quoted(o.value + " [m/s^2]") + "\n");
  if (o.value == "resid_mean")  // signed: a diverging palette, symmetric about zero
    gp.write("set palette defined (-1 '#2166ac', 0 '#f7f7f7', 1 '#b2182b')\n");
  else
    gp.write("set palette defined (0 '#fff5eb', 0.5 '#fd8d3c', 1 '#7f2704')\n");
  if (!recs.empty())
    gp.printf("set xrange [%.1f:%.1f]\n", recs.front().trip - 0.5, recs.back().trip + 0.5);
  if (o.value == "resid_mean" && !depths_mm.empty())
    gp.printf("stats %s using 3 nooutput\nhoist_m = (abs(STATS_min) > abs(STATS_max) ? abs(STATS_min) : abs(STATS_max))\n"
              "if (hoist_m > 0) set cbrange [-hoist_m:hoist_m]\n",
              quoted(std::filesystem::absolute(f.dat).string()).c_str());
  if (recs.empty() || depths_mm.empty())
    gp.write("set label 'no trips with depth bins' at graph 0.5, graph 0.5 center\nset xrange [0:1]\nset yrange [0:1]\n"
             "plot NaN notitle\n");
  else
    gp.printf("set style fill solid 1.0 noborder\nplot %s using 1:2:(0.5):(%.6g):3 with boxxyerror fc palette notitle\n",
              quoted(std::filesystem::absolute(f.dat).string()).c_str(), 0.5 * bin);
  gp.close();
  render(f);
  if (!o.quiet)
    std::cerr << "hoist-trips: depth map of " << recs.size() << " trip(s) x " << depths_mm.size() << " depth bins in "
              << f.png << "\n";
  return 0;
}

}  // namespace hoist::trips
