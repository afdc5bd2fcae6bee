// The restricted Delaunay refiner behind mesh_skin (private to meshing/):
// the 3D Delaunay triangulation of the samples, what its facets say about the
// skin, and the refinement and clean-up that change it. Included by
// skin_mesher.cpp (refinement) and edge_contraction.cpp (clean-up) only.
#pragma once

#include "skinmesh/mesher/skin_mesher.hpp"

#include "skinmesh/core/point_grid.hpp"
#include "skinmesh/core/stopwatch.hpp"

#include "skin_seeds.hpp"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <Eigen/Geometry>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <queue>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace skinmesh::detail {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
struct VertexInfo {
  int cell = -1;  // mixed cell of the sample (a hint for every walk that starts near it)
  int id = -1;    // insertion order
};
using Vb = CGAL::Triangulation_vertex_base_with_info_3<VertexInfo, K>;
// Cell info: a stamp that changes whenever the cell is (re)created, so that an
// evaluation of a facet can tell whether its Voronoi edge is still the same.
// A cell made by the triangulation itself (a vertex removal) starts as
// kFreshCell until the refiner stamps it.
constexpr unsigned kFreshCell = std::numeric_limits<unsigned>::max();
struct CellStamp {
  unsigned value = kFreshCell;
};
using Cb = CGAL::Triangulation_cell_base_with_info_3<CellStamp, K, CGAL::Delaunay_triangulation_cell_base_3<K>>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;
using Vertex_handle = Delaunay::Vertex_handle;
using Cell_handle = Delaunay::Cell_handle;
using Facet = Delaunay::Facet;

inline Eigen::Vector3d to_eigen(const K::Point_3& p) { return {p.x(), p.y(), p.z()}; }

// What the Voronoi edge dual to one Delaunay facet says about it. Kept for
// every restricted facet between passes, so it is kept small (80 bytes):
// memory per output triangle is one of the speed issue's measures.
struct FacetEval {
  int crossings = 0;                 // of the Voronoi edge with the skin; restricted iff > 0
  int cell = -1;                     // mixed cell of the surface Delaunay ball centre
  Eigen::Vector3d center;            // surface Delaunay ball centre (farthest crossing if several)
  double radius = 0;                 // surface Delaunay ball radius
  std::array<Vertex_handle, 3> v;    // ascending ids
  unsigned stamp_c = 0, stamp_n = 0; // of the two cells when evaluated
  uint32_t tile = 0;                 // refinement tile of the centre (Refiner::tile_of): the queue's first key
  TriangleDefect defect = TriangleDefect::none;
  bool force = false;                // a vertex-star repair: insert even without a defect
  bool well_conditioned = false;     // DualEdge::well_conditioned (refine_one skips its nearest-vertex check)
  // The skin's outward side is along +(v1 - v0) x (v2 - v0): the Voronoi edge
  // leaves the skin's inside there (dual_edge walks it along that normal).
  bool outward_along_normal = true;
};
static_assert(sizeof(FacetEval) <= 80, "kept for every restricted facet: keep it small");

// Lists of restricted facets. A deque: it grows without copying itself
// (a vector's reallocation held two copies of the largest list at once, and
// that was the peak of the run).
using FacetEvals = std::deque<FacetEval>;

// A Voronoi edge dual to a Delaunay facet, from a to b along the facet's
// normal, and the apexes of the facet's two tetrahedra (none beyond the hull).
struct DualEdge {
  Eigen::Vector3d a, b;
  Eigen::Vector3d apex_c;
  std::optional<Eigen::Vector3d> apex_n;
  // Both tetrahedra far from flat (each apex at least 1e-3 circumradii off
  // the triangle's plane): both ends are accurate, and the edge lies within
  // the true Voronoi edge to rounding.
  bool well_conditioned = false;
};

// What an evaluation needs of a facet, taken out of the triangulation so
// that it can be evaluated while the triangulation changes (refine evaluates
// one batch while it inserts the next): handles only, since the serial part
// must stay short. Vertices are never removed during refinement, and a
// vertex's point and info do not change after insertion.
struct FacetShape {
  std::array<Vertex_handle, 3> v;  // in any order (the evaluation sorts them)
  Vertex_handle apex_c;            // of the cell the facet was taken from (finite)
  Vertex_handle apex_n;            // of the cell across; null beyond the hull
  unsigned stamp_c = 0, stamp_n = 0;
  Cell_handle cell;                // the finite cell the facet was taken from, and its index there
  int index = 0;
};

// A bad facet in refinement's queue, with the cell it was evaluated from
// when known: while that cell and its neighbour keep their stamps the facet
// is found without CGAL's search (is_facet, a share of the serial thread).
struct QueuedFacet {
  FacetEval eval;
  Cell_handle cell;  // null when not known (a pass's findings)
  int index = 0;
};

