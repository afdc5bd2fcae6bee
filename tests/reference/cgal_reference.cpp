#include "cgal_reference.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/Skin_surface_3.h>
#include <CGAL/Skin_surface_polyhedral_items_3.h>
#include <CGAL/mesh_skin_surface_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/subdivide_skin_surface_mesh_3.h>

#include <map>

namespace skinmesh::test {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

SurfaceMesh cgal_skin_mesh(const std::vector<Ball>& balls, double shrink, int subdivisions) {
  using Skin = CGAL::Skin_surface_3<CGAL::Skin_surface_traits_3<K>>;
  // Faces that remember their cell of CGAL's triangulated mixed complex: each
  // subdivision step then projects a new vertex from that cell instead of
  // walking to it from the infinite cell, which on the 1e-9 A-jittered midway
  // set of 2k39 took longer than 25 minutes for one step (0.8 s this way).
  using Polyhedron = CGAL::Polyhedron_3<K, CGAL::Skin_surface_polyhedral_items_3<Skin>>;
  std::vector<K::Weighted_point_3> points;
  for (const Ball& b : balls) points.emplace_back(K::Point_3(b.center[0], b.center[1], b.center[2]), b.weight);
  const Skin skin(points.begin(), points.end(), shrink, /*grow_balls=*/false);
  Polyhedron polyhedron;
  CGAL::mesh_skin_surface_3(skin, polyhedron);
  CGAL::subdivide_skin_surface_mesh_3(skin, polyhedron, subdivisions);
  SurfaceMesh mesh;
  std::map<Polyhedron::Vertex_const_handle, int> index;
  for (auto v = polyhedron.vertices_begin(); v != polyhedron.vertices_end(); ++v) {
    index[v] = static_cast<int>(mesh.vertices.size());
    mesh.vertices.emplace_back(v->point().x(), v->point().y(), v->point().z());
  }
  for (auto f = polyhedron.facets_begin(); f != polyhedron.facets_end(); ++f) {
    auto h = f->facet_begin();
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k, ++h) t[static_cast<size_t>(k)] = index[h->vertex()];
    mesh.triangles.push_back(t);
  }
  return mesh;
}

long cgal_self_intersecting_pairs(const SurfaceMesh& mesh) {
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  Mesh sm;
  std::vector<Mesh::Vertex_index> handle;
  for (const Eigen::Vector3d& p : mesh.vertices) handle.push_back(sm.add_vertex(K::Point_3(p.x(), p.y(), p.z())));
  for (const auto& t : mesh.triangles)
    if (sm.add_face(handle[static_cast<size_t>(t[0])], handle[static_cast<size_t>(t[1])],
                    handle[static_cast<size_t>(t[2])]) == Mesh::null_face())
      return -1;
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));
  return static_cast<long>(pairs.size());
}

std::vector<double> distances_to_mesh(const SurfaceMesh& mesh, const std::vector<Eigen::Vector3d>& points) {
  using Triangle = K::Triangle_3;
  using Iterator = std::vector<Triangle>::const_iterator;
  using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
  std::vector<Triangle> triangles;
  auto point = [&](int i) {
    const Eigen::Vector3d& p = mesh.vertices[static_cast<size_t>(i)];
    return K::Point_3(p[0], p[1], p[2]);
  };
  for (const auto& t : mesh.triangles) triangles.emplace_back(point(t[0]), point(t[1]), point(t[2]));
  Tree tree(triangles.begin(), triangles.end());
  tree.accelerate_distance_queries();
  std::vector<double> out;
  for (const Eigen::Vector3d& p : points)
    out.push_back(std::sqrt(tree.squared_distance(K::Point_3(p[0], p[1], p[2]))));
  return out;
}

}  // namespace skinmesh::test
