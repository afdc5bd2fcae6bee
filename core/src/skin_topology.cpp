// The dual complex of the union of balls at alpha = 0, classified on CGAL's
// regular triangulation with the kernel's exact predicates, as CGAL's alpha
// shapes classify it (a simplex is in K when a coface is, or when it is
// Gabriel, its smallest orthogonal sphere bounding no vertex of its cofaces,
// and that sphere's weighted squared radius is at most 0), but only in or
// out: CGAL's Fixed_alpha_shape_3 keeps four kinds and a map of every edge,
// which cost twice the triangulation. The radius, a filtered predicate,
// goes first; the Gabriel test only where it passes. CGAL stays in this file.
#include "skinmesh/core/skin_topology.hpp"

#include "skinmesh/core/error.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <utility>

namespace skinmesh {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
// Per cell: its own membership in K and each facet's (facet i opposite
// vertex i), and its index among the cells outside K (-1: in K).
struct CellMarks {
  bool in = false;
  std::array<bool, 4> facet_in{{false, false, false, false}};
  long outside = -1;
};
// Each vertex holds its index (a look-up per edge where a map of handles is slow).
using Vb = CGAL::Triangulation_vertex_base_with_info_3<long, K, CGAL::Regular_triangulation_vertex_base_3<K>>;
using Cb = CGAL::Triangulation_cell_base_with_info_3<CellMarks, K, CGAL::Regular_triangulation_cell_base_3<K>>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Regular = CGAL::Regular_triangulation_3<K, Tds>;

struct UnionFind {
  std::vector<long> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0L); }
  long find(long x) {
    while (parent[static_cast<size_t>(x)] != x) x = parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    return x;
  }
  void join(long a, long b) { parent[static_cast<size_t>(find(a))] = find(b); }
};

// Whether the smallest sphere orthogonal to the points has weighted squared radius <= 0.
template <class... Points>
bool radius_at_most_zero(const Points&... points) {
  return K().compare_weighted_squared_radius_3_object()(points..., 0.0) != CGAL::POSITIVE;
}

// Counts of K's simplices by dimension, with the vertex components.
struct Counted {
  long vertices = 0, edges = 0, triangles = 0, tetrahedra = 0, bodies = 0;
};

// Cells and facets of K, marked in the cells.
void mark_cells_and_facets(Regular& rt, Counted& n) {
  for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) {
    c->info().in = radius_at_most_zero(c->vertex(0)->point(), c->vertex(1)->point(), c->vertex(2)->point(),
                                        c->vertex(3)->point());
    n.tetrahedra += c->info().in;
  }
  for (auto f = rt.finite_facets_begin(); f != rt.finite_facets_end(); ++f) {
    const Regular::Cell_handle c = f->first, other = c->neighbor(f->second);
    const int i = f->second;
    bool in = (!rt.is_infinite(c) && c->info().in) || (!rt.is_infinite(other) && other->info().in);
    if (!in)
      in = radius_at_most_zero(c->vertex((i + 1) % 4)->point(), c->vertex((i + 2) % 4)->point(),
                               c->vertex((i + 3) % 4)->point()) &&
           rt.is_Gabriel(c, i);
    c->info().facet_in[static_cast<size_t>(i)] = in;
    other->info().facet_in[static_cast<size_t>(other->index(c))] = in;
    n.triangles += in;
  }
}

// Edges and vertices of K; the vertex components by union-find over K's edges.
void count_edges_and_vertices(Regular& rt, Counted& n) {
  long index = 0;
  for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) v->info() = index++;
  // The edges of K's triangles, each once.
  std::vector<std::pair<long, long>> of_triangles;
  for (auto f = rt.finite_facets_begin(); f != rt.finite_facets_end(); ++f) {
    const Regular::Cell_handle c = f->first;
    const int i = f->second;
    if (!c->info().facet_in[static_cast<size_t>(i)]) continue;
    for (int k = 1; k < 4; ++k)
      for (int l = k + 1; l < 4; ++l) {
        const long a = c->vertex((i + k) % 4)->info(), b = c->vertex((i + l) % 4)->info();
        of_triangles.emplace_back(std::min(a, b), std::max(a, b));
      }
  }
  std::sort(of_triangles.begin(), of_triangles.end());
  of_triangles.erase(std::unique(of_triangles.begin(), of_triangles.end()), of_triangles.end());
  std::vector<std::pair<long, long>> edges = of_triangles;
  // Edges of K in no triangle of K (singular).
  for (auto e = rt.finite_edges_begin(); e != rt.finite_edges_end(); ++e) {
    const Regular::Vertex_handle p = e->first->vertex(e->second), q = e->first->vertex(e->third);
    const std::pair<long, long> key(std::min(p->info(), q->info()), std::max(p->info(), q->info()));
    if (std::binary_search(of_triangles.begin(), of_triangles.end(), key)) continue;
    if (radius_at_most_zero(p->point(), q->point()) && rt.is_Gabriel(*e)) edges.push_back(key);
  }
  n.edges = static_cast<long>(edges.size());
  std::vector<char> in(static_cast<size_t>(index), 0);
  UnionFind pieces(static_cast<size_t>(index));
  for (const auto& [a, b] : edges) {
    in[static_cast<size_t>(a)] = in[static_cast<size_t>(b)] = 1;
    pieces.join(a, b);
  }
  // A vertex of K on no edge of K (a ball that meets no other).
  for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) {
    char& mark = in[static_cast<size_t>(v->info())];
    if (!mark) mark = radius_at_most_zero(v->point()) && rt.is_Gabriel(Regular::Vertex_handle(v));
  }
  for (long v = 0; v < index; ++v)
    if (in[static_cast<size_t>(v)]) {
      ++n.vertices;
      n.bodies += pieces.find(v) == v;
    }
}

// Components of the body's complement: tetrahedra outside K joined through
// triangles outside K, every infinite cell one unbounded region. Returns
// the bounded ones.
long count_voids(Regular& rt) {
  long outside = 0;
  for (auto c = rt.all_cells_begin(); c != rt.all_cells_end(); ++c)
    c->info().outside = rt.is_infinite(c) || !c->info().in ? outside++ : -1;
  UnionFind regions(static_cast<size_t>(outside) + 1);  // the last: the unbounded region
  for (auto c = rt.all_cells_begin(); c != rt.all_cells_end(); ++c) {
    const long i = c->info().outside;
    if (i < 0) continue;
    if (rt.is_infinite(c)) regions.join(i, outside);
    for (int k = 0; k < 4; ++k) {
      const long other = c->neighbor(k)->info().outside;
      if (other >= 0 && (rt.is_infinite(c, k) || !c->info().facet_in[static_cast<size_t>(k)])) regions.join(i, other);
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
  // three-dimensional whatever the input (the Gabriel tests need it): their
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
  Regular rt(points.begin(), points.end());
  if (rt.dimension() < 3) contract_error("skin_topology: the triangulation with its four far balls is not three-dimensional");
  Counted n;
  mark_cells_and_facets(rt, n);
  count_edges_and_vertices(rt, n);
  out.voids = count_voids(rt);
  out.components = n.bodies + out.voids;
  out.euler = 2 * (n.vertices - n.edges + n.triangles - n.tetrahedra);
  return out;
}

}  // namespace skinmesh
