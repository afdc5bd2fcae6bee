// The flat exchange tetrahedral mesh: what the volume mesher makes, the
// readers read, the grader grades and the writers write. Like SurfaceMesh it
// is plain data, so no module needs another's internals to pass it on.
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

namespace skinmesh {

// Region markers of tetrahedra and boundary markers of faces.
constexpr int kRegionInterior = 1;  // inside the molecule's skin
constexpr int kRegionSolvent = 2;   // between the skin and the box
constexpr int kRegionCavity = 3;    // an enclosed void of the molecule (kept as solvent-like region)
constexpr int kFaceSkin = 1;        // a triangle of the skin (outer surface)
constexpr int kFaceCavity = 2;      // a triangle of a cavity's surface
constexpr int kFaceBox = 3;         // a triangle of the outer box

struct TetMesh {
  std::vector<Eigen::Vector3d> points;           // Angstrom
  std::vector<std::array<int, 4>> tets;          // positively oriented
  std::vector<int> tet_region;                   // kRegion* per tetrahedron
  std::vector<std::array<int, 3>> faces;         // boundary and interface triangles
  std::vector<int> face_marker;                  // kFace* per face
};

}  // namespace skinmesh
