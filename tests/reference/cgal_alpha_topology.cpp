// The skin's topology from CGAL's Fixed_alpha_shape_3 at alpha = 0: CGAL's
// own classification of the regular triangulation's simplices, the reference
// for skin_topology's classification.
#include "cgal_reference.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Fixed_alpha_shape_3.h>
#include <CGAL/Fixed_alpha_shape_cell_base_3.h>
#include <CGAL/Fixed_alpha_shape_vertex_base_3.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <numeric>

namespace skinmesh::test {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Fixed_alpha_shape_vertex_base_3<
    K, CGAL::Triangulation_vertex_base_with_info_3<long, K, CGAL::Regular_triangulation_vertex_base_3<K>>>;
using Cb = CGAL::Fixed_alpha_shape_cell_base_3<
    K, CGAL::Triangulation_cell_base_with_info_3<long, K, CGAL::Regular_triangulation_cell_base_3<K>>>;
using Shape = CGAL::Fixed_alpha_shape_3<CGAL::Regular_triangulation_3<K, CGAL::Triangulation_data_structure_3<Vb, Cb>>>;

struct Sets {
  std::vector<long> parent;
  explicit Sets(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0L); }
  long find(long x) { return parent[static_cast<size_t>(x)] == x ? x : parent[static_cast<size_t>(x)] = find(parent[static_cast<size_t>(x)]); }
  void join(long a, long b) { parent[static_cast<size_t>(find(a))] = find(b); }
  long roots(long n) {
    long r = 0;
    for (long i = 0; i < n; ++i) r += find(i) == i;
    return r;
  }
};

bool outside(const Shape& shape, Shape::Cell_handle c) { return shape.is_infinite(c) || shape.classify(c) == Shape::EXTERIOR; }

}  // namespace

SkinTopology cgal_alpha_shape_topology(const std::vector<Ball>& balls, const std::vector<Ball>& far_balls) {
  std::vector<K::Weighted_point_3> points;
  for (const std::vector<Ball>* set : {&balls, &far_balls})
    for (const Ball& b : *set)
      if (b.weight > 0 || set == &far_balls)
        points.emplace_back(K::Point_3(b.center[0], b.center[1], b.center[2]), b.weight);
  Shape shape(points.begin(), points.end(), 0);
  long vertices = 0, edges = 0, triangles = 0, tetrahedra = 0;
  for (auto v = shape.finite_vertices_begin(); v != shape.finite_vertices_end(); ++v)
    v->info() = shape.classify(v) != Shape::EXTERIOR ? vertices++ : -1;
  Sets bodies(static_cast<size_t>(vertices));
  for (auto e = shape.finite_edges_begin(); e != shape.finite_edges_end(); ++e)
    if (shape.classify(*e) != Shape::EXTERIOR) {
      ++edges;
      bodies.join(e->first->vertex(e->second)->info(), e->first->vertex(e->third)->info());
    }
  for (auto f = shape.finite_facets_begin(); f != shape.finite_facets_end(); ++f)
    triangles += shape.classify(*f) != Shape::EXTERIOR;
  for (auto c = shape.finite_cells_begin(); c != shape.finite_cells_end(); ++c) tetrahedra += shape.classify(c) != Shape::EXTERIOR;
  // The complement: cells outside K through facets outside K; the infinite cells one region.
  long regions = 0;
  for (auto c = shape.all_cells_begin(); c != shape.all_cells_end(); ++c) c->info() = outside(shape, c) ? regions++ : -1;
  Sets pieces(static_cast<size_t>(regions) + 1);
  for (auto c = shape.all_cells_begin(); c != shape.all_cells_end(); ++c) {
    if (c->info() < 0) continue;
    if (shape.is_infinite(c)) pieces.join(c->info(), regions);
    for (int k = 0; k < 4; ++k)
      if (c->neighbor(k)->info() >= 0 &&
          (shape.is_infinite(c, k) || shape.classify(Shape::Facet(c, k)) == Shape::EXTERIOR))
        pieces.join(c->info(), c->neighbor(k)->info());
  }
  SkinTopology out;
  out.voids = pieces.roots(regions + 1) - 1;
  out.components = bodies.roots(vertices) + out.voids;
  out.euler = 2 * (vertices - edges + triangles - tetrahedra);
  return out;
}

}  // namespace skinmesh::test
