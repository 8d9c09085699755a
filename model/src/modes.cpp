// Closed-form mode integrals of the hoisting-rope trial functions
// U_i(xi) = sqrt(2) sin(k_i xi), k_i = (2i-1) pi/2, over xi in [0, 1].
// Every product of two trial functions (or their slopes) is a sum of sines or
// cosines of (k_i +- k_j) xi, and k_i +- k_j is a multiple of pi, so the
// polynomial-weighted integrals below are exact (tests compare them against
// composite Gauss-Legendre quadrature).
#include <cmath>

#include "modes_detail.hpp"

namespace hoist::detail {

double intSin(int p, double w) {  // Int_0^1 xi^p sin(w xi)
  if (w == 0.0) return 0.0;
  const double s = std::sin(w), c = std::cos(w);
  switch (p) {
    case 0: return (1.0 - c) / w;
    case 1: return (s - w * c) / (w * w);
    case 2: return -c / w + 2.0 / w * intCos(1, w);
    default: return std::nan("");
  }
}

double intCos(int p, double w) {  // Int_0^1 xi^p cos(w xi)
  if (w == 0.0) return 1.0 / (p + 1);
  const double s = std::sin(w), c = std::cos(w);
  switch (p) {
    case 0: return s / w;
    case 1: return (c + w * s - 1.0) / (w * w);
    case 2: return s / w - 2.0 / w * intSin(1, w);
    default: return std::nan("");
  }
}

// Weighted integral Int_0^1 (c0 + c1 xi + c2 xi^2) f(w xi), f = sin or cos.
static double wSin(const double c[3], double w) { return c[0] * intSin(0, w) + c[1] * intSin(1, w) + c[2] * intSin(2, w); }
static double wCos(const double c[3], double w) { return c[0] * intCos(0, w) + c[1] * intCos(1, w) + c[2] * intCos(2, w); }

// Int poly * U_i U_j'  = k_j Int poly [sin((ki+kj)xi) + sin((ki-kj)xi)]
double intUdU(const double c[3], double ki, double kj) { return kj * (wSin(c, ki + kj) + wSin(c, ki - kj)); }
// Int poly * U_i' U_j = k_i Int poly [sin((ki+kj)xi) - sin((ki-kj)xi)]
double intdUU(const double c[3], double ki, double kj) { return ki * (wSin(c, ki + kj) - wSin(c, ki - kj)); }
// Int poly * U_i' U_j' = ki kj Int poly [cos((ki-kj)xi) + cos((ki+kj)xi)]
double intdUdU(const double c[3], double ki, double kj) { return ki * kj * (wCos(c, ki - kj) + wCos(c, ki + kj)); }

}  // namespace hoist::detail
