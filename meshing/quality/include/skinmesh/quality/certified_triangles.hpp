// What a frame of a morph whose triangles were certified to meet only where
// they share corners leaves for the next frame's self-intersection check.
// A triangle of the next frame with the same corners (by vertex id: an id
// names one vertex across frames) at exactly the same places meets every
// other such triangle as it did before, that is not at all: only pairs with
// a changed triangle need the exact test (check_changed_self_intersections,
// mesh_quality.hpp).
#pragma once

#include "skinmesh/core/surface_mesh.hpp"

#include <array>
#include <vector>

namespace skinmesh {

class CertifiedTriangles {
 public:
  CertifiedTriangles() = default;  // no triangles
  // The triangles of `mesh`, with `ids` per vertex; as certified once
  // every pair of them was tested and none crosses. Ids that repeat give
  // no triangles.
  CertifiedTriangles(const SurfaceMesh& mesh, const std::vector<long>& ids);

  bool empty() const { return triangles_.empty(); }
  // Per triangle of `later` (in its mesh's order): 1 unless its corners'
  // ids make one of these triangles and each corner is exactly where it
  // was here. All 1 when either side has no triangles (repeated ids).
  std::vector<char> changed_in(const CertifiedTriangles& later) const;

 private:
  struct Place {
    long id;
    double x, y, z;
    int vertex;  // in the mesh
  };
  struct Corners {
    std::array<long, 3> ids;  // ascending
    int triangle;             // in the mesh
  };
  std::vector<Place> places_;        // by id
  std::vector<Corners> triangles_;   // by ids
  std::vector<std::array<int, 3>> mesh_triangles_;
  size_t vertex_count_ = 0;
};

}  // namespace skinmesh
