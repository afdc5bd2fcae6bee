// Private to core/: the skin's topology counted from the dual complex K of
// the union of balls, classified on a three-dimensional regular
// triangulation (regular_triangulation.hpp) with the kernel's exact
// predicates, as CGAL's alpha shapes classify it at alpha = 0: a simplex is
// in K when a coface is, or when it is Gabriel (its smallest orthogonal
// sphere bounds no vertex of its cofaces) and that sphere's weighted squared
// radius is at most 0 (H. Edelsbrunner, "Deformable smooth surface design",
// Discrete Comput. Geom. 21 (1999) 87-115: the skin's body is homotopy
// equivalent to K). Only in or out is kept, where CGAL's Fixed_alpha_shape_3
// keeps four kinds and a map of every edge, which cost twice the
// triangulation. The radius, a filtered predicate, goes first; the Gabriel
// test only where it passes. Used by skin_topology (its own triangulation,
// with four far balls) and by build_skin_complex (the complex's).
#pragma once

#include "regular_triangulation.hpp"

#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/core/union_find.hpp"

#include <algorithm>
#include <utility>
#include <vector>

namespace skinmesh::detail {
namespace dual_complex {

// Whether the smallest sphere orthogonal to the points has weighted squared radius <= 0.
template <class... Points>
bool radius_at_most_zero(const Points&... points) {
  return RtKernel().compare_weighted_squared_radius_3_object()(points..., 0.0) != CGAL::POSITIVE;
}

// Counts of K's simplices by dimension, with the vertex components.
struct Counted {
  long vertices = 0, edges = 0, triangles = 0, tetrahedra = 0, bodies = 0;
};

// The vertices' indices of an edge, the lesser first.
using Edge = std::pair<long, long>;

// Cells and facets of K, marked in the cells. Returns the edges of K's
// triangles (lesser vertex first), once per triangle. Each vertex's info
// is its index.
template <class Rt>
std::vector<Edge> mark_cells_and_facets(Rt& rt, Counted& n) {
  for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) {
    c->info().in = radius_at_most_zero(c->vertex(0)->point(), c->vertex(1)->point(), c->vertex(2)->point(),
                                        c->vertex(3)->point());
    n.tetrahedra += c->info().in;
  }
  std::vector<Edge> of_triangles;
  for (auto f = rt.finite_facets_begin(); f != rt.finite_facets_end(); ++f) {
    const typename Rt::Cell_handle c = f->first, other = c->neighbor(f->second);
    const int i = f->second;
    bool in = (!rt.is_infinite(c) && c->info().in) || (!rt.is_infinite(other) && other->info().in);
    if (!in)
      in = radius_at_most_zero(c->vertex((i + 1) % 4)->point(), c->vertex((i + 2) % 4)->point(),
                               c->vertex((i + 3) % 4)->point()) &&
           rt.is_Gabriel(c, i);
    c->info().facet_in[static_cast<size_t>(i)] = in;
    other->info().facet_in[static_cast<size_t>(other->index(c))] = in;
    n.triangles += in;
    if (in)
      for (int k = 1; k < 4; ++k)
        for (int l = k + 1; l < 4; ++l) {
          const long a = static_cast<long>(c->vertex((i + k) % 4)->info());
          const long b = static_cast<long>(c->vertex((i + l) % 4)->info());
          of_triangles.emplace_back(std::min(a, b), std::max(a, b));
        }
  }
  return of_triangles;
}

// Edges bucketed by their lesser vertex, each once: whether K's triangles
// have an edge is a scan of a few entries, in linear time to build.
class EdgeSet {
 public:
  // `edges` (lesser vertex first, repeats allowed) between vertices below `indices`.
  EdgeSet(const std::vector<Edge>& edges, size_t indices) : first_(indices + 1, 0) {
    for (const auto& [a, b] : edges) ++first_[static_cast<size_t>(a) + 1];
    for (size_t v = 0; v < indices; ++v) first_[v + 1] += first_[v];
    std::vector<long> higher(edges.size());
    std::vector<long> fill(first_.begin(), first_.end() - 1);
    for (const auto& [a, b] : edges) higher[static_cast<size_t>(fill[static_cast<size_t>(a)]++)] = b;
    // Each bucket's repeats dropped, the buckets moved up to close the gaps.
    std::vector<long> seen_from(indices, -1);
    long kept = 0;
    for (size_t v = 0; v < indices; ++v) {
      const long begin = first_[v], end = first_[v + 1];
      first_[v] = kept;
      for (long k = begin; k < end; ++k) {
        const long b = higher[static_cast<size_t>(k)];
        if (seen_from[static_cast<size_t>(b)] == static_cast<long>(v)) continue;
        seen_from[static_cast<size_t>(b)] = static_cast<long>(v);
        higher[static_cast<size_t>(kept++)] = b;
      }
    }
    first_[indices] = kept;
    higher.resize(static_cast<size_t>(kept));
    higher_ = std::move(higher);
  }
  bool contains(long a, long b) const {
    const auto begin = higher_.begin() + first_[static_cast<size_t>(a)];
    const auto end = higher_.begin() + first_[static_cast<size_t>(a) + 1];
    return std::find(begin, end, b) != end;
  }
  // Every edge once.
  std::vector<Edge> edges() const {
    std::vector<Edge> out;
    out.reserve(higher_.size());
    for (size_t a = 0; a + 1 < first_.size(); ++a)
      for (long k = first_[a]; k < first_[a + 1]; ++k)
        out.emplace_back(static_cast<long>(a), higher_[static_cast<size_t>(k)]);
    return out;
  }