// Where a batch of refinement found a restricted facet: the next global pass
// takes these instead of every facet the batches made (a small share of
// them), while both cells still stand. 24 bytes: a list of whole
// evaluations raised the peak memory. The first kKeptBatchEvals
// evaluations of a pass are kept whole all the same (5 MB at most), so that
// the pass need not evaluate them again: that covers all of a morph frame's
// remesh, part of a large molecule's mesh.
struct BatchFound {
  Cell_handle cell;  // FacetShape::cell and ::index
  unsigned stamp_c = 0, stamp_n = 0;
  int index = 0;
  int eval = -1;  // position in Refiner::batch_evals_, or -1 when not kept
};
constexpr size_t kKeptBatchEvals = size_t{1} << 16;

// Whether the link of a vertex (the opposite edges of its restricted
// triangles) is one closed cycle: the vertex star is a disk.
bool is_single_cycle(const std::pair<int, int>* edges, size_t count);
bool is_single_cycle(const std::vector<std::pair<int, int>>& edges);

// A facet by its vertices' ids, ascending: the same key whichever cell the
// facet is reached from.
using FacetKey = std::array<int, 3>;
inline FacetKey facet_key(FacetKey ids) {
  std::sort(ids.begin(), ids.end());
  return ids;
}
inline FacetKey facet_key(const Facet& f) {
  FacetKey ids;
  for (int k = 0; k < 3; ++k) ids[static_cast<size_t>(k)] = f.first->vertex((f.second + 1 + k) & 3)->info().id;
  return facet_key(ids);
}
inline FacetKey facet_key(const FacetEval& e) {
  return facet_key({e.v[0]->info().id, e.v[1]->info().id, e.v[2]->info().id});
}
struct FacetKeyHash {
  // noexcept: std::unordered_map then keeps no hash code in each node.
  size_t operator()(const FacetKey& k) const noexcept {
    size_t h = static_cast<size_t>(k[0]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<size_t>(k[1]);
    return h * 0x9E3779B97F4A7C15ull ^ static_cast<size_t>(k[2]);
  }
};
using FacetSet = std::unordered_set<FacetKey, FacetKeyHash>;

// The link of a vertex in the restricted triangles: the edges opposite it,
// by vertex ids. Its star is a disk when they form one cycle.
using Links = std::unordered_map<int, std::vector<std::pair<int, int>>>;
enum class LinkScope { listed_vertices, every_vertex };
// Adds to each corner's link the edge of triangle `ids` opposite it; with
// listed_vertices only to corners already in `links`.
inline void add_to_links(const FacetKey& ids, LinkScope scope, Links& links) {
  for (size_t k = 0; k < 3; ++k) {
    auto it = links.find(ids[k]);
    if (it == links.end()) {
      if (scope == LinkScope::listed_vertices) continue;
      it = links.emplace(ids[k], std::vector<std::pair<int, int>>{}).first;
    }
    it->second.emplace_back(ids[(k + 1) % 3], ids[(k + 2) % 3]);
  }
}

// A restricted edge the clean-up may contract.
struct ShortEdge {
  double length;
  Vertex_handle a, b;
  int ida, idb;  // to test before touching the handles, which removal may have freed
};

// How the refiner reports progress: at once, or at most every quarter second.
enum class Report { now, throttled };

// Refinement cannot go on (over budget, stalled, unrepairable): thrown inside
// the refiner and turned into the result's status by mesh_skin.
struct RefinementStopped {
  MeshingStatus status;
  std::string message;
  MeshingStats stats = {};  // so far
};

// Refinement goes tile by tile (refine): cubes of this edge, Angstrom.
constexpr double kRefinementTile = 20.0;

class Refiner {
 public:
  Refiner(const SkinComplex& complex, const MeshingOptions& options) : complex_(complex), options_(options) {
    // The skin lies inside the union of the input balls: rays beyond this box miss it.
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    double max_radius = 0;
    for (const Ball& b : complex.balls()) {
      lo = lo.cwiseMin(b.center);
      hi = hi.cwiseMax(b.center);
      max_radius = std::max(max_radius, std::sqrt(std::max(0.0, b.weight)));
    }
    box_center_ = 0.5 * (lo + hi);
    box_radius_ = 0.5 * (hi - lo).norm() + max_radius + 1.0;
    max_radius_edge_ = 1.0 / (2.0 * std::sin(options.min_angle * M_PI / 180.0));
  }

