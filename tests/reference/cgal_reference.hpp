// CGAL as an independent reference for the mesher tests and benchmarks, behind
// a plain interface so that only one file compiles CGAL's skin mesher.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/core/surface_mesh.hpp"

#include <random>
#include <vector>

namespace skinmesh::test {

// CGAL's skin mesh (Kruithof-Vegter; certified topology) of the same weighted
// points and shrink factor: what make_skin_surface_mesh_3 builds, after
// `subdivisions` refinement steps (each splits every triangle in four and
// projects the new vertices onto CGAL's skin).
SurfaceMesh cgal_skin_mesh(const std::vector<Ball>& balls, double shrink, int subdivisions = 0);

// The balls moved by up to `amount` A in each coordinate, deterministically:
// CGAL's mesher needs this on sets with groups of balls orthogonal to one
// sphere (skinmesh does not), so 1e-9 A makes its reference for those sets.
inline std::vector<Ball> jittered(std::vector<Ball> balls, double amount = 1e-9, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (Ball& b : balls) b.center += Eigen::Vector3d(u(rng), u(rng), u(rng));
  return balls;
}

// Intersecting pairs of triangles by CGAL's self-intersection test over the
// whole mesh at once, sequential (the grader splits the mesh in two halves).
long cgal_self_intersecting_pairs(const SurfaceMesh& mesh);

// The skin's topology from CGAL's own alpha shape at alpha = 0
// (Fixed_alpha_shape_3) of the balls of positive weight and `far_balls`
// (any weight: what makes a flat set three-dimensional), the reference for
// skin_topology's classification.
SkinTopology cgal_alpha_shape_topology(const std::vector<Ball>& balls, const std::vector<Ball>& far_balls);

// Distance from each point to the triangle mesh (CGAL AABB tree).
std::vector<double> distances_to_mesh(const SurfaceMesh& mesh, const std::vector<Eigen::Vector3d>& points);

}  // namespace skinmesh::test
