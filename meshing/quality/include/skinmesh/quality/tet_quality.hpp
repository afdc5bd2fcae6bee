// Grading a tetrahedral mesh, ours or another tool's: dihedral angles,
// radius-edge ratios (also away from the boundary, where TetGen's bounds hold),
// inverted tetrahedra and volume per region. The shape of one tetrahedron is
// public so that the volume module's clean-up judges tetrahedra exactly as
// the grader does.
#pragma once

#include "skinmesh/core/tet_mesh.hpp"

#include <Eigen/Core>

namespace skinmesh {

struct TetShape {
  double volume = 0;        // Angstrom^3, signed: positive for a positively oriented tetrahedron
  double radius_edge = 0;   // circumradius / shortest edge (infinite when flat)
  double min_dihedral = 0;  // degrees
  double max_dihedral = 0;  // degrees
};
TetShape tet_shape(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                   const Eigen::Vector3d& p3);
double signed_tet_volume(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                         const Eigen::Vector3d& p3);

struct TetQuality {
  long points = 0, tets = 0;
  double volume = 0;                   // Angstrom^3, all tetrahedra
  double min_dihedral = 0, max_dihedral = 0;  // degrees
  double max_radius_edge = 0;          // circumradius / shortest edge
  // The same over tetrahedra with no vertex on a boundary face (the
  // surface's neighbourhood is where TetGen, forbidden to split the surface,
  // leaves tetrahedra outside its bounds).
  double max_radius_edge_off_boundary = 0;
  double min_dihedral_off_boundary = 0;  // degrees, same tetrahedra
  long inverted = 0;                   // tetrahedra with volume <= 0
};
TetQuality grade_tet_mesh(const TetMesh& mesh);
double region_volume(const TetMesh& mesh, int region);  // Angstrom^3

}  // namespace skinmesh
