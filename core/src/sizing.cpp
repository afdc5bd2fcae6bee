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
  const double size = options.epsilon * local_length(complex, x, cell);
  return std::clamp(size, options.min_size, options.max_size);
}

}  // namespace skinmesh
