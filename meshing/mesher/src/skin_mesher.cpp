// Restricted Delaunay refinement of the skin (see skin_mesher.hpp): facet
// evaluation, seeding, refinement, the global checks and the extraction of
// the mesh. The clean-up by edge contraction is in edge_contraction.cpp.
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/core/error.hpp"
#include "skinmesh/mesher/triangle_estimate.hpp"

#include "refiner.hpp"
#include "skin_seeds.hpp"

#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/hilbert_sort.h>
#include <CGAL/property_map.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_group.h>

#include <iomanip>
#include <numeric>
#include <sstream>

namespace skinmesh::detail {

// The Voronoi edge dual to the facet of `shape` (triangle p0 p1 p2), walked
// along the triangle's normal. It lies on the line through the triangle's
// circumcentre along its normal. Computing it from the triangle, and only the
// parameters of its ends from the two tetrahedra, keeps it accurate when a
// tetrahedron is flat (nearly cocircular samples, common on sphere patches)
// and its circumcentre is ill-conditioned: every point found on it is then
// truly equidistant from the triangle's vertices. Empty for collinear samples.
std::optional<DualEdge> Refiner::dual_edge(const FacetShape& shape, const Eigen::Vector3d& p0,
                                           const Eigen::Vector3d& p1, const Eigen::Vector3d& p2) const {
  const Eigen::Vector3d u = p1 - p0, w = p2 - p0;
  const Eigen::Vector3d uxw = u.cross(w);
  const double cross2 = uxw.squaredNorm();
  if (!(cross2 > 0)) return std::nullopt;
  const Eigen::Vector3d circumcenter = p0 + (u.squaredNorm() * w.cross(uxw) + w.squaredNorm() * uxw.cross(u)) / (2.0 * cross2);
  const Eigen::Vector3d normal = uxw / std::sqrt(cross2);
  const double circumradius2 = (circumcenter - p0).squaredNorm();
  const double reach = (circumcenter - box_center_).norm() + box_radius_;
  // Parameter along `normal` of the circumcentre of the tetrahedron with apex q.
  auto end_parameter = [&](const Eigen::Vector3d& q) {
    const double height = normal.dot(q - circumcenter);
    const double numerator = (q - circumcenter).squaredNorm() - circumradius2;
    if (std::abs(numerator) >= 2.0 * reach * std::abs(height)) return std::copysign(reach, numerator * height);
    return numerator / (2.0 * height);
  };
  DualEdge edge;
  edge.apex_c = to_eigen(shape.apex_c->point());
  if (shape.apex_n != Vertex_handle()) edge.apex_n = to_eigen(shape.apex_n->point());
  const double lambda_c = end_parameter(edge.apex_c);
  // Beyond a convex hull facet the Voronoi edge is a ray leaving the hull.
  const double lambda_n = edge.apex_n ? end_parameter(*edge.apex_n)
                                      : (normal.dot(edge.apex_c - circumcenter) > 0 ? -reach : reach);
  double from = std::min(lambda_c, lambda_n), to = std::max(lambda_c, lambda_n);
  if (!near_patch_.empty()) {
    // A patch whose context covers only the skin near it (mesh_patch's
    // `within`) looks along the edge no farther than twice the circumradius:
    // a crossing beyond is skin the context does not hold.
    const double window = 2 * std::sqrt(circumradius2);
    from = std::max(from, -window);
    to = std::max(from, std::min(to, window));
  }
  edge.a = circumcenter + from * normal;
  edge.b = circumcenter + to * normal;
  const double flat = 1e-3 * std::sqrt(circumradius2);
  edge.well_conditioned = edge.apex_n && std::abs(normal.dot(edge.apex_c - circumcenter)) > flat &&
                          std::abs(normal.dot(*edge.apex_n - circumcenter)) > flat;
  return edge;
}

FacetShape Refiner::shape_of(const Facet& facet) const {
  Cell_handle c = facet.first;
  int i = facet.second;
  if (dt_.is_infinite(c)) {
    Cell_handle m = c->neighbor(i);
    i = m->index(c);
    c = m;
  }
  FacetShape shape;
  shape.cell = c;
  shape.index = i;
  const Cell_handle n = c->neighbor(i);
  shape.stamp_c = c->info().value;
  shape.stamp_n = n->info().value;
  shape.apex_c = c->vertex(i);
  if (!dt_.is_infinite(n)) shape.apex_n = n->vertex(n->index(c));
  for (int k = 0; k < 3; ++k) shape.v[static_cast<size_t>(k)] = c->vertex((i + 1 + k) & 3);
  return shape;
}

// F(x) <= |x - z_i|^2 - s w_i for every ball i: the QP of docs/math.md
// section 2 at l = e_i. A segment with both ends strictly inside that sphere
// (a convex ball) lies in the body's interior and cannot cross the skin. The
// balls tried are those of the facet's corners' mixed cells, where the
// Voronoi edges deep inside an atom lie: many evaluations end here instead
// of walking the complex.
bool Refiner::inside_a_shrunk_ball(const DualEdge& edge, const std::array<Vertex_handle, 3>& corners) const {
  constexpr double kStrictly = 1 - 1e-9;  // far above the walk's rounding: its answer would be the same
  for (const Vertex_handle& v : corners) {
    if (v->info().cell < 0) continue;  // no cell recorded: nothing to try here
    const MixedCell& cell = complex_.cell(v->info().cell);
    for (int j = 0; j <= cell.dim; ++j) {
      const Ball& ball = complex_.balls()[static_cast<size_t>(cell.balls[static_cast<size_t>(j)])];
      const double limit = complex_.shrink() * ball.weight * kStrictly;
      if ((edge.a - ball.center).squaredNorm() < limit && (edge.b - ball.center).squaredNorm() < limit) return true;
    }
  }
  return false;
}

FacetEval Refiner::evaluate(const FacetShape& shape) const {
  FacetEval e;
  e.stamp_c = shape.stamp_c;
  e.stamp_n = shape.stamp_n;
  e.v = shape.v;
  // Canonical form, whichever cell the facet was reached from: vertices in
  // insertion order and the Voronoi edge walked along +normal. Near-degenerate
  // configurations then get the same answer in every pass and every process.
  std::sort(e.v.begin(), e.v.end(), [](Vertex_handle x, Vertex_handle y) { return x->info().id < y->info().id; });
  const Eigen::Vector3d p0 = to_eigen(e.v[0]->point()), p1 = to_eigen(e.v[1]->point()),
                        p2 = to_eigen(e.v[2]->point());
  const std::optional<DualEdge> edge = dual_edge(shape, p0, p1, p2);
  if (!edge) return e;  // collinear samples: no triangle, nothing to test
  if (inside_a_shrunk_ball(*edge, e.v)) return e;
  thread_local std::vector<SegmentCrossing> hits;  // one buffer per thread: millions of evaluations
  complex_.intersect_segment(edge->a, edge->b, e.v[0]->info().cell, &hits);
  // A point inside the Voronoi edge is strictly nearer to the triangle's
  // vertices than to either apex. When a tetrahedron is flat (its apex
  // cocircular with the triangle, which refinement on sphere patches does
  // produce) the end of the edge is ill-conditioned, and where the apex is
  // equidistant the crossing is a degenerate Voronoi vertex. Such crossings are
  // dropped: inserting them would land on or next to a sample.
  hits.erase(std::remove_if(hits.begin(), hits.end(),
                            [&](const SegmentCrossing& h) {
                              const double r2 = (h.point - p0).squaredNorm() * (1 + 1e-7);
                              return (h.point - edge->apex_c).squaredNorm() < r2 ||
                                     (edge->apex_n && (h.point - *edge->apex_n).squaredNorm() < r2);
                            }),
             hits.end());
  // A patch held to `within` (mesh_patch) takes no facet whose crossings
  // all lie far from its samples, and inserts only near them: refinement
  // stays where the context covers the skin around it.
  thread_local std::vector<char> near;
  near.assign(hits.size(), 1);
  if (!near_patch_.empty()) {
    for (size_t k = 0; k < hits.size(); ++k) near[k] = near_patch(hits[k].point);
    if (std::find(near.begin(), near.end(), 1) == near.end()) hits.clear();
  }
  e.crossings = static_cast<int>(hits.size());
  if (hits.empty()) return e;
  // The surface Delaunay ball: of several crossings, the largest.
  size_t best = 0;
  double best_r2 = -1;
  for (size_t k = 0; k < hits.size(); ++k) {
    const double r2 = (hits[k].point - p0).squaredNorm();
    if (near[k] && r2 > best_r2) {
      best_r2 = r2;
      best = k;
    }
  }
  e.center = hits[best].point;
  e.tile = tile_of(e.center);
  e.cell = hits[best].cell;
  e.radius = std::sqrt(best_r2);
  e.well_conditioned = edge->well_conditioned;
  e.outward_along_normal = !hits[best].entering;
  RestrictedTriangle triangle;
  triangle.corners = {p0, p1, p2};
  triangle.ball_center = e.center;
  triangle.ball_cell = e.cell;
  triangle.crossings = e.crossings;
  e.defect = triangle_defect(complex_, triangle, options_);
  // A patch's triangles become a morph frame's, which the frame judge holds
  // to the skin crossed once within its window about the circumcentre
  // (restricted_triangle, the tolerance as reach). The Voronoi edge can be
  // shorter than that window: next to a neck about to pinch it crosses the
  // skin once where the window crosses it twice. Such a facet is refined as
  // a topology defect; kept, the judge refuses it, and growing the patch
  // around it meshes it the same way again.
  if (!roles_.empty() && e.defect == TriangleDefect::none) {
    const auto judged = restricted_triangle(complex_, triangle.corners, options_.tolerance, e.cell);
    if (!judged || judged->crossings != 1) e.defect = TriangleDefect::topology;
  }
  return e;
}

void Refiner::report(const char* stage, Report when, long pending) {
  if (!options_.progress) return;
  if (when == Report::throttled && seconds_since(last_report_) < 0.25) return;
  last_report_ = Clock::now();
  MeshingProgress p;
  p.stage = stage;
  p.vertices = static_cast<long>(dt_.number_of_vertices());
  p.pending = pending;
  p.expected_vertices = expected_vertices_;
  options_.progress(p);
}

void Refiner::check_budget() const {
  // A patch that needs more than twice its own points (its context not
  // counted), or than the budget its caller gave, is not a local repair.
  if (!roles_.empty() && next_id_ - sample_ids_ > patch_budget_)
    throw RefinementStopped{MeshingStatus::stalled, "the patch needed more than twice its own points", stats_};
  // A closed surface mesh has about twice as many triangles as vertices.
  const long estimate = 2 * static_cast<long>(dt_.number_of_vertices());
  if (estimate > options_.max_triangles)
    throw RefinementStopped{MeshingStatus::over_budget,
                            "refinement passed the budget of " + std::to_string(options_.max_triangles) +
                                " triangles; raise the budget or ask for larger triangles (a larger epsilon, "
                                "edge length or tolerance)"};
}

// The cells around a newly inserted vertex are all new, hence all unstamped
// (kFreshCell; cells a removal made are stamped before any insertion): a walk
// across their facets through v finds them, stamping each as it goes, which
// is its own visited mark. (CGAL's incident_cells, with visited flags of its
// own, was a share of the serial thread.) Below dimension 3, CGAL's.
void Refiner::stamp_star(Vertex_handle v) {
  star_.clear();
  if (dt_.dimension() < 3) {
    dt_.incident_cells(v, std::back_inserter(star_));
    for (const Cell_handle& c : star_) c->info().value = ++stamp_;
    return;
  }
  star_.push_back(v->cell());
  v->cell()->info().value = ++stamp_;
  for (size_t k = 0; k < star_.size(); ++k) {
    const Cell_handle c = star_[k];
    const int at = c->index(v);
    for (int j = 0; j < 4; ++j) {
      const Cell_handle n = c->neighbor(j);
      if (j == at || n->info().value != kFreshCell) continue;
      n->info().value = ++stamp_;
      star_.push_back(n);
    }
  }
}

Vertex_handle Refiner::insert(const Eigen::Vector3d& point, int cell, Cell_handle hint) {
  // A crossing is a root of the cell's quadric, so it is on the skin to
  // rounding; where that root is ill-conditioned (a nearly tangent Voronoi
  // edge, a tiny sphere far from the origin) one projection step restores it.
  Eigen::Vector3d p = point;
  const SkinEval check = complex_.evaluate(p, cell);
  if (std::abs(check.value) > 1e-13 * check.gradient.norm()) {
    const Projection polished = complex_.project(p, check.cell, 1e-14);
    if (polished.converged) {
      p = polished.point;
      cell = polished.cell;
    }
  }
  const Vertex_handle v = dt_.insert(K::Point_3(p[0], p[1], p[2]), hint);
  if (v->info().id < 0) {
    v->info().cell = cell;
    v->info().id = next_id_++;
    stamp_star(v);
    if (recording_made_)
      for (const Cell_handle& c : star_) made_.emplace_back(c, c->info().value);
    recent_.push_back(v);
  }
  return v;
}

void Refiner::insert_seeds(const std::vector<SkinPoint>& seeds, double spacing) {
  // Seeds closer than a quarter of the target edge length to a kept one are
  // dropped: a pair of nearly coincident critical points (common where a
  // critical point sits near a cell boundary) would otherwise force refinement
  // down to their distance. A component still keeps its seeds unless all of
  // them lie that close to another component, which the curvature sizing rules
  // out (a component that small has curvature radius, hence target length, of
  // its own size or less). After samples (remesh_skin) the spacing is a whole
  // target length: every point of a meshed part of the skin lies within a
  // surface Delaunay ball radius (target / sqrt 3) of a sample, so only the
  // seeds of parts the samples miss are kept.
  Cell_handle hint;
  for (const auto& s : seeds) {
    const K::Point_3 p(s.point[0], s.point[1], s.point[2]);
    if (dt_.number_of_vertices() > 0) {
      const Vertex_handle nearest = dt_.nearest_vertex(p, hint);
      const Eigen::Vector3d q = to_eigen(nearest->point());
      const double apart = spacing * std::min(target_edge_length(complex_, s.point, s.cell, options_),
                                              target_edge_length(complex_, q, nearest->info().cell, options_));
      if ((q - s.point).norm() < apart) continue;
    }
    const Vertex_handle v = insert(s.point, s.cell, hint);
    hint = v->cell();
    ++stats_.seeds;
  }
}

// The given samples along a Hilbert curve, each with its index as id; then
// every cell is stamped as of this moment, so that the first global pass can
// tell later changes from the batch. The order is fixed (CGAL's range insert
// shuffles with its global random state): samples on one sphere are
// cospherical, and their Delaunay triangulation, hence the mesh, depends on
// the insertion order.
void Refiner::insert_samples(const std::vector<SkinSample>& samples) {
  // Each sample checked on the skin (and polished onto it when off) in
  // parallel: a morph frame remeshes from all its vertices, and one by one
  // this was a serial stretch of every frame.
  std::vector<SkinSample> checked(samples.size());
  std::vector<char> on_skin(samples.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, samples.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const SkinEval check = complex_.evaluate(samples[i].point, samples[i].cell);
      if (std::abs(check.value) <= 1e-13 * check.gradient.norm()) {
        checked[i] = {samples[i].point, check.cell};
        on_skin[i] = 1;
        continue;
      }
      const Projection polished = complex_.project(samples[i].point, check.cell, 1e-14);
      if (!polished.converged) continue;  // a sample that cannot be put on the skin is left out
      checked[i] = {polished.point, polished.cell};
      on_skin[i] = 1;
    }
  });
  std::vector<K::Point_3> points;
  std::vector<VertexInfo> infos;
  points.reserve(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!on_skin[i]) continue;
    const Eigen::Vector3d& p = checked[i].point;
    points.emplace_back(p[0], p[1], p[2]);
    infos.push_back(VertexInfo{checked[i].cell, static_cast<int>(i)});
  }
  std::vector<size_t> order(points.size());
  std::iota(order.begin(), order.end(), size_t{0});
  using Traits = CGAL::Spatial_sort_traits_adapter_3<K, CGAL::Pointer_property_map<K::Point_3>::type>;
  CGAL::hilbert_sort(order.begin(), order.end(), Traits(CGAL::make_property_map(points)));
  Cell_handle hint;
  for (size_t k : order) {
    const Vertex_handle v = dt_.insert(points[k], hint);
    if (v->info().id < 0) v->info() = infos[k];
    hint = v->cell();
  }
  sample_ids_ = next_id_ = static_cast<int>(samples.size());
  ++stamp_;
  for (auto c = dt_.all_cells_begin(); c != dt_.all_cells_end(); ++c) c->info().value = stamp_;
}

