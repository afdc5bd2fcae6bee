#include "skinmesh/core/vertex_stars.hpp"

namespace skinmesh {

VertexStars::VertexStars(const SurfaceMesh& mesh) : offset(mesh.vertices.size() + 1, 0) {
  for (const auto& t : mesh.triangles)
    for (int v : t) ++offset[static_cast<size_t>(v) + 1];
  for (size_t v = 1; v < offset.size(); ++v) offset[v] += offset[v - 1];
  triangles.resize(static_cast<size_t>(offset.back()));
  std::vector<int> fill(offset.begin(), offset.end() - 1);
  for (size_t f = 0; f < mesh.triangles.size(); ++f)
    for (int v : mesh.triangles[f]) triangles[static_cast<size_t>(fill[static_cast<size_t>(v)]++)] = static_cast<int>(f);
}

}  // namespace skinmesh
