// The triangles around each vertex of a flat mesh, in compressed rows: the
// star of vertex v is triangles[offset[v], offset[v + 1]), in increasing
// triangle order. Built by counting, two passes over the triangles; the
// quality grade, the self-intersection test and the morph's local repair
// all walk stars this way.
#pragma once

#include "skinmesh/core/surface_mesh.hpp"

#include <vector>

namespace skinmesh {

struct VertexStars {
  std::vector<int> offset;     // per vertex, and one past the last: where its row starts
  std::vector<int> triangles;  // triangle indices, row after row

  VertexStars() = default;
  // Every corner of `mesh`'s triangles must be a vertex index of `mesh`.
  explicit VertexStars(const SurfaceMesh& mesh);

  int size(int v) const { return offset[static_cast<size_t>(v) + 1] - offset[static_cast<size_t>(v)]; }
  bool empty(int v) const { return size(v) == 0; }
  const int* begin(int v) const { return triangles.data() + offset[static_cast<size_t>(v)]; }
  const int* end(int v) const { return triangles.data() + offset[static_cast<size_t>(v) + 1]; }
  template <class Visit>
  void each(int v, Visit visit) const {
    for (const int* f = begin(v); f != end(v); ++f) visit(*f);
  }
};

}  // namespace skinmesh
