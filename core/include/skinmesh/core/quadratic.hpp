// Real roots of a t^2 + b t + c in the numerically stable form (no
// cancellation between -b and the root of the discriminant), ascending.
// A quadratic whose |a| is at most linear_below * (|a| + |b| + |c|) is
// solved as the line b t + c. Returns how many roots were written (0-2).
#pragma once

#include <algorithm>
#include <cmath>

namespace skinmesh {

inline int quadratic_roots(double a, double b, double c, double linear_below, double roots[2]) {
  const double scale = std::abs(a) + std::abs(b) + std::abs(c);
  if (std::abs(a) <= linear_below * scale) {
    if (b == 0.0) return 0;
    roots[0] = -c / b;
    return 1;
  }
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return 0;
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  int count = 0;
  roots[count++] = q / a;
  if (q != 0.0) roots[count++] = c / q;
  if (count == 2 && roots[0] > roots[1]) std::swap(roots[0], roots[1]);
  return count;
}

}  // namespace skinmesh
