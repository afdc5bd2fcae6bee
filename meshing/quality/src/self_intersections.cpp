// Exact self-intersection check (CGAL Polygon_mesh_processing, exact
// predicates); CGAL stays in this file.
#include "skinmesh/quality/mesh_quality.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <iterator>
#include <vector>

namespace skinmesh {

long count_self_intersections(const SurfaceMesh& mesh) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  Mesh sm;
  std::vector<Mesh::Vertex_index> handle;
  handle.reserve(mesh.vertices.size());
  for (const Eigen::Vector3d& p : mesh.vertices) handle.push_back(sm.add_vertex(K::Point_3(p.x(), p.y(), p.z())));
  for (const auto& t : mesh.triangles)
    if (sm.add_face(handle[t[0]], handle[t[1]], handle[t[2]]) == Mesh::null_face()) return -1;
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));
  return static_cast<long>(pairs.size());
}

}  // namespace skinmesh
