#include "skinmesh/core/sizing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace skinmesh {

double local_length(const SkinComplex& complex, const Eigen::Vector3d& x, int cell) {
  const double k = complex.max_abs_curvature(x, cell);
  return k > 0 ? 1.0 / k : std::numeric_limits<double>::infinity();
}

double target_size(const SkinComplex& complex, const Eigen::Vector3d& x, int cell, const SizingOptions& options) {
  return size_for_length(local_length(complex, x, cell), options);
}

double size_for_length(double length, const SizingOptions& options) {
  return std::clamp(options.epsilon * length, options.min_size, options.max_size);
}

}  // namespace skinmesh
