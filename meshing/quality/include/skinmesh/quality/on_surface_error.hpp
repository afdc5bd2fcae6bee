// How far mesh vertices are from the skin, measured by the oracle of
// docs/math.md section 2 (one convex minimisation per point), which is
// independent of the mixed complex the mesher works on.
#pragma once

#include "skinmesh/core/balls.hpp"

#include <Eigen/Core>

#include <vector>

namespace skinmesh {

struct SurfaceError {
  double max = 0.0, mean = 0.0;  // Angstrom: |F(x)| / |grad F(x)| over the vertices
  long uncertified = 0;          // vertices where the oracle could not certify its answer
};

// In parallel over the vertices.
SurfaceError on_surface_error(const std::vector<Eigen::Vector3d>& vertices, const std::vector<Ball>& balls,
                              double shrink);

}  // namespace skinmesh