void Refiner::push_if_bad(const FacetEval& e) {
  if (e.crossings > 0 && e.defect != TriangleDefect::none) pending_.push_back(e);
}

void Refiner::push_repair(FacetEval e) {
  if (e.crossings == 0) return;
  e.force = true;
  pending_.push_back(e);
}

void Refiner::keep_restricted(const std::vector<Facet>& facets, FacetEvals* restricted) const {
  std::vector<FacetEval> evals(facets.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, facets.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) evals[k] = evaluate(facets[k]);
  });
  for (const FacetEval& e : evals)
    if (e.crossings > 0) restricted->push_back(e);
}

// The finite facets of the cells insertions made (made_) that still stand,
// each once: a facet between two such cells is listed from the one made
// first. (Listing the cells around the new vertices again, as CGAL finds
// them, was a noticeable part of refinement; insert() has them already.)
void Refiner::made_facets(std::vector<Facet>* facets) const {
  std::vector<Facet>& out = *facets;
  out.clear();
  for (const auto& [c, stamp] : made_) {
    // A cell made and then replaced within the batch is gone (or its place
    // holds a newer cell, with another stamp).
    if (!dt_.tds().cells().is_used(c) || c->info().value != stamp) continue;
    const bool infinite = dt_.is_infinite(c);
    for (int j = 0; j < 4; ++j) {
      if (infinite && j != c->index(dt_.infinite_vertex())) continue;  // only its finite facet
      const unsigned other = c->neighbor(j)->info().value;
      if (other >= made_since_ && other != kFreshCell && other < stamp) continue;  // listed from the neighbour
      out.emplace_back(c, j);
    }
  }
}

