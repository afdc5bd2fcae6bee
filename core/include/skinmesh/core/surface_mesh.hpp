// The flat exchange mesh: the only mesh type that crosses module boundaries
// (OpenMesh and CGAL meshes stay inside the module that uses them).
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

namespace skinmesh {

struct SurfaceMesh {
  std::vector<Eigen::Vector3d> vertices;       // Angstrom
  std::vector<std::array<int, 3>> triangles;   // counter-clockwise seen from outside
  std::vector<Eigen::Vector3d> normals;        // per vertex, unit; empty when unknown
  std::vector<int> cells;                      // per vertex mixed cell; empty when unknown
};

}  // namespace skinmesh
