// CGAL as an independent reference for the mesher tests and benchmarks, behind
// a plain interface so that only one file compiles CGAL's skin mesher.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/surface_mesh.hpp"

#include <vector>

namespace skinmesh::test {

// CGAL's make_skin_surface_mesh_3 (Kruithof-Vegter; certified topology) of the
// same weighted points and shrink factor, after `subdivisions` refinement steps.
SurfaceMesh cgal_skin_mesh(const std::vector<Ball>& balls, double shrink, int subdivisions = 0);

// Distance from each point to the triangle mesh (CGAL AABB tree).
std::vector<double> distances_to_mesh(const SurfaceMesh& mesh, const std::vector<Eigen::Vector3d>& points);

}  // namespace skinmesh::test