// One queued bad facet: its surface ball centre inserted (the new vertex is
// returned), or nothing. An entry whose cells changed since its evaluation is
// dropped when its newer cell was made during this refinement (refine
// evaluates every facet of the cells it makes, and queued it then if bad), or
// evaluated again and, if still to do, put in `requeue`.
std::optional<Vertex_handle> Refiner::refine_one(QueuedFacet q, unsigned refine_start,
                                                std::vector<QueuedFacet>* requeue) {
  FacetEval& e = q.eval;
  Cell_handle c;
  int facet_index = 0;
  const bool known = q.cell != Cell_handle();
  if (known && still_stands(q.cell, q.index, e.stamp_c, e.stamp_n)) {
    c = q.cell;  // both cells as evaluated (a live cell keeps its vertices)
    facet_index = q.index;
  } else {
    // Evaluated during this refinement and changed since: by this
    // refinement, which evaluates every cell it makes.
    if (known && std::max(e.stamp_c, e.stamp_n) > refine_start && !e.force) return std::nullopt;
    int i0, i1, i2;
    if (!dt_.tds().is_facet(e.v[0], e.v[1], e.v[2], c, i0, i1, i2)) return std::nullopt;
    facet_index = 6 - i0 - i1 - i2;
    const Cell_handle n = c->neighbor(facet_index);
    const unsigned sc = c->info().value, sn = n->info().value;
    if (!((sc == e.stamp_c && sn == e.stamp_n) || (sc == e.stamp_n && sn == e.stamp_c))) {
      const unsigned newer = std::max(sc, sn);
      if (newer > refine_start && newer != kFreshCell && !e.force) return std::nullopt;
      const bool force = e.force;
      const FacetShape shape = shape_of(Facet(c, facet_index));
      e = evaluate(shape);  // its Voronoi edge changed: look again
      if (e.crossings > 0 && (e.defect != TriangleDefect::none || force)) {
        e.force = force;
        requeue->push_back({e, shape.cell, shape.index});
      }
      return std::nullopt;
    }
  }
  if (e.radius < 1e-9) return std::nullopt;  // cannot happen for a proper triangle; never insert a duplicate
  // The surface Delaunay ball is empty in exact arithmetic: a ball centred
  // on the Voronoi edge through the triangle's vertices lies in the union of
  // its two tetrahedra's circumballs, which hold no vertex. Where a
  // tetrahedron is nearly flat its end of the edge is ill-conditioned, and
  // near a Voronoi vertex on the skin two Voronoi edges cross it at almost
  // the same point; after one is inserted the other must not be (a
  // near-duplicate vertex would send refinement chasing it). So the nearest
  // vertex is looked up there, and in a patch (below); elsewhere the lookup
  // (CGAL's walk over adjacent vertices, a share of the serial thread)
  // never found one closer than half the radius on the shipped molecules.
  if (!e.well_conditioned || !roles_.empty()) {
    const Vertex_handle nearest = dt_.nearest_vertex(K::Point_3(e.center[0], e.center[1], e.center[2]), c);
    if ((to_eigen(nearest->point()) - e.center).norm() < 0.5 * e.radius) return std::nullopt;
    // A patch grows no further than its context: a point nearest a context
    // vertex would mesh skin the rest of the mesh covers already.
    if (!active(nearest->info().id)) return std::nullopt;
  }
  switch (e.defect) {
    case TriangleDefect::topology: ++stats_.inserted_topology; break;
    case TriangleDefect::size: ++stats_.inserted_size; break;
    case TriangleDefect::distance: ++stats_.inserted_distance; break;
    case TriangleDefect::shape: ++stats_.inserted_shape; break;
    case TriangleDefect::none: ++stats_.inserted_topology; break;  // forced: a vertex star repair
  }
  const int before = next_id_;
  const Vertex_handle v = insert(e.center, e.cell, c);
  if (next_id_ == before) return std::nullopt;  // the point is a sample already
  return v;
}

