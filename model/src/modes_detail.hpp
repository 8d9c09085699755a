#pragma once
// Internal closed forms for the hoisting-rope mode integrals (see modes.cpp).
namespace hoist::detail {
double intSin(int p, double w);
double intCos(int p, double w);
double intUdU(const double c[3], double ki, double kj);
double intdUU(const double c[3], double ki, double kj);
double intdUdU(const double c[3], double ki, double kj);
}  // namespace hoist::detail
