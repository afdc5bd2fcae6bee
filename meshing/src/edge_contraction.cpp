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
namespace {

FacetKey key_of(int a, int b, int c) {
  FacetKey k{{a, b, c}};
  std::sort(k.begin(), k.end());
  return k;
}

}  // namespace

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
  std::unordered_map<int, std::vector<std::pair<int, int>>> links;
  for (const Vertex_handle& w : region) links[w->info().id];
  FacetSet seen;
  std::vector<Facet> facets;
  for (const Vertex_handle& w : region) {
    facets.clear();
    dt_.finite_incident_facets(w, std::back_inserter(facets));
    for (const Facet& f : facets) {
      const Cell_handle c = f.first, n = c->neighbor(f.second);
      std::array<int, 3> ids{};
      for (int k = 0; k < 3; ++k) ids[static_cast<size_t>(k)] = c->vertex((f.second + 1 + k) & 3)->info().id;
      const FacetKey key = key_of(ids[0], ids[1], ids[2]);
      if (!seen.insert(key).second) continue;
      bool restricted;
      if (c->info().value <= pass_stamp && n->info().value <= pass_stamp) {
        restricted = restricted_before.count(key) > 0;  // unchanged since the last clean pass
      } else {
        const FacetEval e = evaluate(f);
        if (e.crossings > 0 && e.defect != Defect::none) return false;
        restricted = e.crossings > 0;
      }
      if (!restricted) continue;
      for (int k = 0; k < 3; ++k) {
        auto it = links.find(key[static_cast<size_t>(k)]);
        if (it != links.end())
          it->second.emplace_back(key[static_cast<size_t>((k + 1) % 3)], key[static_cast<size_t>((k + 2) % 3)]);
      }
    }
  }
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

long Refiner::contract_short_edges(const std::vector<FacetEval>& restricted) {
  const unsigned pass_stamp = stamp_;
  FacetSet restricted_before;
  struct Candidate {
    double length;
    Vertex_handle a, b;
    int ida, idb;  // to test before touching the handles, which removal may have freed
  };
  std::vector<Candidate> candidates;
  std::unordered_set<long long> listed;
  for (const FacetEval& e : restricted) {
    restricted_before.insert(key_of(e.v[0]->info().id, e.v[1]->info().id, e.v[2]->info().id));
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
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& x, const Candidate& y) { return x.length < y.length; });
  // The surface fan the contraction would make: the new point joined to the
  // link edges of both ends. If one of its triangles is already too thin the
  // restricted Delaunay triangles will be too (they are that fan, or a
  // Delaunay flip of it), so the edge is skipped without touching the
  // triangulation; most failed attempts end here, cheaply.
  std::unordered_map<int, std::vector<std::pair<Vertex_handle, Vertex_handle>>> link;
  for (const FacetEval& e : restricted)
    for (int k = 0; k < 3; ++k)
      link[e.v[static_cast<size_t>(k)]->info().id].emplace_back(e.v[static_cast<size_t>((k + 1) % 3)],
                                                               e.v[static_cast<size_t>((k + 2) % 3)]);
  auto fan_is_good = [&](const Candidate& c, const Eigen::Vector3d& m) {
    for (const auto& [end, other] : {std::pair<int, int>{c.ida, c.idb}, std::pair<int, int>{c.idb, c.ida}}) {
      for (const auto& [x, y] : link[end]) {
        if (x->info().id == other || y->info().id == other) continue;
        const Eigen::Vector3d px = to_eigen(x->point()), py = to_eigen(y->point());
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
  for (const Candidate& c : candidates) {
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
    report("contracting", false, static_cast<long>(candidates.size()));
  }
  stats_.contracted += contracted;
  return contracted;
}

}  // namespace skinmesh::detail