  // For progress reports: the vertex count the estimate expects (0: unknown).
  void expect_vertices(double vertices) { expected_vertices_ = vertices; }
  // Seeds the skin, or starts from `samples` (remesh_skin) when given.
  SkinMeshResult run(const std::vector<SkinSample>* samples = nullptr);
  // mesh_patch: the samples with their roles, refined where patch facets fail.
  PatchMeshResult run_patch(const std::vector<SkinSample>& samples, const std::vector<PatchRole>& roles,
                            long least_budget, const std::vector<double>& within);

 private:
  // Calls visit(facet, key) once for every finite facet with a vertex in
  // `region`, until visit returns false.
  template <class Visit>
  void for_each_facet_around(const std::vector<Vertex_handle>& region, Visit visit) const {
    FacetSet seen;
    std::vector<Facet> facets;
    for (const Vertex_handle& w : region) {
      facets.clear();
      dt_.finite_incident_facets(w, std::back_inserter(facets));
      for (const Facet& f : facets) {
        const FacetKey key = facet_key(f);
        if (seen.insert(key).second && !visit(f, key)) return;
      }
    }
  }

  // Patch mode (roles_ not empty): which facets count and which stars must
  // be disks. Ids past the given samples are inserted points: interior.
  bool active(int id) const {
    return roles_.empty() || id >= static_cast<int>(roles_.size()) ||
           roles_[static_cast<size_t>(id)] != PatchRole::context;
  }
  bool active(const FacetKey& ids) const { return active(ids[0]) && active(ids[1]) && active(ids[2]); }
  // Patch mode, a triangulation of dimension 3: calls visit(facet) for
  // each finite facet whose corners are all active, from the cell the
  // triangulation's facet iterator reports it from (the one of lower
  // address; the finite one on the hull). Most of a patch's cells hold
  // context vertices: a cell with fewer than three active corners is
  // passed over without reading its facets.
  template <class Visit>
  void active_facets(Visit visit) const {
    for (auto c = dt_.finite_cells_begin(); c != dt_.finite_cells_end(); ++c) {
      int inactive = -1, count = 0;
      for (int k = 0; k < 4; ++k)
        if (!active(c->vertex(k)->info().id)) inactive = k, ++count;
      if (count > 1) continue;
      for (int i = 0; i < 4; ++i) {
        if (count == 1 && i != inactive) continue;  // the facet holds the inactive corner
        const Cell_handle n = c->neighbor(i);
        if (dt_.is_infinite(n) || Cell_handle(c) < n) visit(Facet(c, i));
      }
    }
  }
  bool star_checked(int id) const {
    return roles_.empty() || id >= static_cast<int>(roles_.size()) ||
           roles_[static_cast<size_t>(id)] == PatchRole::interior;
  }
  std::vector<Vertex_handle> star_checked_only(std::vector<Vertex_handle> vertices) const;

  FacetShape shape_of(const Facet& facet) const;
  // Reads nothing of the triangulation but the shape's vertices: safe while
  // the triangulation changes elsewhere.
  FacetEval evaluate(const FacetShape& shape) const;
  FacetEval evaluate(const Facet& facet) const { return evaluate(shape_of(facet)); }
  // Whether the Voronoi edge lies strictly inside the body, by one ball: no crossing.
  bool inside_a_shrunk_ball(const DualEdge& edge, const std::array<Vertex_handle, 3>& corners) const;
  std::optional<DualEdge> dual_edge(const FacetShape& shape, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                    const Eigen::Vector3d& p2) const;
  // Seeds closer than spacing times the target edge length to a sample are left out.
  void insert_seeds(const std::vector<SkinPoint>& seeds, double spacing);
  void insert_samples(const std::vector<SkinSample>& samples);
  Vertex_handle insert(const Eigen::Vector3d& p, int cell, Cell_handle hint);
  void stamp_star(Vertex_handle v);  // stamps the cells around a new vertex, into star_
  void push_if_bad(const FacetEval& e);
  void push_repair(FacetEval e);  // a vertex-star repair: insert its ball centre even without a defect
  void refine();
  // The refinement tile holding p, as its Morton code (tiles of kRefinementTile,
  // 1,024 a side around the molecule; beyond, the outermost).
  uint32_t tile_of(const Eigen::Vector3d& p) const;
  std::optional<Vertex_handle> refine_one(QueuedFacet q, unsigned refine_start, std::vector<QueuedFacet>* requeue);
  void made_facets(std::vector<Facet>* facets) const;  // replaces *facets
  bool made_by_batch(unsigned stamp) const;             // a stamp a batch of refinement made
  // Whether facet `index` of c lies between the same two cells as when they
  // had these stamps (c may have been freed: the container tells).
  bool still_stands(Cell_handle c, int index, unsigned stamp_c, unsigned stamp_n) const;
  void keep_batch_found(const std::vector<FacetShape>& shapes, const std::vector<FacetEval>& evals);
  // Appends the restricted ones of `facets` (evaluated in parallel) to `restricted`.
  void keep_restricted(const std::vector<Facet>& facets, FacetEvals* restricted) const;
  bool global_pass();
  // The place of the facet with these ids in restricted_, if it is there.
  std::optional<uint32_t> find_restricted(const FacetKey& ids) const;
  void index_restricted();
  void forget_restricted_index();
  void keep_pass(std::vector<uint32_t> unchanged, FacetEvals fresh);
  bool repair_stars(const FacetEvals& restricted, const std::vector<Vertex_handle>& vertices);
  std::optional<Projection> isolated_repair_point(Vertex_handle v) const;
  void local_passes();
  SurfaceMesh extract(const FacetEvals& restricted, std::vector<long>* origins) const;
  void report(const char* stage, Report when, long pending = 0);
  void refine_until_clean();  // then restricted_ holds the mesh

