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
  CertifiedTriangles() = default;  // nothing certified: every triangle is changed
  // `mesh` whose every pair of triangles was tested and none crosses; `ids`
  // per vertex. Ids that repeat certify nothing.
  CertifiedTriangles(const SurfaceMesh& mesh, const std::vector<long>& ids);

  bool empty() const { return triangles_.empty(); }
  // Per triangle of `mesh` (ids per vertex): 1 unless its corners' ids
  // make a certified triangle and each corner is exactly where it was.
  // Every triangle is changed when `ids` repeat an id.
  std::vector<char> changed(const SurfaceMesh& mesh, const std::vector<long>& ids) const;

 private:
  struct Place {
    long id;
    double x, y, z;
  };
  std::vector<Place> places_;                   // by id
  std::vector<std::array<long, 3>> triangles_;  // corner ids, each triple ascending; sorted
};

}  // namespace skinmesh
