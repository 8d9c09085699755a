// hoist/io/results.hpp -- hoist-sim's output files.
//
// Result CSV: header `t,l,v,a,x_c,y_c,theta,lambda_0,...,lambda_4`, one row per
// output step.  Shape CSV: header `t,x,y1,y2`, one row per depth x for each
// requested time.  Doubles are written in shortest round-trip form, so
// reading a file back gives exactly the numbers computed.
#pragma once

#include <iosfwd>
#include <string>

#include "hoist/solver.hpp"

namespace hoist::io {

/// The fixed first columns of every cage-response CSV (hoist-sim, hoist-log2csv).
inline constexpr const char* kResultHeader =
    "t,l,v,a,x_c,y_c,theta,lambda_0,lambda_1,lambda_2,lambda_3,lambda_4";

void writeResultHeader(std::ostream& out);
void writeResultRow(std::ostream& out, const CageResponse& r);
/// The same row appended to `s` (streaming writers).
void appendResultRow(std::string& s, const CageResponse& r);

inline constexpr const char* kShapeHeader = "t,x,y1,y2";
void writeShapeHeader(std::ostream& out);
/// Rows t,x(i),y1(i),y2(i) for all i.
void writeShapeRows(std::ostream& out, double t, const VectorXd& x, const VectorXd& y1, const VectorXd& y2);
void appendShapeRows(std::string& s, double t, const VectorXd& x, const VectorXd& y1, const VectorXd& y2);

/// Append the shortest round-trip decimal form of v to `s`.
void appendNumber(std::string& s, double v);

}  // namespace hoist::io
