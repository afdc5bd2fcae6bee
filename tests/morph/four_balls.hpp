// Four balls of weight 6.1 A^2 at the corners of a tetrahedron about the
// origin, at distance about l from it (off regular by a few hundredths of
// an Angstrom). Their orthogonal sphere's R2 is about l^2 - 6.1: past
// l = 2.47 A they hold a void about the origin, in the tetrahedron's mixed
// cell while its radius sqrt(R2 / 2) stays under the cell's inradius l / 6
// (shrink factor 1/2).
#pragma once

#include "skinmesh/core/balls.hpp"

#include <array>
#include <cmath>
#include <vector>

namespace skinmesh::test {

inline std::vector<Ball> tetrahedron_of_balls(double l) {
  const std::array<Eigen::Vector3d, 4> corners{Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, -1),
                                               Eigen::Vector3d(-1, 1, -1), Eigen::Vector3d(-1, -1, 1)};
  std::vector<Ball> balls;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d off = 0.01 * Eigen::Vector3d(std::sin(1.3 * k), std::cos(2.1 * k), std::sin(0.7 * k + 1));
    balls.push_back({l * corners[static_cast<size_t>(k)].normalized() + off, 6.1});
  }
  return balls;
}

}  // namespace skinmesh::test
