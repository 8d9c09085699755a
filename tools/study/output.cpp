#include "output.hpp"

#include "hoist/io/checked_file.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace hoist::study::out {
namespace {

std::string csvQuote(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string gpQuote(const std::string& s) {  // single-quoted gnuplot string
  std::string q;
  for (char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
  return "'" + q + "'";
}

}  // namespace

void writeTraceCsv(const std::string& path, const Trace& tr) {
  io::CheckedFile f(path);
  f.printf("t,l,v,a,x_c,y_c,theta,lambda_0,lambda_1,lambda_2,lambda_3,lambda_4\n");
  for (std::size_t i = 0; i < tr.size(); ++i)
    f.printf("%.6g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", tr.t[i],
                 tr.l[i], tr.v[i], tr.a[i], tr.x_c[i], tr.y_c[i], tr.theta[i], tr.lambda[0][i],
                 tr.lambda[1][i], tr.lambda[2][i], tr.lambda[3][i], tr.lambda[4][i]);
  f.close();
}

void writeShapesCsv(const std::string& path, const std::vector<Shape>& shapes) {
  io::CheckedFile f(path);
  f.printf("t,x,y1,y2\n");
  for (const auto& s : shapes) {
    for (std::size_t i = 0; i < s.x.size(); ++i)
      f.printf("%.6g,%.9g,%.9g,%.9g\n", s.t, s.x[i], s.y1[i], s.y2[i]);
  }
  f.close();
}

void writeSummaryCsv(const std::string& path, const Study& study, const std::vector<RunResult>& runs,
                     const std::vector<MetricSet>& metrics) {
  io::CheckedFile f(path);
  f.printf("run,label,key,value,Tb1,Tb2,m,J,Fa,b,n,initial,status");
  const MetricSet* first = nullptr;
  for (const auto& m : metrics)
    if (!m.items().empty()) {
      first = &m;
      break;
    }
  if (first)
    for (const auto& kv : first->items()) f.printf(",%s", kv.first.c_str());
  f.printf("\n");
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const auto& r = runs[i];
    const auto& p = r.spec.params;
    f.printf("%zu,%s,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%s,%s", i + 1,
                 csvQuote(r.spec.label).c_str(), csvQuote(study.key).c_str(), r.spec.value, p.Tb1,
                 p.Tb2, p.m, p.J, p.Fa, p.b, p.n, toString(p.initial),
                 r.ok() ? "ok" : csvQuote("failed: " + r.error).c_str());
    if (first)
      for (const auto& kv : first->items())
        f.printf(",%.9g", metrics[i].has(kv.first) ? metrics[i].get(kv.first) : std::nan(""));
    f.printf("\n");
  }
  f.close();
}

void writeAdvisorCsv(const std::string& path, const std::vector<AdvisorPoint>& pts) {
  io::CheckedFile f(path);
  f.printf("total,split,Tb1,Tb2,peak_excursion,peak_sleeve_force,peak_y_c,peak_theta,feasible\n");
  for (const auto& p : pts)
    f.printf("%.9g,%.6g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d\n", p.total, p.split,
                 p.split * p.total, (1.0 - p.split) * p.total, p.peaks.excursion, p.peaks.sleeve_force,
                 p.peaks.y_c, p.peaks.theta, p.feasible ? 1 : 0);
  f.close();
}

void writeGnuplotScript(const std::string& dir, const Figure& fig) {
  const std::string path = (std::filesystem::path(dir) / (fig.name + ".gp")).string();
  io::CheckedFile f(path);
  const int rows = static_cast<int>((fig.panels.size() + static_cast<std::size_t>(fig.cols) - 1) /
                                    static_cast<std::size_t>(fig.cols));
  f.printf("# %s\n# Written by hoist-study; re-render with:  cd %s && gnuplot %s.gp\n",
               fig.title.c_str(), dir.c_str(), fig.name.c_str());
  f.printf(
               "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
               "  set terminal pngcairo size %d,%d font ',9' linewidth 1.2\n"
               "} else {\n  set terminal png size %d,%d\n}\nset termoption noenhanced\n",
               fig.width, fig.height, fig.width, fig.height);
  // hoist-study runs the script with hoist_output='-': the PNG comes on
  // gnuplot's stdout and is written by hoist-study's checked writer
  // (runGnuplot); run by hand, gnuplot writes NAME.png itself.
  f.printf("if (!exists('hoist_output')) hoist_output = %s\n"
           "if (hoist_output eq '-') { set output } else { set output hoist_output }\n"
           "set datafile separator ','\nset grid\nset key %s samplen 2\n",
           gpQuote(fig.name + ".png").c_str(), fig.key.c_str());
  f.printf("set multiplot layout %d,%d title %s\n", rows, fig.cols, gpQuote(fig.title).c_str());
  for (const auto& p : fig.panels) {
    f.printf("set xlabel %s\nset ylabel %s\n", gpQuote(p.xlabel).c_str(), gpQuote(p.ylabel).c_str());
    if (!p.extra.empty()) f.printf("%s\n", p.extra.c_str());
    f.printf("plot ");
    for (std::size_t i = 0; i < p.series.size(); ++i) {
      const auto& s = p.series[i];
      f.printf("%s%s using %s with %s title %s", i ? ", \\\n     " : "", gpQuote(s.file).c_str(),
                   s.using_.c_str(), s.style.c_str(), gpQuote(s.title).c_str());
    }
    f.printf("\n");
    if (!p.extra.empty()) f.printf("unset logscale; unset arrow; unset label; set autoscale\n");
  }
  f.printf("unset multiplot\n");
  f.close();
}

std::string findGnuplot() {
  const char* env = std::getenv("PATH");
  std::stringstream ss(env ? env : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) continue;
    const std::string p = dir + "/gnuplot";
    if (::access(p.c_str(), X_OK) == 0) return p;
  }
  return "";
}