 private:
  std::vector<long> first_, higher_;
};

// Edges and vertices of K, given the edges of its triangles
// (mark_cells_and_facets, repeats allowed); the vertex components by
// union-find over K's edges. Each vertex's info is its index, below
// `indices`.
template <class Rt>
void count_edges_and_vertices(const Rt& rt, size_t indices, const std::vector<Edge>& of_triangles, Counted& n) {
  const long index = static_cast<long>(indices);
  const EdgeSet in_triangles(of_triangles, indices);
  std::vector<Edge> edges = in_triangles.edges();
  // Edges of K in no triangle of K (singular).
  for (auto e = rt.finite_edges_begin(); e != rt.finite_edges_end(); ++e) {
    const typename Rt::Vertex_handle p = e->first->vertex(e->second), q = e->first->vertex(e->third);
    const long a = static_cast<long>(p->info()), b = static_cast<long>(q->info());
    const Edge key(std::min(a, b), std::max(a, b));
    if (in_triangles.contains(key.first, key.second)) continue;
    if (radius_at_most_zero(p->point(), q->point()) && rt.is_Gabriel(*e)) edges.push_back(key);
  }
  n.edges = static_cast<long>(edges.size());
  std::vector<char> in(static_cast<size_t>(index), 0);
  UnionFind<long> pieces(static_cast<size_t>(index));
  for (const auto& [a, b] : edges) {
    in[static_cast<size_t>(a)] = in[static_cast<size_t>(b)] = 1;
    pieces.unite(a, b);
  }
  // A vertex of K on no edge of K (a ball that meets no other).
  for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) {
    char& mark = in[static_cast<size_t>(v->info())];
    if (!mark) mark = radius_at_most_zero(v->point()) && rt.is_Gabriel(typename Rt::Vertex_handle(v));
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
template <class Rt>
long count_voids(Rt& rt) {
  long outside = 0;
  for (auto c = rt.all_cells_begin(); c != rt.all_cells_end(); ++c)
    c->info().outside = rt.is_infinite(c) || !c->info().in ? outside++ : -1;
  UnionFind<long> regions(static_cast<size_t>(outside) + 1);  // the last: the unbounded region
  for (auto c = rt.all_cells_begin(); c != rt.all_cells_end(); ++c) {
    const long i = c->info().outside;
    if (i < 0) continue;
    if (rt.is_infinite(c)) regions.unite(i, outside);
    for (int k = 0; k < 4; ++k) {
      const long other = c->neighbor(k)->info().outside;
      if (other >= 0 && (rt.is_infinite(c, k) || !c->info().facet_in[static_cast<size_t>(k)])) regions.unite(i, other);
    }
  }
  long voids = 0;
  const long unbounded = regions.find(outside);
  for (long i = 0; i < outside; ++i) voids += regions.find(i) == i && i != unbounded;
  return voids;
}

}  // namespace dual_complex

// The topology of the skin of the triangulation's balls. The triangulation
// must be three-dimensional, each vertex's info its index below `indices`,
// and every ball of positive weight but for balls of negative weight so far
// away that they take no part in the union's power cells (skin_topology's
// four); the cells' marks are written.
template <class Rt>
SkinTopology count_dual_complex(Rt& rt, size_t indices) {
  dual_complex::Counted n;
  const std::vector<dual_complex::Edge> of_triangles = dual_complex::mark_cells_and_facets(rt, n);
  dual_complex::count_edges_and_vertices(rt, indices, of_triangles, n);
  SkinTopology out;
  out.voids = dual_complex::count_voids(rt);
  out.components = n.bodies + out.voids;
  out.euler = 2 * (n.vertices - n.edges + n.triangles - n.tetrahedra);
  return out;
}

}  // namespace skinmesh::detail