  // Clean-up (edge_contraction.cpp).
  long contract_short_edges(const FacetEvals& restricted);
  std::vector<ShortEdge> short_edges(const FacetEvals& restricted) const;
  bool try_contract(Vertex_handle a, Vertex_handle b, const Projection& target, unsigned pass_stamp,
                    const FacetSet& restricted_before, std::unordered_set<int>* touched);
  bool region_is_good(const std::vector<Vertex_handle>& region, unsigned pass_stamp,
                      const FacetSet& restricted_before) const;
  Vertex_handle reinsert(const Eigen::Vector3d& p, const VertexInfo& info, Cell_handle hint);
  void stamp_fresh_cells(const std::vector<Vertex_handle>& vertices);  // around these vertices
  void check_budget() const;

  const SkinComplex& complex_;
  const MeshingOptions& options_;
  Delaunay dt_;
  std::vector<FacetEval> pending_;   // bad facets waiting for their surface ball centre
  // Refinement's batches evaluate every facet of the cells they make: the
  // stamps they made since the last global pass, as ranges (first, last],
  // and the restricted facets they found there (cleaned up as cells go).
  std::vector<std::pair<unsigned, unsigned>> batch_stamps_;
  std::deque<BatchFound> batch_found_;
  std::vector<FacetEval> batch_evals_;  // whole evaluations of batch_found_ (see BatchFound)
  size_t batch_found_after_cleanup_ = 0;
  std::vector<Cell_handle> star_;    // cells made by the last insertion
  // Cells made by insert() since made_since_ (a refinement batch), with
  // their stamps; recorded only while refine() runs (seeding makes many).
  std::vector<std::pair<Cell_handle, unsigned>> made_;
  unsigned made_since_ = 0;
  bool recording_made_ = false;
  std::vector<Vertex_handle> recent_;  // inserted since the last global or local pass
  unsigned stamp_ = 0;
  // The restricted facets of the last global pass in the order of their keys,
  // and the stamp then: cells stamped no later are unchanged since. One copy
  // of each evaluation: most of the refiner's memory after CGAL's triangulation.
  FacetEvals restricted_;
  // Where restricted_'s entries whose smallest vertex id is i begin (entry i)
  // and the two larger ids of each entry, so that a facet is found without
  // touching vertex handles (a clean-up may have removed the vertices of
  // entries that are gone). In id order, hence in the order of refinement:
  // a hash map here missed the cache on large meshes and cost 33 bytes a
  // restricted facet, these 4 and 8.
  std::vector<uint32_t> restricted_start_;
  std::vector<std::pair<int, int>> restricted_rest_;
  unsigned last_pass_stamp_ = 0;
  bool have_pass_cache_ = false;
  Eigen::Vector3d box_center_;
  double box_radius_ = 0;
  double max_radius_edge_ = 1;
  int next_id_ = 0;
  int sample_ids_ = 0;  // ids below this are the given samples' indices (remesh_skin, mesh_patch)
  std::vector<int> star_slot_;  // by vertex id: its place in repair_stars' list, else -1
  std::vector<PatchRole> roles_;  // by sample id (mesh_patch); empty for the whole skin
  // Patch mode with `within` (mesh_patch): the patch samples, each with the
  // distance from it a facet's skin crossing may lie, in cells as wide as
  // the largest such distance. Empty: no bound.
  PointGrid<std::pair<Eigen::Vector3d, double>> near_patch_;
  bool near_patch(const Eigen::Vector3d& p) const;
  long patch_budget_ = 0;         // insertions a patch may make (mesh_patch)
  MeshingStats stats_;
  Clock::time_point last_report_ = Clock::now();
  double expected_vertices_ = 0;
};

}  // namespace skinmesh::detail
