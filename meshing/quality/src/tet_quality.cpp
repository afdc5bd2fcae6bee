// Grading tetrahedral meshes (see tet_quality.hpp).
#include "skinmesh/quality/tet_quality.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace skinmesh {

double signed_tet_volume(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                         const Eigen::Vector3d& p3) {
  return (p1 - p0).dot((p2 - p0).cross(p3 - p0)) / 6.0;
}

TetShape tet_shape(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                          const Eigen::Vector3d& p3) {
  const Eigen::Vector3d p[4] = {p0, p1, p2, p3};
  TetShape s;
  s.volume = signed_tet_volume(p0, p1, p2, p3);
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

double region_volume(const TetMesh& mesh, int region) {
  double v = 0;
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    if (mesh.tet_region[i] != region) continue;
    const auto& t = mesh.tets[i];
    v += signed_tet_volume(mesh.points[static_cast<size_t>(t[0])], mesh.points[static_cast<size_t>(t[1])],
                           mesh.points[static_cast<size_t>(t[2])], mesh.points[static_cast<size_t>(t[3])]);
  }
  return v;
}

TetQuality grade_tet_mesh(const TetMesh& mesh) {
  TetQuality q;
  q.points = static_cast<long>(mesh.points.size());
  q.tets = static_cast<long>(mesh.tets.size());
  q.min_dihedral = 180;
  q.min_dihedral_off_boundary = 180;
  std::vector<char> on_boundary(mesh.points.size(), 0);
  for (const auto& f : mesh.faces)
    for (int v : f) on_boundary[static_cast<size_t>(v)] = 1;
  for (const auto& t : mesh.tets) {
    const TetShape s =
        tet_shape(mesh.points[static_cast<size_t>(t[0])], mesh.points[static_cast<size_t>(t[1])],
                          mesh.points[static_cast<size_t>(t[2])], mesh.points[static_cast<size_t>(t[3])]);
    q.volume += s.volume;
    if (!(s.volume > 0)) {
      ++q.inverted;
      continue;
    }
    const bool inner = !on_boundary[static_cast<size_t>(t[0])] && !on_boundary[static_cast<size_t>(t[1])] &&
                       !on_boundary[static_cast<size_t>(t[2])] && !on_boundary[static_cast<size_t>(t[3])];
    q.max_radius_edge = std::max(q.max_radius_edge, s.radius_edge);
    q.min_dihedral = std::min(q.min_dihedral, s.min_dihedral);
    q.max_dihedral = std::max(q.max_dihedral, s.max_dihedral);
    if (inner) {
      q.max_radius_edge_off_boundary = std::max(q.max_radius_edge_off_boundary, s.radius_edge);
      q.min_dihedral_off_boundary = std::min(q.min_dihedral_off_boundary, s.min_dihedral);
    }
  }
  if (mesh.tets.empty()) q.min_dihedral = 0;
  return q;
}

}  // namespace skinmesh