bool runGnuplot(const std::string& gnuplot, const std::string& dir, const std::string& script,
                std::string& err) {
  // The PNG is written by us (io::CheckedFile: a fresh temporary file, never
  // a device node, FIFO or planted symlink at NAME.png), from gnuplot's stdout.
  std::string png = script;
  if (png.size() > 3 && png.compare(png.size() - 3, 3, ".gp") == 0) png.resize(png.size() - 3);
  png = (std::filesystem::path(dir) / (png + ".png")).string();
  std::optional<io::CheckedFile> out;
  try {
    out.emplace(png);
  } catch (const io::WriteError& e) {
    err = e.what();
    return false;
  }
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    err = std::string("pipe failed: ") + std::strerror(errno);
    return false;
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    err = std::string("fork failed: ") + std::strerror(errno);
    ::close(fds[0]);
    ::close(fds[1]);
    return false;
  }
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(126);
    // gnuplot's own warnings go to our stderr; its stdout is the PNG.
    if (::dup2(fds[1], STDOUT_FILENO) < 0) ::_exit(126);
    ::execl(gnuplot.c_str(), "gnuplot", "-e", "hoist_output='-'", script.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(fds[1]);
  std::string write_err;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    if (!write_err.empty()) continue;  // drain, so gnuplot is not blocked
    try {
      out->write(std::string_view(buf, static_cast<std::size_t>(n)));
    } catch (const io::WriteError& e) {
      write_err = e.what();
    }
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) {
      err = std::string("waitpid failed: ") + std::strerror(errno);
      return false;
    }
  if (!write_err.empty()) {
    err = write_err;
    return false;
  }
  if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
    err = "gnuplot " + script + " in " + dir + " failed (status " +
          std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
    return false;
  }
  if (out->bytes() == 0) {
    err = "gnuplot " + script + " in " + dir + " wrote no image";
    return false;
  }
  try {
    out->close();
  } catch (const io::WriteError& e) {
    err = e.what();
    return false;
  }
  return true;
}

}  // namespace hoist::study::out
