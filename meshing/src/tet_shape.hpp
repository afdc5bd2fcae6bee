// The shape measures of one tetrahedron, shared by the grader and the
// smoother so that both judge a tetrahedron the same way.
#pragma once

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace skinmesh::detail {

struct TetShape {
  double volume = 0;        // signed: positive for a positively oriented tetrahedron
  double radius_edge = 0;   // circumradius / shortest edge (infinite when flat)
  double min_dihedral = 0;  // degrees
  double max_dihedral = 0;  // degrees
};

inline TetShape tet_shape(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                          const Eigen::Vector3d& p3) {
  const Eigen::Vector3d p[4] = {p0, p1, p2, p3};
  TetShape s;
  s.volume = (p1 - p0).dot((p2 - p0).cross(p3 - p0)) / 6.0;
  if (!(s.volume != 0)) {
    s.radius_edge = INFINITY;
    return s;
  }
  // Circumcentre relative to p0: 2 (p_i - p0) . c = |p_i - p0|^2.
  Eigen::Matrix3d A;
  Eigen::Vector3d rhs;
  for (int i = 1; i < 4; ++i) {
    A.row(i - 1) = 2.0 * (p[i] - p[0]).transpose();
    rhs[i - 1] = (p[i] - p[0]).squaredNorm();
  }
  const double radius = A.fullPivLu().solve(rhs).norm();
  double shortest = INFINITY;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) shortest = std::min(shortest, (p[i] - p[j]).norm());
  s.radius_edge = radius / shortest;
  // Outward normal of the face opposite each vertex; the dihedral angle at
  // the edge shared by faces k and l is pi minus the angle of their normals.
  Eigen::Vector3d n[4];
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d& a = p[(k + 1) % 4];
    const Eigen::Vector3d& b = p[(k + 2) % 4];
    const Eigen::Vector3d& c = p[(k + 3) % 4];
    n[k] = (b - a).cross(c - a).normalized();
    if (n[k].dot(p[k] - a) > 0) n[k] = -n[k];
  }
  s.min_dihedral = 180;
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l) {
      const double angle = 180.0 - std::acos(std::clamp(n[k].dot(n[l]), -1.0, 1.0)) * 180.0 / M_PI;
      s.min_dihedral = std::min(s.min_dihedral, angle);
      s.max_dihedral = std::max(s.max_dihedral, angle);
    }
  return s;
}

}  // namespace skinmesh::detail