// Refinement: insert the surface ball centres of the pending bad facets,
// largest ball first, in batches; evaluate the facets of the cells each batch
// made (in parallel) and queue the bad ones; repeat until none is left.
// Bits of x (21 of them) spread to every third bit: one coordinate of a
// Morton code.
static uint64_t spread_by_three(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

uint32_t Refiner::tile_of(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d q = (p - box_center_) / kRefinementTile + Eigen::Vector3d::Constant(1 << 9);
  uint64_t code = 0;
  for (int k = 0; k < 3; ++k) {
    const double clamped = std::clamp(std::floor(q[k]), 0.0, double((1 << 10) - 1));
    code |= spread_by_three(static_cast<uint64_t>(clamped)) << k;
  }
  return static_cast<uint32_t>(code);  // 30 bits
}

void Refiner::refine() {
  // Tile by tile along a Morton curve, and in a tile the largest ball first.
  // Within a tile this is the usual order; across tiles it keeps the
  // triangulation's working set small (taken by size alone, the queue
  // jumps across the whole triangulation, and a large assembly costs more
  // per triangle). Ties broken by the facet's vertex ids: CGAL's containers
  // are ordered by memory addresses in places, and the order of refinement
  // must not be.
  auto smaller = [](const QueuedFacet& x, const QueuedFacet& y) {
    const FacetEval &a = x.eval, &b = y.eval;
    if (a.tile != b.tile) return a.tile > b.tile;
    return a.radius < b.radius || (a.radius == b.radius && facet_key(a) > facet_key(b));
  };
  std::vector<QueuedFacet> heap;
  heap.reserve(pending_.size());
  for (const FacetEval& e : pending_) heap.push_back({e, Cell_handle(), 0});
  pending_.clear();
  std::make_heap(heap.begin(), heap.end(), smaller);
  auto push = [&](const QueuedFacet& q) {
    heap.push_back(q);
    std::push_heap(heap.begin(), heap.end(), smaller);
  };
  const unsigned refine_start = stamp_;
  // Insertion is serial (CGAL's); evaluation, most of the time, is not. A
  // batch of insertions lets the evaluations of their stars run together,
  // and they run while the next batch is inserted (from copies of the
  // facets' shapes): the queue then takes a batch's bad facets one batch
  // late, always at the same point, so the order of refinement does not
  // depend on timing. An entry whose cells the next batch replaced is
  // dropped when it comes up (refine_one): the new cells are evaluated.
  // 1,024 insertions a batch (the fastest of 256 to 4,096): cells a later
  // insertion of the same batch replaces are never evaluated.
  constexpr size_t kBatch = 1024;
  std::vector<QueuedFacet> requeue;
  // Kept across batches: each is hundreds of kilobytes, which the allocator
  // maps afresh (allocator.hpp) and the kernel then zeroes page by page.
  std::vector<Facet> facets;
  std::vector<FacetShape> shapes, next;
  std::vector<FacetEval> evals;
  tbb::task_group evaluating;
  bool in_flight = false;
  auto collect = [&] {  // the evaluated batch's bad facets into the queue
    evaluating.wait();
    in_flight = false;
    for (size_t k = 0; k < evals.size(); ++k)
      if (evals[k].crossings > 0 && evals[k].defect != TriangleDefect::none)
        push({evals[k], shapes[k].cell, shapes[k].index});
    keep_batch_found(shapes, evals);
  };
  recording_made_ = true;
  while (!heap.empty() || in_flight) {
    if (heap.empty()) {
      collect();
      continue;
    }
    size_t inserted = 0;
    made_.clear();
    made_since_ = stamp_ + 1;
    while (!heap.empty() && inserted < kBatch) {
      std::pop_heap(heap.begin(), heap.end(), smaller);
      const QueuedFacet q = heap.back();
      heap.pop_back();
      requeue.clear();
      inserted += refine_one(q, refine_start, &requeue).has_value();
      for (const QueuedFacet& r : requeue) push(r);
    }
    made_facets(&facets);
    next.clear();
    for (const Facet& f : facets)
      if (roles_.empty() || active(facet_key(f))) next.push_back(shape_of(f));
    if (in_flight) collect();
    shapes.swap(next);
    evals.resize(shapes.size());
    evaluating.run([this, &shapes, &evals] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, shapes.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) evals[k] = evaluate(shapes[k]);
      });
    });
    in_flight = true;
    check_budget();
    report("refining", Report::throttled, static_cast<long>(heap.size()));
  }
  recording_made_ = false;
  made_.clear();
  if (stamp_ > refine_start) batch_stamps_.emplace_back(refine_start, stamp_);
}

bool Refiner::made_by_batch(unsigned stamp) const {
  // Ranges in increasing order, a few per pass.
  auto it = std::lower_bound(batch_stamps_.begin(), batch_stamps_.end(), stamp,
                             [](const std::pair<unsigned, unsigned>& r, unsigned x) { return r.second < x; });
  return it != batch_stamps_.end() && stamp > it->first && stamp <= it->second && stamp != kFreshCell;
}

// Whether the facet is still there between the same two cells. A cell is
// never changed in place by insertion, and a new cell gets a new stamp (a
// freed cell's place is recognised by the container without reading it).
bool Refiner::still_stands(Cell_handle c, int index, unsigned stamp_c, unsigned stamp_n) const {
  if (!dt_.tds().cells().is_used(c) || c->info().value != stamp_c) return false;
  return c->neighbor(index)->info().value == stamp_n;
}

void Refiner::keep_batch_found(const std::vector<FacetShape>& shapes, const std::vector<FacetEval>& evals) {
  for (size_t k = 0; k < evals.size(); ++k) {
    if (evals[k].crossings == 0) continue;
    int kept = -1;
    if (batch_evals_.size() < kKeptBatchEvals) {
      kept = static_cast<int>(batch_evals_.size());
      batch_evals_.push_back(evals[k]);
    }
    batch_found_.push_back({shapes[k].cell, shapes[k].stamp_c, shapes[k].stamp_n, shapes[k].index, kept});
  }
  // Most facets found are replaced by later batches: drop those gone once
  // the list has grown by half, so that it stays near the live restricted count.
  if (batch_found_.size() < batch_found_after_cleanup_ + batch_found_after_cleanup_ / 2 + 65536) return;
  batch_found_.erase(std::remove_if(batch_found_.begin(), batch_found_.end(),
                                    [&](const BatchFound& f) { return !still_stands(f.cell, f.index, f.stamp_c, f.stamp_n); }),
                     batch_found_.end());
  batch_found_.shrink_to_fit();
  batch_found_after_cleanup_ = batch_found_.size();
}

bool is_single_cycle(const std::pair<int, int>* edges, size_t count) {
  if (count == 0) return false;
  // One cycle: every link vertex has degree two and a walk visits every edge.
  // Links are short (about six edges), so plain scans beat any map.
  auto degree = [&](int x) {
    int d = 0;
    for (size_t k = 0; k < count; ++k) d += (edges[k].first == x) + (edges[k].second == x);
    return d;
  };
  for (size_t k = 0; k < count; ++k)
    if (degree(edges[k].first) != 2 || degree(edges[k].second) != 2) return false;
  size_t edge = 0, steps = 1;
  int cur = edges[0].second;
  while (cur != edges[0].first && steps <= count) {
    size_t next = 0;
    while (next == edge || (edges[next].first != cur && edges[next].second != cur)) ++next;
    cur = edges[next].first == cur ? edges[next].second : edges[next].first;
    edge = next;
    ++steps;
  }
  return steps == count;
}

bool is_single_cycle(const std::vector<std::pair<int, int>>& edges) { return is_single_cycle(edges.data(), edges.size()); }

