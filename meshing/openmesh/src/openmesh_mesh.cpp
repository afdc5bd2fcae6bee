#include "skinmesh/openmesh/openmesh_mesh.hpp"

#include "skinmesh/core/error.hpp"

#include <stdexcept>
#include <string>

namespace skinmesh {

SkinTriMesh to_openmesh(const SurfaceMesh& mesh) {
  SkinTriMesh out;
  OpenMesh::VPropHandleT<int> cell;
  out.add_property(cell, mixed_cell_property_name());
  std::vector<SkinTriMesh::VertexHandle> handles;
  handles.reserve(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d& p = mesh.vertices[i];
    const auto v = out.add_vertex(SkinTriMesh::Point(p[0], p[1], p[2]));
    out.property(cell, v) = i < mesh.cells.size() ? mesh.cells[i] : -1;
    if (i < mesh.normals.size()) out.set_normal(v, SkinTriMesh::Normal(mesh.normals[i][0], mesh.normals[i][1], mesh.normals[i][2]));
    handles.push_back(v);
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const auto f = out.add_face(handles[static_cast<size_t>(tri[0])], handles[static_cast<size_t>(tri[1])],
                                handles[static_cast<size_t>(tri[2])]);
    if (!f.is_valid())
      contract_error("triangle " + std::to_string(t) + " makes the mesh non-manifold; OpenMesh refuses it");
  }
  return out;
}

SurfaceMesh from_openmesh(const SkinTriMesh& mesh) {
  SurfaceMesh out;
  OpenMesh::VPropHandleT<int> cell;
  const bool has_cells = mesh.get_property_handle(cell, mixed_cell_property_name());
  std::vector<int> index(mesh.n_vertices(), -1);
  for (const auto v : mesh.vertices()) {
    if (mesh.status(v).deleted()) continue;
    index[static_cast<size_t>(v.idx())] = static_cast<int>(out.vertices.size());
    const auto& p = mesh.point(v);
    out.vertices.emplace_back(p[0], p[1], p[2]);
    const auto& n = mesh.normal(v);
    out.normals.emplace_back(n[0], n[1], n[2]);
    out.cells.push_back(has_cells ? mesh.property(cell, v) : -1);
  }
  for (const auto f : mesh.faces()) {
    if (mesh.status(f).deleted()) continue;
    std::array<int, 3> t{};
    int k = 0;
    for (const auto v : mesh.fv_range(f)) t[static_cast<size_t>(k++)] = index[static_cast<size_t>(v.idx())];
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace skinmesh
