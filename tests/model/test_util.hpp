// Shared helpers for the model tests: Gauss-Legendre quadrature (an
// independent way to evaluate the mode integrals), CSV reading, norms.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <fstream>
#include <functional>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hoist::test {

/// Gauss-Legendre nodes/weights on [-1, 1] by Newton iteration on P_m.
inline void gaussLegendre(int m, std::vector<double>& x, std::vector<double>& w) {
  x.assign(m, 0.0);
  w.assign(m, 0.0);
  for (int i = 0; i < m; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (m + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= m; ++k) {
        const double p2 = ((2.0 * k - 1) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (m == 1) p0 = 1;
      dp = m * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    x[i] = z;
    w[i] = 2.0 / ((1 - z * z) * dp * dp);
  }
}

/// Composite Gauss-Legendre on [a, b] with `panels` panels of `m` points.
inline double integrate(const std::function<double(double)>& f, double a, double b, int panels, int m = 10) {
  std::vector<double> x, w;
  gaussLegendre(m, x, w);
  double s = 0;
  const double hp = (b - a) / panels;
  for (int p = 0; p < panels; ++p) {
    const double c = a + (p + 0.5) * hp;
    for (int i = 0; i < m; ++i) s += w[i] * f(c + 0.5 * hp * x[i]);
  }
  return 0.5 * hp * s;
}

struct Table {
  std::vector<std::string> cols;
  std::vector<std::vector<double>> rows;
  int col(const std::string& name) const {
    for (size_t i = 0; i < cols.size(); ++i)
      if (cols[i] == name) return static_cast<int>(i);
    throw std::runtime_error("no column " + name);
  }
  std::vector<double> column(const std::string& name) const {
    const int c = col(name);
    std::vector<double> v;
    for (const auto& r : rows) v.push_back(r[c]);
    return v;
  }
};

inline Table readCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  Table t;
  std::string line;
  std::getline(in, line);
  {
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, ',')) t.cols.push_back(c);
  }
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, ',')) row.push_back(std::stod(c));
    t.rows.push_back(row);
  }
  return t;
}

/// RMS(a - b) / RMS(b).
inline double nrms(const std::vector<double>& a, const std::vector<double>& b) {
  double se = 0, sr = 0;
  for (size_t i = 0; i < b.size(); ++i) {
    se += (a[i] - b[i]) * (a[i] - b[i]);
    sr += b[i] * b[i];
  }
  return std::sqrt(se / sr);
}

inline std::string dataDir() { return HOIST_TEST_DATA_DIR; }

}  // namespace hoist::test
