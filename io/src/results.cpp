#include "hoist/io/results.hpp"

#include <ostream>

namespace hoist::io {

void writeResultHeader(std::ostream& out) { out << kResultHeader << '\n'; }

void writeResultRow(std::ostream& out, const CageResponse& r) {
  std::string s;
  s.reserve(256);
  appendResultRow(s, r);
  out << s;
}

void appendResultRow(std::string& s, const CageResponse& r) {
  const double cols[] = {r.t,     r.kin.l,     r.kin.v,     r.kin.a,     r.x_c,       r.y_c,
                         r.theta, r.lambda[0], r.lambda[1], r.lambda[2], r.lambda[3], r.lambda[4]};
  bool first = true;
  for (double c : cols) {
    if (!first) s += ',';
    first = false;
    appendNumber(s, c);
  }
  s += '\n';
}

void writeShapeHeader(std::ostream& out) { out << kShapeHeader << '\n'; }

void writeShapeRows(std::ostream& out, double t, const VectorXd& x, const VectorXd& y1, const VectorXd& y2) {
  std::string s;
  appendShapeRows(s, t, x, y1, y2);
  out << s;
}

void appendShapeRows(std::string& s, double t, const VectorXd& x, const VectorXd& y1, const VectorXd& y2) {
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    appendNumber(s, t);
    s += ',';
    appendNumber(s, x[i]);
    s += ',';
    appendNumber(s, y1[i]);
    s += ',';
    appendNumber(s, y2[i]);
    s += '\n';
  }
}

}  // namespace hoist::io
