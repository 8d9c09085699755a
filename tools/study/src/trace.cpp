// One run's time series: see hoist/study/trace.hpp.
#include "hoist/study/trace.hpp"

#include <algorithm>
#include <cmath>

namespace hoist::study {

void Trace::append(const CageResponse& r) {
  t.push_back(r.t);
  l.push_back(r.kin.l);
  v.push_back(r.kin.v);
  a.push_back(r.kin.a);
  x_c.push_back(r.x_c);
  y_c.push_back(r.y_c);
  theta.push_back(r.theta);
  for (int k = 0; k < 5; ++k) lambda[k].push_back(r.lambda[k]);
}

void Trace::reserve(std::size_t n) {
  for (auto* vec : {&t, &l, &v, &a, &x_c, &y_c, &theta}) vec->reserve(n);
  for (auto& vec : lambda) vec.reserve(n);
}

std::vector<double> Trace::excursion(double h) const {
  std::vector<double> e(size());
  for (std::size_t i = 0; i < size(); ++i)
    e[i] = std::max(std::abs(y_c[i] - h * theta[i]), std::abs(y_c[i] + h * theta[i]));
  return e;
}

}  // namespace hoist::study