// Classifies every Delaunay facet (in parallel), queues the bad ones and the
// repairs of vertex stars that are not disks. Returns true when nothing is left
// to do; then restricted_ holds the restricted facets.
bool Refiner::global_pass() {
  ++stats_.passes;
  recent_.clear();  // this pass looks at everything
  // A facet whose two cells are older than the previous pass has the same
  // Voronoi edge, hence the same evaluation: take it from that pass (restricted
  // facets are kept; any other unchanged facet was not restricted). Only the
  // facets of new cells are evaluated again, in chunks: about one facet in
  // seven is restricted, and an evaluation of every facet at once was half the
  // peak memory. Of the facets refinement's
  // batches evaluated, only the restricted ones they found that still stand
  // are taken, their evaluations as kept (BatchFound) or evaluated again:
  // the others were not restricted then and are the same now.
  constexpr size_t kChunk = size_t{1} << 14;
  std::vector<Facet> facets;
  facets.reserve(kChunk);
  std::vector<uint32_t> unchanged;  // positions in restricted_
  FacetEvals fresh;
  // What the pass does with a facet (sorted in parallel, a chunk of the
  // triangulation's facets at a time, then taken in order): a position in
  // restricted_ (unchanged and restricted), or one of these.
  constexpr int64_t kSkip = -1, kEvaluate = -2;
  auto classify = [&](const Facet& f) -> int64_t {
    if (!roles_.empty() && !active(facet_key(f))) return kSkip;
    if (!have_pass_cache_) return kEvaluate;
    const Cell_handle c = f.first, n = c->neighbor(f.second);
    const unsigned sc = c->info().value, sn = n->info().value;
    if (sc <= last_pass_stamp_ && sn <= last_pass_stamp_) {
      const std::optional<uint32_t> k = find_restricted(facet_key(f));
      return k ? static_cast<int64_t>(*k) : kSkip;
    }
    // Evaluated by the batch that made its newer cell: in batch_found_ if restricted.
    return made_by_batch(std::max(sc, sn)) ? kSkip : kEvaluate;
  };
  std::vector<Facet> scanned;
  std::vector<int64_t> verdict;
  auto take_scanned = [&] {
    verdict.resize(scanned.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, scanned.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k != r.end(); ++k) verdict[k] = classify(scanned[k]);
    });
    for (size_t k = 0; k < scanned.size(); ++k) {
      if (verdict[k] >= 0) unchanged.push_back(static_cast<uint32_t>(verdict[k]));
      if (verdict[k] != kEvaluate) continue;
      facets.push_back(scanned[k]);
      if (facets.size() == kChunk) {
        keep_restricted(facets, &fresh);
        facets.clear();
      }
    }
    scanned.clear();
  };
  const auto scan = [&](const Facet& f) {
    scanned.push_back(f);
    if (scanned.size() == 4 * kChunk) take_scanned();
  };
  if (!roles_.empty() && dt_.dimension() == 3)
    active_facets(scan);
  else
    for (auto f = dt_.finite_facets_begin(); f != dt_.finite_facets_end(); ++f) scan(*f);
  take_scanned();
  for (; !batch_found_.empty(); batch_found_.pop_front()) {
    const BatchFound& f = batch_found_.front();
    if (!still_stands(f.cell, f.index, f.stamp_c, f.stamp_n)) continue;
    // The same cells, hence the same Voronoi edge and evaluation.
    if (f.eval >= 0) {
      fresh.push_back(batch_evals_[static_cast<size_t>(f.eval)]);
      continue;
    }
    facets.emplace_back(f.cell, f.index);
    if (facets.size() == kChunk) {
      keep_restricted(facets, &fresh);
      facets.clear();
    }
  }
  batch_found_after_cleanup_ = 0;
  batch_evals_.clear();
  batch_stamps_.clear();
  keep_restricted(facets, &fresh);
  keep_pass(std::move(unchanged), std::move(fresh));
  bool clean = true;
  for (const FacetEval& e : restricted_) {
    if (e.defect != TriangleDefect::none) {
      push_if_bad(e);
      clean = false;
    }
  }
  if (!clean) return false;

  std::vector<Vertex_handle> all;
  all.reserve(dt_.number_of_vertices());
  for (auto v = dt_.finite_vertices_begin(); v != dt_.finite_vertices_end(); ++v) all.push_back(v);
  std::sort(all.begin(), all.end(), [](Vertex_handle a, Vertex_handle b) { return a->info().id < b->info().id; });
  return repair_stars(restricted_, star_checked_only(std::move(all)));
}

void Refiner::index_restricted() {
  restricted_start_.assign(static_cast<size_t>(next_id_) + 1, 0);
  restricted_rest_.resize(restricted_.size());
  for (size_t k = 0; k < restricted_.size(); ++k) {
    const FacetKey ids = facet_key(restricted_[k]);
    ++restricted_start_[static_cast<size_t>(ids[0]) + 1];
    restricted_rest_[k] = {ids[1], ids[2]};
  }
  for (size_t i = 1; i < restricted_start_.size(); ++i) restricted_start_[i] += restricted_start_[i - 1];
}

void Refiner::forget_restricted_index() {
  restricted_start_ = {};
  restricted_rest_ = {};
}

std::optional<uint32_t> Refiner::find_restricted(const FacetKey& ids) const {
  const size_t first = static_cast<size_t>(ids[0]);
  if (first + 1 >= restricted_start_.size()) return std::nullopt;  // a vertex newer than the index
  for (uint32_t k = restricted_start_[first]; k < restricted_start_[first + 1]; ++k)
    if (restricted_rest_[k] == std::pair<int, int>{ids[1], ids[2]}) return k;
  return std::nullopt;
}

// Sorts by facet key: each key computed once (a key reads three vertices),
// the keys sorted in parallel, the evaluations then permuted in place
// (sorting the 80-byte evaluations with keys computed per comparison was a
// large part of a pass on large meshes).
static void sort_by_key(FacetEvals& evals) {
  std::vector<std::pair<FacetKey, uint32_t>> order(evals.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, evals.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) order[k] = {facet_key(evals[k]), static_cast<uint32_t>(k)};
  });
  tbb::parallel_sort(order.begin(), order.end());
  // Entry i takes old entry order[i].second: follow each cycle once, marking
  // a place done by pointing it at itself.
  for (size_t i = 0; i < order.size(); ++i) {
    if (order[i].second == i) continue;
    FacetEval first = evals[i];
    size_t at = i;
    for (;;) {
      const size_t from = order[at].second;
      order[at].second = static_cast<uint32_t>(at);
      if (from == i) {
        evals[at] = first;
        break;
      }
      evals[at] = evals[from];
      at = from;
    }
  }
}

// The new pass's restricted facets: the `unchanged` entries of restricted_
// (compacted in place; the others name facets that are gone, whose vertex
// handles must not be touched) and the `fresh` evaluations.
void Refiner::keep_pass(std::vector<uint32_t> unchanged, FacetEvals fresh) {
  forget_restricted_index();
  std::sort(unchanged.begin(), unchanged.end());
  size_t kept = 0;
  for (const uint32_t k : unchanged) restricted_[kept++] = restricted_[k];
  restricted_.resize(kept);
  for (; !fresh.empty(); fresh.pop_front()) restricted_.push_back(fresh.front());
  // In the order of their vertex ids, not of CGAL's containers (whose order
  // depends on memory addresses): the mesh, the order of its vertices and of
  // the repairs are then the same in every call and every process.
  sort_by_key(restricted_);
  index_restricted();
  last_pass_stamp_ = stamp_;
  have_pass_cache_ = true;
}

// In a patch: the interior samples, and the inserted points with no
// context vertex among their Delaunay neighbours (near the context a star is
// cut off by the inactive facets, as a boundary sample's is).
std::vector<Vertex_handle> Refiner::star_checked_only(std::vector<Vertex_handle> vertices) const {
  if (roles_.empty()) return vertices;
  std::vector<Vertex_handle> neighbours;
  auto checked = [&](const Vertex_handle& v) {
    if (!star_checked(v->info().id)) return false;
    if (v->info().id < sample_ids_) return true;
    neighbours.clear();
    dt_.finite_adjacent_vertices(v, std::back_inserter(neighbours));
    return std::all_of(neighbours.begin(), neighbours.end(),
                       [&](const Vertex_handle& w) { return active(w->info().id); });
  };
  vertices.erase(std::remove_if(vertices.begin(), vertices.end(), [&](const Vertex_handle& v) { return !checked(v); }),
                 vertices.end());
  return vertices;
}

