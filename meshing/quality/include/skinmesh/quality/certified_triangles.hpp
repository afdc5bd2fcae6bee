// What a frame of a morph whose triangles were certified to meet only where
// they share corners leaves for the next frame's self-intersection check.
// A triangle of the next frame with the same corners (by vertex id: an id
// names one vertex across frames) at exactly the same places meets every
// other such triangle as it did before, that is not at all: only pairs with
// a changed triangle need the exact test (check_changed_self_intersections,
// mesh_quality.hpp).
#pragma once

#include "skinmesh/core/surface_mesh.hpp"

#include <Eigen/Core>

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

  bool empty() const { return !unique_ids_ || mesh_triangles_.empty(); }
  // Per triangle of `later` (in its mesh's order): 1 unless its corners'
  // ids make one of these triangles and each corner is exactly where it
  // was here. All 1 when either side has no triangles (repeated ids).
  std::vector<char> changed_in(const CertifiedTriangles& later) const;

 private:
  bool index_ids();  // vertex_of_id_ or id_slots_ from ids_; false when an id repeats
  int vertex_with_id(long id) const;  // -1: none
  int triangle_with_ids(const std::array<long, 3>& ids) const;  // -1: none

  bool unique_ids_ = false;
  long first_id_ = 0;
  std::vector<long> ids_;                          // per vertex
  std::vector<Eigen::Vector3d> places_;            // per vertex
  // The vertex of each id: a table indexed by id - first_id_ when the ids
  // are nearly consecutive (a morph's are), else open addressing over ids_.
  std::vector<int> vertex_of_id_;
  std::vector<int> id_slots_;
  std::vector<std::array<int, 3>> mesh_triangles_;
  std::vector<std::array<long, 3>> triangle_ids_;  // per triangle: its corners' ids, ascending
  // The triangles whose corner of least id is vertex v: led_[first_led_[v]]
  // up to led_[first_led_[v + 1]].
  std::vector<int> first_led_, led_;
};

}  // namespace skinmesh
