// The dual complex of the union of balls from CGAL's weighted alpha shape at
// alpha = 0 (Fixed_alpha_shape_3: each simplex classified by exact
// predicates for that one alpha, which keeps tangent balls and nearly
// degenerate sets right without the whole alpha spectrum's exact
// comparisons). CGAL stays in this file.
#include "skinmesh/core/skin_topology.hpp"

#include "skinmesh/core/error.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Fixed_alpha_shape_3.h>
#include <CGAL/Fixed_alpha_shape_cell_base_3.h>
#include <CGAL/Fixed_alpha_shape_vertex_base_3.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace skinmesh {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
// Each vertex and cell holds its index among those counted (-1: not
// counted): a look-up per edge and per neighbour, where a map of handles
// cost as much as the alpha shape's own classification.
using Vb = CGAL::Fixed_alpha_shape_vertex_base_3<
    K, CGAL::Triangulation_vertex_base_with_info_3<long, K, CGAL::Regular_triangulation_vertex_base_3<K>>>;
using Cb = CGAL::Fixed_alpha_shape_cell_base_3<
    K, CGAL::Triangulation_cell_base_with_info_3<long, K, CGAL::Regular_triangulation_cell_base_3<K>>>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Regular = CGAL::Regular_triangulation_3<K, Tds>;
using AlphaShape = CGAL::Fixed_alpha_shape_3<Regular>;

struct UnionFind {
  std::vector<long> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0L); }
  long find(long x) {
    while (parent[static_cast<size_t>(x)] != x) x = parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    return x;
  }
  void join(long a, long b) { parent[static_cast<size_t>(find(a))] = find(b); }
};

// Components of the body's complement: tetrahedra outside K joined through
// triangles outside K (a lower face outside K has every coface outside K),
// every infinite cell one unbounded region. Returns the bounded ones.
long count_voids(AlphaShape& shape) {
  if (shape.dimension() < 3) return 0;  // flat or fewer than four balls: nothing is enclosed
  std::vector<AlphaShape::Cell_handle> outside_cells;
  for (auto c = shape.all_cells_begin(); c != shape.all_cells_end(); ++c) {
    const bool outside = shape.is_infinite(c) || shape.classify(c) == AlphaShape::EXTERIOR;
    c->info() = outside ? static_cast<long>(outside_cells.size()) : -1;
    if (outside) outside_cells.push_back(c);
  }
  const long outside = static_cast<long>(outside_cells.size());  // the unbounded region
  UnionFind regions(outside_cells.size() + 1);
  for (long i = 0; i < outside; ++i) {
    const AlphaShape::Cell_handle cell = outside_cells[static_cast<size_t>(i)];
    if (shape.is_infinite(cell)) regions.join(i, outside);
    for (int k = 0; k < 4; ++k) {
      const long other = cell->neighbor(k)->info();
      if (other < 0) continue;
      const bool facet_outside = shape.is_infinite(cell, k) || shape.classify(AlphaShape::Facet(cell, k)) == AlphaShape::EXTERIOR;
      if (facet_outside) regions.join(i, other);
    }
  }
  long voids = 0;
  const long unbounded = regions.find(outside);
  for (long i = 0; i < outside; ++i) voids += regions.find(i) == i && i != unbounded;
  return voids;
}

}  // namespace

std::string SkinTopology::text() const {
  return std::to_string(components) + " component(s) (" + std::to_string(voids) + " voids), Euler characteristic " +
         std::to_string(euler);
}

SkinTopology skin_topology(const std::vector<Ball>& balls) {
  std::vector<Regular::Weighted_point> points;
  for (const Ball& b : balls) {
    if (!b.center.allFinite() || !std::isfinite(b.weight)) contract_error("skin_topology: a ball is not finite");
    if (b.weight > 0) points.emplace_back(K::Point_3(b.center.x(), b.center.y(), b.center.z()), b.weight);
  }
  SkinTopology out;
  if (points.empty()) return out;
  // Four balls of no body far around the rest make the triangulation
  // three-dimensional whatever the input (CGAL's alpha shape needs it): their
  // power is huge near the balls, so they take no part of the union's power
  // cells, and every simplex they belong to lies outside K.
  Eigen::Vector3d low = balls.front().center, high = low;
  for (const Ball& b : balls) {
    low = low.cwiseMin(b.center);
    high = high.cwiseMax(b.center);
  }
  double reach = 0;
  for (const Ball& b : balls) reach = std::max(reach, std::sqrt(std::max(b.weight, 0.0)));
  const Eigen::Vector3d mid = (low + high) / 2;
  const double far = 10 * ((high - low).norm() + reach) + 100;
  for (const Eigen::Vector3d& corner : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, -1), Eigen::Vector3d(-1, 1, -1),
                                        Eigen::Vector3d(-1, -1, 1)}) {
    const Eigen::Vector3d x = mid + far * corner;
    points.emplace_back(K::Point_3(x.x(), x.y(), x.z()), -1.0);
  }
  AlphaShape shape(points.begin(), points.end(), 0);
  // Every simplex of K counts (-1)^dim towards the body's Euler characteristic.
  long vertices = 0, edges = 0, triangles = 0, tetrahedra = 0;
  for (auto v = shape.finite_vertices_begin(); v != shape.finite_vertices_end(); ++v)
    v->info() = shape.classify(v) != AlphaShape::EXTERIOR ? vertices++ : -1;
  UnionFind pieces(static_cast<size_t>(vertices));
  for (auto e = shape.finite_edges_begin(); e != shape.finite_edges_end(); ++e) {
    if (shape.classify(*e) == AlphaShape::EXTERIOR) continue;
    ++edges;
    const long from = e->first->vertex(e->second)->info(), to = e->first->vertex(e->third)->info();
    if (from < 0 || to < 0) contract_error("skin_topology: an edge of the alpha complex has an end outside it");
    pieces.join(from, to);
  }
  for (auto f = shape.finite_facets_begin(); f != shape.finite_facets_end(); ++f)
    triangles += shape.classify(*f) != AlphaShape::EXTERIOR;
  for (auto c = shape.finite_cells_begin(); c != shape.finite_cells_end(); ++c)
    tetrahedra += shape.classify(c) != AlphaShape::EXTERIOR;
  long bodies = 0;
  for (long i = 0; i < vertices; ++i) bodies += pieces.find(i) == i;
  out.voids = count_voids(shape);
  out.components = bodies + out.voids;
  out.euler = 2 * (vertices - edges + triangles - tetrahedra);
  return out;
}

}  // namespace skinmesh