// Checks that each of `vertices` has restricted triangles forming one disk
// (its link is a single cycle, which also makes every edge shared by exactly
// two triangles) and queues or makes the repairs. `restricted` must hold every
// restricted facet around each of them. Returns true when all are disks.
// A skin point to split the restricted Voronoi cell of a sample that has no
// restricted triangle: the projection of one of its Voronoi vertices, the
// farthest from the sample. When a projection lands in another sample's cell
// (the skin in this cell is a thin sliver, as along the creases of a skin
// whose shrink factor is near 1), the skin point found by halving the way
// from the sample towards it until it falls in this cell is used instead: a
// point outside does not split this cell, and repeating it went on for
// many passes, or for ever (a tiny void whose Voronoi vertices project onto
// the outer skin). Only when no such point
// exists is an outside projection used.
std::optional<Projection> Refiner::isolated_repair_point(Vertex_handle v) const {
  std::vector<Cell_handle> cells;
  dt_.incident_cells(v, std::back_inserter(cells));
  const Eigen::Vector3d pv = to_eigen(v->point());
  const auto owner = [&](const Projection& p, Cell_handle hint) {
    return dt_.nearest_vertex(K::Point_3(p.point[0], p.point[1], p.point[2]), hint);
  };
  std::optional<Projection> best;
  bool best_in_cell = false;
  const auto consider = [&](const Projection& p, bool in_cell) {
    if (!best || (in_cell && !best_in_cell) ||
        (in_cell == best_in_cell && (p.point - pv).norm() > (best->point - pv).norm())) {
      best = p;
      best_in_cell = in_cell;
    }
  };
  for (const Cell_handle& c : cells) {
    if (dt_.is_infinite(c)) continue;
    const Eigen::Vector3d dual = to_eigen(dt_.dual(c));
    const Projection p = complex_.project(dual, v->info().cell);
    if (!p.converged || (p.point - pv).norm() < 1e-6) continue;
    const Vertex_handle nearest = owner(p, c);
    if ((to_eigen(nearest->point()) - p.point).norm() < 1e-6) continue;
    if (!active(nearest->info().id)) continue;  // a patch does not grow into its context
    if (nearest == v) {
      consider(p, true);
      continue;
    }
    consider(p, false);
    for (double f = 0.5; f > 1e-6; f *= 0.5) {
      const Projection q = complex_.project(pv + f * (dual - pv), v->info().cell);
      if (!q.converged || (q.point - pv).norm() < 1e-6) break;
      if (owner(q, c) == v) {
        consider(q, true);
        break;
      }
    }
  }
  return best;
}

bool Refiner::repair_stars(const FacetEvals& restricted, const std::vector<Vertex_handle>& vertices) {
  bool clean = true;
  // The link of each listed vertex, in one array in the order of `vertices`
  // (a map of vectors per vertex was 60 bytes a triangle at the global pass,
  // the run's peak of memory). star_slot_ maps an id to its place in
  // `vertices`; it is reset before returning.
  if (star_slot_.size() < static_cast<size_t>(next_id_)) star_slot_.resize(static_cast<size_t>(next_id_), -1);
  for (size_t k = 0; k < vertices.size(); ++k) star_slot_[static_cast<size_t>(vertices[k]->info().id)] = static_cast<int>(k);
  auto slot = [&](int id) { return star_slot_[static_cast<size_t>(id)]; };
  std::vector<int> offset(vertices.size() + 1, 0);
  std::vector<int> best_facet(vertices.size(), -1);  // per listed vertex: its restricted facet with the largest ball
  for (size_t f = 0; f < restricted.size(); ++f) {
    const FacetEval& e = restricted[f];
    for (const Vertex_handle& v : e.v) {
      const int k = slot(v->info().id);
      if (k < 0) continue;
      ++offset[static_cast<size_t>(k) + 1];
      int& best = best_facet[static_cast<size_t>(k)];
      if (best < 0 || e.radius > restricted[static_cast<size_t>(best)].radius) best = static_cast<int>(f);
    }
  }
  for (size_t k = 0; k < vertices.size(); ++k) offset[k + 1] += offset[k];
  std::vector<std::pair<int, int>> link(static_cast<size_t>(offset.back()));
  {
    std::vector<int> filled(offset.begin(), offset.end() - 1);
    for (const FacetEval& e : restricted) {
      const FacetKey ids{{e.v[0]->info().id, e.v[1]->info().id, e.v[2]->info().id}};
      for (size_t c = 0; c < 3; ++c) {
        const int k = slot(ids[c]);
        if (k >= 0) link[static_cast<size_t>(filled[static_cast<size_t>(k)]++)] = {ids[(c + 1) % 3], ids[(c + 2) % 3]};
      }
    }
  }
  for (const Vertex_handle& v : vertices) star_slot_[static_cast<size_t>(v->info().id)] = -1;
  std::vector<Vertex_handle> isolated;
  for (size_t k = 0; k < vertices.size(); ++k) {
    const size_t edges = static_cast<size_t>(offset[k + 1] - offset[k]);
    if (edges == 0) {
      // In a patch a point without triangles is simply left out of it.
      if (roles_.empty()) isolated.push_back(vertices[k]);
      continue;
    }
    if (!is_single_cycle(&link[static_cast<size_t>(offset[k])], edges)) {
      push_repair(restricted[static_cast<size_t>(best_facet[k])]);
      clean = false;
    }
  }
  // A sample with no restricted triangle: the skin around it escapes every
  // Voronoi edge of its cell. Add a skin point inside that Voronoi cell; the
  // triangulation then sees that piece (isolated_repair_point).
  for (const Vertex_handle& v : isolated) {
    const std::optional<Projection> best = isolated_repair_point(v);
    if (!best)
      throw RefinementStopped{MeshingStatus::unrepairable,
                              "a sample of the skin has no triangle and no repair point was found"};
    ++stats_.inserted_topology;
    insert(best->point, best->cell, v->cell());  // the next pass looks at it
    clean = false;
  }
  return clean;
}

SurfaceMesh Refiner::extract(const FacetEvals& restricted, std::vector<long>* origins) const {
  SurfaceMesh mesh;
  origins->clear();
  std::vector<int> index(static_cast<size_t>(next_id_), -1);
  // Every sample is on the skin and nearly all are mesh vertices: reserving
  // spares the growth slack at what is the run's peak of memory.
  const size_t vertices = dt_.number_of_vertices();
  mesh.vertices.reserve(vertices);
  mesh.normals.reserve(vertices);
  mesh.cells.reserve(vertices);
  origins->reserve(vertices);
  mesh.triangles.reserve(restricted.size());
  for (const FacetEval& e : restricted) {
    std::array<int, 3> t;
    for (int k = 0; k < 3; ++k) {
      const Vertex_handle v = e.v[static_cast<size_t>(k)];
      int& slot = index[static_cast<size_t>(v->info().id)];
      if (slot < 0) {
        slot = static_cast<int>(mesh.vertices.size());
        const Eigen::Vector3d p = to_eigen(v->point());
        const SkinEval se = complex_.evaluate(p, v->info().cell);
        mesh.vertices.push_back(p);
        mesh.normals.push_back(se.gradient.normalized());
        mesh.cells.push_back(se.cell);
        origins->push_back(v->info().id < sample_ids_ ? v->info().id : -1);
      }
      t[static_cast<size_t>(k)] = slot;
    }
    if (!e.outward_along_normal) std::swap(t[1], t[2]);
    mesh.triangles.push_back(t);
  }
  return mesh;
}

