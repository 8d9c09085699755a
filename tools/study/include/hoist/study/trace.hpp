// hoist/study/trace.hpp -- one run's recorded time series and guide-rope shapes.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "hoist/solver.hpp"

namespace hoist::study {

/// One run's time series (struct of arrays; rows as in hoist-sim's CSV).
struct Trace {
  std::vector<double> t, l, v, a, x_c, y_c, theta;
  std::array<std::vector<double>, 5> lambda;
  void append(const CageResponse& r);
  void reserve(std::size_t n);
  std::size_t size() const { return t.size(); }
  /// Cage lateral excursion at the top and bottom sleeves, max(|y_c - h theta|,
  /// |y_c + h theta|), per sample.
  std::vector<double> excursion(double h) const;
};

/// Lateral shape of both guide ropes at one instant.
struct Shape {
  double t = 0.0;   ///< requested time
  double l = 0.0;   ///< rope length (cage top) at that instant
  std::vector<double> x, y1, y2;
};

}  // namespace hoist::study
