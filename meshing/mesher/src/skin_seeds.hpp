// Seeds for the mesher: points on every connected component of the skin.
#pragma once

#include "skinmesh/core/skin_complex.hpp"

#include <Eigen/Core>

#include <vector>

namespace skinmesh::detail {

struct SkinPoint {
  Eigen::Vector3d point;
  int cell = -1;
};

// The points where the skin's outward normal is d, for four fixed, generic
// directions d (a turned regular tetrahedron). The Gauss map of every closed
// surface is onto the sphere (take the highest or the lowest point in direction
// d), so every component, cavities included, gets at least four seeds, whatever
// its size. Found per mixed cell in closed form: on the quadric of cell X the
// normal is d exactly at z_X + alpha M^-1 d, alpha > 0, with
// M = (1-s)(I-P) - sP (docs/math.md section 3).
std::vector<SkinPoint> critical_point_seeds(const SkinComplex& complex);

}  // namespace skinmesh::detail
