// What every solver shares (hoist/solver.hpp): the method names, the
// factory, and the guide-rope shapes from a solver's coordinates and loads.
#include "hoist/solver.hpp"

#include "hoist/fast_solver.hpp"
#include "hoist/paper_solver.hpp"

namespace hoist {

const char* toString(Method m) { return m == Method::Fast ? "fast" : "paper"; }

std::unique_ptr<Solver> makeSolver(Method method, std::shared_ptr<const ShaftModel> model) {
  if (method == Method::Paper) return std::make_unique<PaperSolver>(std::move(model));
  return std::make_unique<FastSolver>(std::move(model));
}

void Solver::guideRopeShapes(const VectorXd& x, VectorXd& y1, VectorXd& y2) const {
  VectorXd q1, q2;
  guideRopeCoordinates(q1, q2);
  VectorXd U(q1.size());
  SleeveLoads loads;
  residualSleeveLoads(loads);
  y1.resize(x.size());
  y2.resize(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    model_->guideModes(x(i) / model_->params().L, U);
    y1(i) = U.dot(q1);
    y2(i) = U.dot(q2);
    for (int k = 0; k < loads.count; ++k)
      (loads.rope[k] == 1 ? y1(i) : y2(i)) += model_->guideGreen(loads.rope[k], x(i), loads.x[k]) * loads.f[k];
  }
}

}  // namespace hoist
