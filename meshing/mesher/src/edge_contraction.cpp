// Clean-up after refinement, in the manner of Cheng and Shi: a restricted edge
// much shorter than the local target length (left by topology repairs, seeds
// and refinement near small features) is contracted to one sample, the skin
// point nearest its midpoint. In the Delaunay setting that is: remove both
// ends, insert the new point, and look at what changed. Every facet whose
// Voronoi edge changed has all its vertices among the neighbours of the two
// ends, so checking those facets (angle, size, distance, one crossing) and
// those vertices' stars (one disk each) decides whether every guarantee still
// holds. If one does not, the edge is put back exactly as it was.
#include "refiner.hpp"

#include <algorithm>
#include <unordered_map>

namespace skinmesh::detail {

void Refiner::stamp_fresh_cells(const std::vector<Vertex_handle>& vertices) {
  // Every cell a removal makes has all its vertices among the removed
  // vertex's neighbours, so looking around those finds all of them.
  std::vector<Cell_handle> cells;
  for (const Vertex_handle& v : vertices) {
    cells.clear();
    dt_.incident_cells(v, std::back_inserter(cells));
    for (const Cell_handle& c : cells)
      if (c->info().value == kFreshCell) c->info().value = ++stamp_;
  }
}

Vertex_handle Refiner::reinsert(const Eigen::Vector3d& p, const VertexInfo& info, Cell_handle hint) {
  const Vertex_handle v = dt_.insert(K::Point_3(p[0], p[1], p[2]), hint);
  v->info() = info;
  stamp_fresh_cells({v});
  return v;
}

bool Refiner::region_is_good(const std::vector<Vertex_handle>& region, unsigned pass_stamp,
                             const FacetSet& restricted_before) const {
  Links links;
  for (const Vertex_handle& w : region) links[w->info().id];
  bool good = true;
  for_each_facet_around(region, [&](const Facet& f, const FacetKey& key) {
    const Cell_handle c = f.first, n = c->neighbor(f.second);
    bool restricted;
    if (c->info().value <= pass_stamp && n->info().value <= pass_stamp) {
      restricted = restricted_before.count(key) > 0;  // unchanged since the last clean pass
    } else {
      const FacetEval e = evaluate(f);
      if (e.crossings > 0 && e.defect != TriangleDefect::none) return good = false;
      restricted = e.crossings > 0;
    }
    if (restricted) add_to_links(key, LinkScope::listed_vertices, links);
    return true;
  });
  if (!good) return false;
  for (const auto& [id, edges] : links)
    if (!is_single_cycle(edges)) return false;
  return true;
}

bool Refiner::try_contract(Vertex_handle a, Vertex_handle b, const Projection& target, unsigned pass_stamp,
                           const FacetSet& restricted_before, std::unordered_set<int>* touched) {
  const Eigen::Vector3d pa = to_eigen(a->point()), pb = to_eigen(b->point());
  const VertexInfo ia = a->info(), ib = b->info();

  std::vector<Vertex_handle> ring;
  dt_.finite_adjacent_vertices(a, std::back_inserter(ring));
  dt_.finite_adjacent_vertices(b, std::back_inserter(ring));
  ring.erase(std::remove_if(ring.begin(), ring.end(), [&](Vertex_handle w) { return w == a || w == b; }), ring.end());
  std::sort(ring.begin(), ring.end());
  ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  if (ring.empty()) return false;

  dt_.remove(a);
  dt_.remove(b);
  stamp_fresh_cells(ring);
  const int before = next_id_;
  const Vertex_handle m = insert(target.point, target.cell, ring.front()->cell());
  const bool fresh = next_id_ != before;
  std::vector<Vertex_handle> region = ring;
  region.push_back(m);
  if (fresh && region_is_good(region, pass_stamp, restricted_before)) {
    for (const Vertex_handle& w : region) touched->insert(w->info().id);
    touched->insert(ia.id);  // removed
    touched->insert(ib.id);
    return true;
  }
  // Put the edge back: the Delaunay triangulation of the same points is the
  // same, so the restricted facets around are the ones that passed before.
  if (fresh) dt_.remove(m);
  reinsert(pa, ia, ring.front()->cell());
  reinsert(pb, ib, ring.front()->cell());
  stamp_fresh_cells(ring);
  touched->insert(ia.id);  // their handles changed
  touched->insert(ib.id);
  return false;
}

// The restricted edges shorter than contract_below times the smaller target
// length at their ends, shortest first.
std::vector<ShortEdge> Refiner::short_edges(const FacetEvals& restricted) const {
  std::vector<ShortEdge> candidates;
  std::unordered_set<long long> listed;
  for (const FacetEval& e : restricted)
    for (int k = 0; k < 3; ++k) {
      Vertex_handle a = e.v[static_cast<size_t>(k)], b = e.v[static_cast<size_t>((k + 1) % 3)];
      if (a->info().id > b->info().id) std::swap(a, b);
      const long long edge_key = (static_cast<long long>(a->info().id) << 32) | b->info().id;
      if (!listed.insert(edge_key).second) continue;
      const Eigen::Vector3d pa = to_eigen(a->point()), pb = to_eigen(b->point());
      const double length = (pa - pb).norm();
      const double lower = options_.contract_below * std::min(target_edge_length(complex_, pa, a->info().cell, options_),
                                                              target_edge_length(complex_, pb, b->info().cell, options_));
      if (length < lower) candidates.push_back({length, a, b, a->info().id, b->info().id});
    }
  std::sort(candidates.begin(), candidates.end(),
            [](const ShortEdge& x, const ShortEdge& y) { return x.length < y.length; });
  return candidates;
}

long Refiner::contract_short_edges(const FacetEvals& restricted) {
  const unsigned pass_stamp = stamp_;
  FacetSet restricted_before;
  for (const FacetEval& e : restricted) restricted_before.insert(facet_key(e));
  const std::vector<ShortEdge> candidates = short_edges(restricted);
  // The surface fan the contraction would make: the new point joined to the
  // link edges of both ends. If one of its triangles is already too thin the
  // restricted Delaunay triangles will be too (they are that fan, or a
  // Delaunay flip of it), so the edge is skipped without touching the
  // triangulation; most failed attempts end here, cheaply.
  Links link;
  std::unordered_map<int, Eigen::Vector3d> position;  // of every restricted vertex, by id
  for (const FacetEval& e : restricted) {
    const FacetKey ids{{e.v[0]->info().id, e.v[1]->info().id, e.v[2]->info().id}};
    add_to_links(ids, LinkScope::every_vertex, link);
    for (size_t k = 0; k < 3; ++k) position.emplace(ids[k], to_eigen(e.v[k]->point()));
  }
  auto fan_is_good = [&](const ShortEdge& c, const Eigen::Vector3d& m) {
    for (const auto& [end, other] : {std::pair<int, int>{c.ida, c.idb}, std::pair<int, int>{c.idb, c.ida}}) {
      for (const auto& [x, y] : link[end]) {
        if (x == other || y == other) continue;
        const Eigen::Vector3d px = position.at(x), py = position.at(y);
        const Eigen::Vector3d u = px - m, w = py - m;
        const double cross = u.cross(w).norm();
        const double shortest = std::min({u.norm(), w.norm(), (py - px).norm()});
        // circumradius = |u||w||u-w| / (2 |u x w|)
        if (!(cross > 0) || u.norm() * w.norm() * (py - px).norm() / (2 * cross) > max_radius_edge_ * shortest)
          return false;
      }
    }
    return true;
  };

  std::unordered_set<int> touched;
  long contracted = 0;
  for (const ShortEdge& c : candidates) {
    // Untouched vertices keep their handles (removals never move other vertices).
    if (touched.count(c.ida) || touched.count(c.idb)) continue;
    Cell_handle cell;
    int i, j;
    if (!dt_.is_edge(c.a, c.b, cell, i, j)) continue;
    ++stats_.contraction_attempts;
    const Eigen::Vector3d pa = to_eigen(c.a->point()), pb = to_eigen(c.b->point());
    const Eigen::Vector3d mid = 0.5 * (pa + pb);
    const Projection target = complex_.project(mid, c.a->info().cell, 1e-14);
    if (!target.converged || (target.point - mid).norm() > 0.5 * (pa - pb).norm()) continue;
    if (!fan_is_good(c, target.point)) continue;
    if (try_contract(c.a, c.b, target, pass_stamp, restricted_before, &touched)) ++contracted;
    report("contracting", Report::throttled, static_cast<long>(candidates.size()));
  }
  stats_.contracted += contracted;
  return contracted;
}

}  // namespace skinmesh::detail
