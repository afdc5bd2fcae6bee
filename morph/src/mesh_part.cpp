#include "mesh_part.hpp"

namespace skinmesh::detail {

SurfaceMesh used_part(const SurfaceMesh& mesh, const std::vector<char>& keep_triangle, std::vector<int>& kept_from) {
  auto kept = [&](size_t f) { return keep_triangle.empty() || keep_triangle[f]; };
  std::vector<int> renumber(mesh.vertices.size(), -1);
  for (size_t f = 0; f < mesh.triangles.size(); ++f)
    if (kept(f))
      for (int v : mesh.triangles[f]) renumber[static_cast<size_t>(v)] = 0;
  SurfaceMesh part;
  kept_from.clear();
  for (size_t v = 0; v < renumber.size(); ++v) {
    if (renumber[v] < 0) continue;
    renumber[v] = static_cast<int>(part.vertices.size());
    part.vertices.push_back(mesh.vertices[v]);
    part.cells.push_back(mesh.cells[v]);
    part.normals.push_back(mesh.normals[v]);
    kept_from.push_back(static_cast<int>(v));
  }
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (!kept(f)) continue;
    const auto& t = mesh.triangles[f];
    part.triangles.push_back({renumber[static_cast<size_t>(t[0])], renumber[static_cast<size_t>(t[1])],
                              renumber[static_cast<size_t>(t[2])]});
  }
  return part;
}

}  // namespace skinmesh::detail