// After refinement, the stars around the vertices it inserted are checked
// here, not by another global pass: repairs come in short chains (a repair
// point upsets a neighbour), and each global pass walks every facet. The
// facets around the region are evaluated again unless both
// their cells are older than the last global pass.
void Refiner::local_passes() {
  // After a large refinement the region is most of the mesh, and one global
  // pass (which visits each facet once) is cheaper.
  const size_t most = std::max<size_t>(64, dt_.number_of_vertices() / 100);
  // Stars a round could not check (it found bad triangles, and a star is
  // only judged once its triangles are good) are checked in the next one:
  // otherwise a broken star away from the next insertions waited for the
  // next global pass, which costs more.
  std::vector<Vertex_handle> unchecked;
  for (int round = 0; round < 50 && !recent_.empty() && recent_.size() <= most; ++round) {
    std::vector<Vertex_handle> region = std::move(unchecked);
    unchecked.clear();
    for (const Vertex_handle& v : recent_) {
      region.push_back(v);
      dt_.finite_adjacent_vertices(v, std::back_inserter(region));
    }
    recent_.clear();
    std::sort(region.begin(), region.end());
    region.erase(std::unique(region.begin(), region.end()), region.end());
    FacetEvals restricted;
    bool defects = false;
    for_each_facet_around(region, [&](const Facet& f, const FacetKey& key) {
      if (!active(key)) return true;
      const Cell_handle c = f.first, n = c->neighbor(f.second);
      if (c->info().value <= last_pass_stamp_ && n->info().value <= last_pass_stamp_) {
        if (const std::optional<uint32_t> k = find_restricted(key)) restricted.push_back(restricted_[*k]);
        return true;
      }
      const FacetEval e = evaluate(f);
      if (e.crossings == 0) return true;
      restricted.push_back(e);
      if (e.defect != TriangleDefect::none) {
        push_if_bad(e);
        defects = true;
      }
      return true;
    });
    if (defects) {
      unchecked = std::move(region);
      refine();
    } else if (!repair_stars(restricted, star_checked_only(region))) {
      refine();
    }
  }
}

// Global passes and refinement until a pass finds nothing to do.
void Refiner::refine_until_clean() {
  for (;;) {
    report("checking", Report::now);
    const auto before = dt_.number_of_vertices();
    if (global_pass()) return;
    refine();
    local_passes();
    check_budget();
    // Every bad triangle found by a pass gets a new vertex unless its surface
    // ball centre coincides with a sample, which only rounding can cause
    // (flat Delaunay tetrahedra of cocircular samples). Say so, never spin.
    // Repairs of vertex stars can chase each other on degenerate sets (the
    // exactly repeated balls of a morph's B(t)); real meshes settle in a
    // few passes.
    if (stats_.passes > 200)
      throw RefinementStopped{MeshingStatus::stalled, "refinement did not settle after 200 passes", stats_};
    if (dt_.number_of_vertices() == before)
      throw RefinementStopped{MeshingStatus::stalled,
                              "refinement stalled: the bad triangles left have surface Delaunay ball centres at "
                              "existing samples (numerically degenerate Delaunay tetrahedra)"};
  }
}

SkinMeshResult Refiner::run(const std::vector<SkinSample>* samples) {
  const auto start = Clock::now();
  report("seeding", Report::now);
  // The seeds are found on the other cores while CGAL inserts the samples
  // (serial), so that a remesh (a morph frame's) does not wait for them.
  std::vector<SkinPoint> seeds;
  tbb::task_group seeding;
  seeding.run([&] { seeds = critical_point_seeds(complex_); });
  if (samples) insert_samples(*samples);
  seeding.wait();
  insert_seeds(seeds, samples ? 1.0 : 0.25);
  stats_.seconds_seeding = seconds_since(start);
  const auto refine_start = Clock::now();
  refine_until_clean();
  stats_.seconds_refining = seconds_since(refine_start);
  // Clean-up: contract short edges (one round: a contraction blocks its
  // neighbourhood for the round, and further rounds found few more), then
  // check globally and refine again if that finds anything (it should not:
  // each contraction is checked locally).
  if (options_.contract_below > 0) {
    const auto contract_start = Clock::now();
    report("contracting", Report::now);
    if (contract_short_edges(restricted_) > 0) refine_until_clean();
    stats_.seconds_contracting = seconds_since(contract_start);
  }
  forget_restricted_index();  // the passes are over: room for the mesh
  SkinMeshResult result;
  result.mesh = extract(restricted_, &result.origins);
  if (!samples) result.origins.clear();
  stats_.seconds_total = seconds_since(start);
  result.stats = stats_;
  return result;
}

bool Refiner::near_patch(const Eigen::Vector3d& p) const {
  return near_patch_.any_near(p, 1, [&](const std::pair<Eigen::Vector3d, double>& sample) {
    return (sample.first - p).squaredNorm() < sample.second * sample.second;
  });
}

PatchMeshResult Refiner::run_patch(const std::vector<SkinSample>& samples, const std::vector<PatchRole>& roles,
                                   long least_budget, const std::vector<double>& within) {
  const auto start = Clock::now();
  roles_ = roles;
  double widest = 0;
  for (size_t i = 0; i < within.size(); ++i)
    if (roles[i] != PatchRole::context) widest = std::max(widest, within[i]);
  near_patch_ = decltype(near_patch_)(widest > 0 ? widest : 1.0);
  if (widest > 0)
    for (size_t i = 0; i < samples.size(); ++i)
      if (roles[i] != PatchRole::context && within[i] > 0)
        near_patch_.insert(samples[i].point, {samples[i].point, within[i]});
  const long own = std::count_if(roles.begin(), roles.end(), [](PatchRole r) { return r != PatchRole::context; });
  patch_budget_ = std::max(2 * own + 64, least_budget);
  insert_samples(samples);
  refine_until_clean();
  PatchMeshResult result;
  std::unordered_map<int, long> added;  // id of an inserted point -> its corner number
  const long n = static_cast<long>(samples.size());
  for (const FacetEval& e : restricted_) {
    std::array<long, 3> t;
    for (size_t k = 0; k < 3; ++k) {
      const Vertex_handle v = e.v[k];
      const int id = v->info().id;
      if (id < sample_ids_) {
        t[k] = id;
        continue;
      }
      const auto [it, fresh] = added.try_emplace(id, n + static_cast<long>(result.added.size()));
      if (fresh) result.added.push_back({to_eigen(v->point()), complex_.evaluate(to_eigen(v->point()), v->info().cell).cell});
      t[k] = it->second;
    }
    if (!e.outward_along_normal) std::swap(t[1], t[2]);
    result.triangles.push_back(t);
  }
  stats_.seconds_total = seconds_since(start);
  result.stats = stats_;
  return result;
}

}  // namespace skinmesh::detail

namespace skinmesh {

const char* meshing_status_name(MeshingStatus status) {
  switch (status) {
    case MeshingStatus::ok: return "ok";
    case MeshingStatus::over_budget: return "over_budget";
    case MeshingStatus::stalled: return "stalled";
    case MeshingStatus::unrepairable: return "unrepairable";
    case MeshingStatus::empty_skin: return "empty_skin";
  }
  return "unknown";
}

namespace {

void check_options(const MeshingOptions& options) {
  if (!(options.min_angle > 0 && options.min_angle <= 30.0))
    contract_error("the angle bound must be in (0, 30] degrees (Delaunay refinement "
                                "terminates for bounds up to about 30 degrees)");
  if (!(options.tolerance > 0)) contract_error("the distance tolerance must be positive");
  if (!(options.edge_length >= 0)) contract_error("the edge length must be positive");
  if (!(options.sizing.epsilon > 0) || !(options.sizing.min_size > 0) ||
      !(options.sizing.max_size >= options.sizing.min_size))
    contract_error("sizing: epsilon and min_size must be positive, max_size >= min_size");
  if (options.max_triangles <= 0) contract_error("the triangle budget must be positive");
  if (!(options.max_memory_bytes >= 0) || !std::isfinite(options.max_memory_bytes))
    contract_error("the memory limit must be a finite number of bytes, or 0 for none");
  if (!(options.contract_below >= 0 && options.contract_below < 1))
    contract_error("the contraction threshold must be in [0, 1) times the target edge length");
}

// A lower bound of the triangles any mesh meeting `options` has, known
// before refinement: the skin body holds every ball shrunk by sqrt(s)
// (conv B holds every ball), so the skin's area is at least that of the
// largest such sphere, 4 pi s w_max (a closed surface around a convex body
// has at least its area); a triangle whose surface ball has radius at most
// L / sqrt(3) has area at most (sqrt(3)/4) L^2, and the target edge length
// L is nowhere above the largest size or the edge length cap. Halved, for an
// inscribed mesh has a little less area than the skin.
double triangles_at_least(const SkinComplex& complex, const MeshingOptions& options) {
  double w_max = 0;
  for (const Ball& b : complex.balls()) w_max = std::max(w_max, b.weight);
  double longest = options.sizing.max_size;
  if (options.edge_length > 0) longest = std::min(longest, options.edge_length);
  return 0.5 * 4 * M_PI * complex.shrink() * w_max / (std::sqrt(3.0) / 4 * longest * longest);
}

// A count for a message: whole below 1e15, else in powers of ten (never cast
// past the range of an integer).
std::string rounded_count(double n) {
  if (n < 1e15) return std::to_string(std::llround(n));
  std::ostringstream text;
  text << std::setprecision(3) << n;
  return text.str();
}

// mesh_skin's refusal before refinement: even the low end of the estimate
// passes what the options afford (triangle budget or memory).
std::optional<SkinMeshResult> refuse_if_unaffordable(const SkinAreaProfile& profile, const TriangleEstimate& estimate,
                                                     double shrink, const MeshingOptions& options) {
  const double affordable = affordable_triangles(options);
  if (estimate.low() <= affordable) return std::nullopt;
  const double expected = estimate.triangles;
  const double spread = estimate.creases > expected / 2 ? kCreaseEstimateSpread : kTriangleEstimateSpread;
  SkinMeshResult refused;
  refused.status = MeshingStatus::over_budget;
  refused.estimated_triangles = expected;
  refused.fitting_sizes = sizes_that_fit(profile, options, affordable);
  if (refused.fitting_sizes.empty()) refused.fitting_shrink = shrink_that_fits(estimate, shrink, affordable);
  std::ostringstream text;
  text << "the skin needs about " << rounded_count(expected) << " triangles at these sizes (estimated from its area, "
       << rounded_count(profile.area) << " A^2, before refinement; within "
       << std::lround((spread - 1) * 100) << "% either way), more than ";
  if (affordable < static_cast<double>(options.max_triangles))
    text << "the memory allows (about " << std::setprecision(3) << estimate.peak_bytes / 1e9
         << " GB needed, " << options.max_memory_bytes / 1e9 << " GB available)";
  else
    text << "the budget of " << options.max_triangles << " triangles";
  if (refused.fitting_shrink > 0)
    text << "; most of them (about " << rounded_count(estimate.creases)
         << ") along necks sharper than any size asks for, as the shrink factor is close to 1 (" << shrink
         << "), which no coarser size changes; a shrink factor of at most " << refused.fitting_shrink << " would fit";
  else if (refused.fitting_sizes.empty())
    text << "; no coarser sizes fit it: the skin has more small patches than this budget allows";
  else {
    text << "; sizes that would fit:";
    const char* between_fits = " ";
    for (const FittingSize& fit : refused.fitting_sizes) {
      text << between_fits;
      const char* between_changes = "";
      for (const SizeChange& change : fit.changes) {
        text << between_changes << size_option_name(change.option) << " " << std::setprecision(2) << change.value;
        between_changes = " with ";
      }
      between_fits = ", or ";
    }
  }
  refused.message = text.str();
  return refused;
}

SkinMeshResult run_refiner(const SkinComplex& complex, const std::vector<SkinSample>* samples,
                           const MeshingOptions& options) {
  check_options(options);
  std::optional<tbb::global_control> threads;
  if (options.threads > 0)
    threads.emplace(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(options.threads));
  // With every weight <= 0 every power distance is >= 0, so F >= 0 (docs/math.md
  // section 2): the body is empty and so is the skin.
  if (std::none_of(complex.balls().begin(), complex.balls().end(), [](const Ball& b) { return b.weight > 0; })) {
    SkinMeshResult empty;
    empty.status = MeshingStatus::empty_skin;
    empty.message = "the skin of this ball set is empty: no ball has a positive weight";
    return empty;
  }
  // The estimate from the skin's area first, for its refusal names the sizes
  // that fit (mesh_skin only: a morph frame's remesh starts from a mesh that
  // fitted, and the profile would cost it time); the lower bound after it
  // guards remesh_skin too.
  double expected_triangles = 0;
  if (!samples) {
    const SkinAreaProfile profile = skin_area_profile(complex);
    const TriangleEstimate estimate = estimate_triangles(profile, options);
    expected_triangles = estimate.triangles;
    if (auto refused = refuse_if_unaffordable(profile, estimate, complex.shrink(), options)) return *refused;
  }
  if (const double least = triangles_at_least(complex, options); least > static_cast<double>(options.max_triangles)) {
    SkinMeshResult refused;
    refused.status = MeshingStatus::over_budget;
    refused.message = "the skin needs at least " + std::to_string(std::llround(least)) +
                      " triangles at these sizes (its largest ball alone), more than the budget of " +
                      std::to_string(options.max_triangles) +
                      " triangles; raise the budget or ask for larger triangles (a larger edge length or maximum size)";
    return refused;
  }
  detail::Refiner refiner(complex, options);
  refiner.expect_vertices(expected_triangles / 2);  // a closed surface mesh: about two triangles per vertex
  try {
    SkinMeshResult result = refiner.run(samples);
    result.estimated_triangles = expected_triangles;
    return result;
  } catch (const detail::RefinementStopped& stop) {
    SkinMeshResult result;
    result.status = stop.status;
    result.message = stop.message;
    result.estimated_triangles = expected_triangles;
    if (stop.status == MeshingStatus::over_budget && expected_triangles > 0) {
      const size_t cut = std::min(result.message.find(';'), result.message.size());
      result.message.insert(cut, " (estimated before refinement: about " + rounded_count(expected_triangles) + ")");
    }
    return result;
  }
}

}  // namespace

SkinMeshResult mesh_skin(const SkinComplex& complex, const MeshingOptions& options) {
  return run_refiner(complex, nullptr, options);
}

SkinMeshResult remesh_skin(const SkinComplex& complex, const std::vector<SkinSample>& samples,
                           const MeshingOptions& options) {
  return run_refiner(complex, &samples, options);
}

PatchMeshResult mesh_patch(const SkinComplex& complex, const std::vector<SkinSample>& samples,
                           const std::vector<PatchRole>& roles, const MeshingOptions& options, long least_budget,
                           const std::vector<double>& within) {
  check_options(options);
  if (roles.size() != samples.size()) contract_error("mesh_patch: one role per sample");
  if (!within.empty() && within.size() != samples.size())
    contract_error("mesh_patch: one distance per sample in `within`, or none");
  std::optional<tbb::global_control> threads;
  if (options.threads > 0)
    threads.emplace(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(options.threads));
  detail::Refiner refiner(complex, options);
  try {
    return refiner.run_patch(samples, roles, least_budget, within);
  } catch (const detail::RefinementStopped& stop) {
    PatchMeshResult result;
    result.status = stop.status;
    result.message = stop.message;
    result.stats = stop.stats;
    return result;
  }
}

}  // namespace skinmesh
