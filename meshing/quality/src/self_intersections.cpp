// Exact self-intersection count: a uniform grid (or, for boxes of very
// unequal sizes, CGAL's box intersection) finds the pairs of triangles
// whose bounding boxes meet, and CGAL's exact predicates decide each pair,
// on the triangles' vertex indices (no halfedge mesh is built: building one
// was a tenth of the count). A pair sharing a vertex whose star is the
// graph of a function over a coordinate plane (graph_stars, proven by
// exact orientations once a vertex) needs no test of its own: on a quality
// mesh of a smooth surface nearly every vertex's star is one, and nearly
// every pair of meeting boxes shares a vertex. CGAL stays in this file.
#include "skinmesh/quality/mesh_quality.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/vertex_stars.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

namespace skinmesh {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int, CGAL::Box_intersection_d::ID_FROM_BOX_ADDRESS>;

K::Point_3 point(const SurfaceMesh& mesh, int v) {
  const Eigen::Vector3d& p = mesh.vertices[static_cast<size_t>(v)];
  return {p.x(), p.y(), p.z()};
}

bool degenerate(const SurfaceMesh& mesh, const std::array<int, 3>& t) {
  return t[0] == t[1] || t[1] == t[2] || t[0] == t[2] ||
         CGAL::collinear(point(mesh, t[0]), point(mesh, t[1]), point(mesh, t[2]));
}

// Whether two non-degenerate triangles meet in more than the vertices and
// edge they share (by index). Sharing an edge uv with far corners p and q:
// only when p, u, v, q are coplanar and p, q lie on the same side of uv.
// Sharing a vertex w: the two meet along the line through w common to both
// planes (or in their common plane), and beyond w exactly when the edge
// opposite w of one triangle meets the other triangle. Sharing nothing: when
// they meet at all. All three sets of vertices the same: they coincide.
bool triangles_cross(const SurfaceMesh& mesh, const std::array<int, 3>& a, const std::array<int, 3>& b) {
  int shared = 0, ia = -1, ib = -1;  // a[ia] == b[ib] for the last shared pair
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a[i] == b[j]) ++shared, ia = i, ib = j;
  if (shared == 3) return true;
  const std::array<K::Point_3, 3> pa{point(mesh, a[0]), point(mesh, a[1]), point(mesh, a[2])};
  const std::array<K::Point_3, 3> pb{point(mesh, b[0]), point(mesh, b[1]), point(mesh, b[2])};
  const auto at = [](const std::array<K::Point_3, 3>& t, int i) -> const K::Point_3& {
    return t[static_cast<size_t>(i % 3)];
  };
  if (shared == 2) {
    // The corner of a not in b, and of b not in a; u, v the shared corners.
    int far_a = 0, far_b = 0;
    while (std::find(b.begin(), b.end(), a[static_cast<size_t>(far_a)]) != b.end()) ++far_a;
    while (std::find(a.begin(), a.end(), b[static_cast<size_t>(far_b)]) != a.end()) ++far_b;
    const K::Point_3 &u = at(pa, far_a + 1), &v = at(pa, far_a + 2), &p = at(pa, far_a), &q = at(pb, far_b);
    return CGAL::coplanar(u, v, p, q) && CGAL::coplanar_orientation(u, v, p, q) == CGAL::POSITIVE;
  }
  if (shared == 0) return CGAL::do_intersect(K::Triangle_3(pa[0], pa[1], pa[2]), K::Triangle_3(pb[0], pb[1], pb[2]));
  // A triangle whose edge opposite the shared corner lies strictly on one
  // side of the other's plane touches that plane only at the shared
  // corner: the usual case on a smooth surface, decided by two orientations
  // instead of two triangle-segment tests.
  const auto off_plane = [](const std::array<K::Point_3, 3>& t, const K::Point_3& s, const K::Point_3& e) {
    const CGAL::Orientation o = CGAL::orientation(t[0], t[1], t[2], s);
    return o != CGAL::COPLANAR && o == CGAL::orientation(t[0], t[1], t[2], e);
  };
  if (off_plane(pb, at(pa, ia + 1), at(pa, ia + 2)) || off_plane(pa, at(pb, ib + 1), at(pb, ib + 2))) return false;
  const K::Triangle_3 ta(pa[0], pa[1], pa[2]), tb(pb[0], pb[1], pb[2]);
  return CGAL::do_intersect(ta, K::Segment_3(at(pb, ib + 1), at(pb, ib + 2))) ||
         CGAL::do_intersect(tb, K::Segment_3(at(pa, ia + 1), at(pa, ia + 2)));
}

// Whether the wedges `link` (a, b) about v make one fan that is a graph
// over a coordinate plane (graph_stars).
bool star_is_graph(const SurfaceMesh& mesh, int v, const std::vector<std::array<int, 2>>& link) {
  const size_t k = link.size();
  if (k < 3) return false;
  // One cycle: the wedges' a are distinct and so are their b, and
  // following a -> b from the first wedge meets every wedge once before
  // it returns (each b then starts a wedge: the b are the a).
  for (size_t i = 0; i < k; ++i)
    for (size_t j = i + 1; j < k; ++j)
      if ((link[i][0] == link[j][0]) | (link[i][1] == link[j][1])) return false;
  size_t at = 0;
  for (size_t step = 1; step <= k; ++step) {
    size_t next = 0;
    while (next < k && link[next][0] != link[at][1]) ++next;
    if (next == k || (next == 0) != (step == k)) return false;
    at = next;
  }
  const auto& V = mesh.vertices;
  const Eigen::Vector3d& c = V[static_cast<size_t>(v)];
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& w : link) normal += (V[static_cast<size_t>(w[0])] - c).cross(V[static_cast<size_t>(w[1])] - c);
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  if (normal[axis] == 0 || !std::isfinite(normal[axis])) return false;
  // The other two coordinates in cyclic order: looking down the axis, a
  // wedge whose normal points along +axis turns counterclockwise.
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  const auto flat = [&](int u) { return K::Point_2(V[static_cast<size_t>(u)][i], V[static_cast<size_t>(u)][j]); };
  const CGAL::Orientation turn = normal[axis] > 0 ? CGAL::LEFT_TURN : CGAL::RIGHT_TURN;
  const K::Point_2 centre = flat(v);
  for (const auto& w : link)
    if (CGAL::orientation(centre, flat(w[0]), flat(w[1])) != turn) return false;
  // Every wedge turns less than half a turn, and the wedges' angular
  // intervals [a, b), end to end round the cycle, cover every direction
  // as often as the fan winds about the centre. The direction of the first
  // wedge's a is in a wedge's [a, b) when it is past a (or along a:
  // collinear, and then b turns from it as from a) and not yet at b. The
  // first wedge holds it and the wedge ending at its a does not: both are
  // decided by index (a predicate on a repeated point falls back to exact
  // arithmetic, and is slow).
  const int first_a = link[0][0];
  const K::Point_2 along = flat(first_a);
  int holding = 1;
  for (size_t w = 1; w < k; ++w) {
    const auto& [a, b] = link[w];
    if (b == first_a) continue;
    const CGAL::Orientation from_a = CGAL::orientation(centre, flat(a), along);
    holding += (from_a == turn || from_a == CGAL::COLLINEAR) && CGAL::orientation(centre, along, flat(b)) == turn;
  }
  return holding == 1;
}

// Per vertex, 1 where its star is the graph of a function over one of the
// coordinate planes: the triangles around v, each (v, a, b) in the mesh's
// orientation, form one fan whose link a -> b is a single cycle; dropping
// the coordinate along which their normals' sum is longest, every
// projected wedge (v, a, b) turns the same way (exact orientations: the
// projection drops a coordinate, no rounding); and the wedges wind about v
// once (a ray from v along the first wedge's edge lies in exactly one
// wedge, each counted half-open). The wedges then tile a star-shaped
// polygon without overlap, and two triangles of the star meet only where
// they share v or an edge through v: no pair sharing v needs a test.
// `wanted`: per vertex, whether its star is asked about.
std::vector<char> graph_stars(const SurfaceMesh& mesh, const std::vector<char>& wanted) {
  const size_t n = mesh.vertices.size();
  const VertexStars stars(mesh);
  std::vector<char> out(n, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<std::array<int, 2>> link;  // per wedge: a, b
    for (size_t v = r.begin(); v != r.end(); ++v) {
      if (!wanted[v]) continue;
      link.clear();
      for (const int* f = stars.begin(static_cast<int>(v)); f != stars.end(static_cast<int>(v)); ++f) {
        const auto& t = mesh.triangles[static_cast<size_t>(*f)];
        const int at = t[0] == static_cast<int>(v) ? 0 : t[1] == static_cast<int>(v) ? 1 : 2;
        link.push_back({t[static_cast<size_t>((at + 1) % 3)], t[static_cast<size_t>((at + 2) % 3)]});
      }
      out[v] = star_is_graph(mesh, static_cast<int>(v), link);
    }
  });
  return out;
}

Box box_of(const SurfaceMesh& mesh, int f) {
  const auto& t = mesh.triangles[static_cast<size_t>(f)];
  const Eigen::Vector3d& a = mesh.vertices[static_cast<size_t>(t[0])];
  const Eigen::Vector3d& b = mesh.vertices[static_cast<size_t>(t[1])];
  const Eigen::Vector3d& c = mesh.vertices[static_cast<size_t>(t[2])];
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = std::min({a[k], b[k], c[k]}), hi[k] = std::max({a[k], b[k], c[k]});
  return Box(lo, hi, f);
}

// The triangles cut into `slabs` ranges of x at quantiles of their boxes'
// middles; a triangle goes to every slab its x extent meets, so every pair
// whose boxes meet lies wholly in a slab (the one holding an x both reach).
std::vector<std::vector<const Box*>> cut_into_slabs(const std::vector<Box>& boxes, size_t slabs,
                                                   std::vector<double>& cut) {
  std::vector<double> middle;
  middle.reserve(boxes.size());
  for (const Box& b : boxes) middle.push_back(0.5 * (b.min_coord(0) + b.max_coord(0)));
  cut.clear();  // slab k is [cut[k-1], cut[k]], the outer ones open
  for (size_t k = 1; k < slabs; ++k) {
    auto at = middle.begin() + static_cast<long>(middle.size() * k / slabs);
    std::nth_element(middle.begin(), at, middle.end());
    cut.push_back(*at);
  }
  std::sort(cut.begin(), cut.end());
  std::vector<std::vector<const Box*>> slab(slabs);
  for (const Box& b : boxes) {
    const size_t first = static_cast<size_t>(std::lower_bound(cut.begin(), cut.end(), b.min_coord(0)) - cut.begin());
    const size_t last = static_cast<size_t>(std::upper_bound(cut.begin(), cut.end(), b.max_coord(0)) - cut.begin());
    for (size_t k = first; k <= std::min(last, slabs - 1); ++k) slab[k].push_back(&b);
  }
  return slab;
}

// Past the bound on box pairs, the callback throws this to leave CGAL's
// box intersection at once.
struct OverBound {};

// What the slabs share: the box pairs examined so far, against the bound.
struct BoxPairs {
  long max = 0;
  std::atomic<long> seen{0};
  std::atomic<bool> over{false};
};

// A pair's boxes both reach x = max of their lower x ends: the slab holding
// that x, the one slab of those holding both that counts the pair, so that a
// pair found in two slabs is counted once without storing any pair.
size_t owner_slab(const std::vector<double>& cut, const Box& a, const Box& b) {
  const double x = std::max(a.min_coord(0), b.min_coord(0));
  return static_cast<size_t>(std::lower_bound(cut.begin(), cut.end(), x) - cut.begin());
}

// CGAL's cutoff below which a range is scanned instead of split: 2,000, as
// CGAL's own self-intersection test uses (smaller ones were slower).
constexpr std::ptrdiff_t kBoxCutoff = 2000;

// Counts the crossing pairs CGAL's box intersection reports, against the
// shared bound on box pairs; with `cut` not empty, only the pairs slab
// `slab` owns (owner_slab). Past the bound it throws OverBound.
struct PairCounter {
  const SurfaceMesh& mesh;
  BoxPairs& shared;
  const std::vector<char>* graph = nullptr;  // per vertex: its star is a graph (graph_stars)
  const std::vector<double>* cut = nullptr;
  size_t slab = 0;
  long crossing = 0, unreported = 0;  // box pairs not yet added to shared.seen
  void count_pair() {
    // The shared count is updated in batches: an atomic add per pair would
    // cost more than most pairs' predicates.
    if (++unreported == 4096) {
      if (shared.seen.fetch_add(unreported) + unreported > shared.max || shared.over) throw OverBound{};
      unreported = 0;
    }
  }
  void operator()(const Box* x, const Box* y) {
    count_pair();
    if (cut && !cut->empty() && owner_slab(*cut, *x, *y) != slab) return;
    const std::array<int, 3>& a = mesh.triangles[static_cast<size_t>(x->info())];
    const std::array<int, 3>& b = mesh.triangles[static_cast<size_t>(y->info())];
    if (!in_a_graph_star(a, b)) crossing += triangles_cross(mesh, a, b);
  }
  // Whether a and b share a vertex whose star is a graph: they meet only
  // where they share it or an edge through it (graph_stars).
  bool in_a_graph_star(const std::array<int, 3>& a, const std::array<int, 3>& b) const {
    if (!graph) return false;
    for (int u : a)  // three comparisons, not std::find, which was not inlined
      if ((u == b[0]) | (u == b[1]) | (u == b[2]) && (*graph)[static_cast<size_t>(u)]) return true;
    return false;
  }
};

// Runs one of CGAL's box intersections with `counter`; its count, or
// `over` set past the bound.
template <class Run>
long count_pairs(PairCounter counter, Run run) {
  try {
    run(counter);
    counter.shared.seen += counter.unreported;
  } catch (const OverBound&) {
    counter.shared.over = true;
  }
  return counter.crossing;
}

// The crossing pairs slab k of `cut`'s slabs owns (CGAL sorts the slab's
// boxes in place); stops (over set) when the slabs together pass the bound
// on box pairs.
long count_slab(const SurfaceMesh& mesh, std::vector<const Box*>& slab, size_t k, const std::vector<double>& cut,
                BoxPairs& shared, const std::vector<char>& graph) {
  return count_pairs(PairCounter{mesh, shared, &graph, &cut, k}, [&](PairCounter& c) {
    CGAL::box_self_intersection_d<CGAL::Sequential_tag>(slab.begin(), slab.end(), std::ref(c), kBoxCutoff);
  });
}

// A uniform grid over boxes: cells twice as wide as the median box, so
// that a box of a quality mesh reaches a few, spanning the boxes' reach.
struct GridFrame {
  Eigen::Array3d lo;
  double cell = 1;
  Eigen::Array3i size;

  // Over the boxes `each` visits (each(f) with f(const Box&)); false when
  // there are none, a coordinate is not finite, or the grid would have
  // more than `cells_per_box` cells a box (and 4096).
  template <class Each>
  bool fit(Each each, double cells_per_box) {
    std::vector<double> extent;
    Eigen::AlignedBox3d reach;
    each([&](const Box& b) {
      double e = 0;
      for (int k = 0; k < 3; ++k) e = std::max(e, b.max_coord(k) - b.min_coord(k));
      extent.push_back(e);
      reach.extend(Eigen::Vector3d(b.min_coord(0), b.min_coord(1), b.min_coord(2)));
      reach.extend(Eigen::Vector3d(b.max_coord(0), b.max_coord(1), b.max_coord(2)));
    });
    if (extent.empty() || !reach.sizes().allFinite()) return false;
    std::nth_element(extent.begin(), extent.begin() + static_cast<long>(extent.size() / 2), extent.end());
    cell = std::max(2 * extent[extent.size() / 2], 1e-9 * (1 + reach.sizes().maxCoeff()));
    lo = reach.min().array();
    const Eigen::Array3d cells = ((reach.max().array() - lo) / cell).floor() + 1;
    if (!(cells.prod() <= cells_per_box * static_cast<double>(extent.size()) + 4096)) return false;
    size = cells.cast<int>();
    return true;
  }
  size_t cells() const { return static_cast<size_t>(size.prod()); }
  // The cell coordinate of x along axis k, clamped to the grid (order kept).
  int coordinate(double x, int k) const {
    return std::clamp(static_cast<int>(std::floor((x - lo[k]) / cell)), 0, size[k] - 1);
  }
  size_t index(int i, int j, int k) const {
    return (static_cast<size_t>(i) * static_cast<size_t>(size[1]) + static_cast<size_t>(j)) * static_cast<size_t>(size[2]) +
           static_cast<size_t>(k);
  }
  // on_cell(c) for the cells box b meets (clamped to the grid) until it
  // returns true; whether one did. A box wholly outside meets none.
  template <class OnCell>
  bool visit(const Box& b, OnCell on_cell) const {
    for (int k = 0; k < 3; ++k)
      if (std::floor((b.max_coord(k) - lo[k]) / cell) < 0 || std::floor((b.min_coord(k) - lo[k]) / cell) >= size[k])
        return false;
    int first[3], last[3];
    for (int k = 0; k < 3; ++k) first[k] = coordinate(b.min_coord(k), k), last[k] = coordinate(b.max_coord(k), k);
    for (int i = first[0]; i <= last[0]; ++i)
      for (int j = first[1]; j <= last[1]; ++j)
        for (int k = first[2]; k <= last[2]; ++k)
          if (on_cell(index(i, j, k))) return true;
    return false;
  }
};

// The box pairs of a uniform grid's cells. Among the boxes the first
// `wanted` are paired with every box, the rest only with those: the pairs
// of two boxes from the rest are not looked at. A pair is counted in the
// one cell holding the lowest corner of the two boxes' intersection, which
// both reach. The cells are twice as wide as the median box, so a box of a
// quality mesh reaches a few cells and a cell holds a few dozen boxes (on
// 266,000-triangle frames of a moving protein the whole count took a
// quarter to a third less time on one core than with CGAL's box
// intersection). Boxes of unequal sizes
// (a few boxes far larger than the rest, a sparse cloud) make the grid too
// large or its cells too full: then nothing is counted and the caller uses
// CGAL's box intersection.
class BoxGrid {
 public:
  // False when the grid does not suit the boxes.
  bool build(const std::vector<const Box*>& boxes) {
    if (!grid_.fit([&](auto take) { for (const Box* b : boxes) take(*b); }, 4)) return false;
    const double n = static_cast<double>(boxes.size());
    start_.assign(grid_.cells() + 1, 0);
    size_t entries = 0;
    for (const Box* b : boxes) {
      grid_.visit(*b, [&](size_t c) { return ++entries, ++start_[c + 1], false; });
      if (static_cast<double>(entries) > 8 * n + 4096) return false;
    }
    // Boxes that crowd a cell without meeting (plates stacked closer than
    // a cell) are compared pair by pair and never reach the bound on box
    // pairs: past a few hundred comparisons a box, CGAL's box intersection
    // counts instead.
    double comparisons = 0;
    for (size_t c = 1; c < start_.size(); ++c) comparisons += 0.5 * static_cast<double>(start_[c]) * static_cast<double>(start_[c]);
    if (comparisons > 256 * n + 1e6) return false;
    for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    items_.resize(entries);
    std::vector<size_t> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < boxes.size(); ++i) {
      const Item item = item_of(*boxes[i], static_cast<int>(i));
      grid_.visit(*boxes[i], [&](size_t c) { return items_[fill[c]++] = item, false; });
    }
    return true;
  }

  // The crossing pairs of boxes that meet, at least one of them among the
  // first `wanted`; throws OverBound (through `shared`) past the bound.
  long count(const SurfaceMesh& mesh, const std::vector<const Box*>& boxes, size_t wanted, BoxPairs& shared,
             const std::vector<char>& graph) const {
    const auto meet = [](const Box& x, const Box& y) {
      for (int k = 0; k < 3; ++k)
        if (x.max_coord(k) < y.min_coord(k) || y.max_coord(k) < x.min_coord(k)) return false;
      return true;
    };
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, start_.size() - 1, 512), 0L,
        [&](const tbb::blocked_range<size_t>& r, long sum) {
          PairCounter counter{mesh, shared, &graph};
          std::vector<size_t> near;  // the items of the cell whose float boxes meet p's
          for (size_t c = r.begin(); c != r.end(); ++c)
            for (size_t a = start_[c]; a < start_[c + 1]; ++a) {
              const Item& p = items_[a];
              if (static_cast<size_t>(p.box) >= wanted) break;  // a cell's boxes ascend: the rest are not wanted
              // Written without a branch: whether two boxes of a cell meet
              // is close to a coin toss, and its mispredicted branch was
              // most of this loop's time.
              near.resize(start_[c + 1] - a);
              size_t found = 0;
              for (size_t b = a + 1; b < start_[c + 1]; ++b) {
                near[found] = b;
                found += may_meet(p, items_[b]);
              }
              for (size_t i = 0; i < found; ++i) {
                const Item& q = items_[near[i]];
                if (owner(p, q) != c) continue;
                // Most pairs share a vertex whose star is a graph: decided
                // from their corners before their boxes are read again
                // (boxes that share a corner meet).
                if (counter.in_a_graph_star(mesh.triangles[static_cast<size_t>(p.triangle)],
                                            mesh.triangles[static_cast<size_t>(q.triangle)])) {
                  counter.count_pair();
                  continue;
                }
                const Box& x = *boxes[static_cast<size_t>(p.box)];
                const Box& y = *boxes[static_cast<size_t>(q.box)];
                if (meet(x, y)) counter(&x, &y);
              }
            }
          shared.seen += counter.unreported;
          return sum + counter.crossing;
        },
        std::plus<>());
  }

 private:
  // A box in a cell's list, widened to floats (rounded outwards) so that a
  // cell's boxes lie side by side in memory: two boxes that meet have
  // items that meet, and only those are compared exactly.
  struct Item {
    float lo[3], hi[3];
    int box;
    int triangle;  // the box's (its info)
    int first[3];  // the box's first cell
  };
  Item item_of(const Box& b, int box) const {
    Item item{};
    for (int k = 0; k < 3; ++k) {
      item.first[k] = grid_.coordinate(b.min_coord(k), k);
      item.lo[k] = static_cast<float>(b.min_coord(k));
      if (item.lo[k] > b.min_coord(k)) item.lo[k] = std::nextafter(item.lo[k], -std::numeric_limits<float>::infinity());
      item.hi[k] = static_cast<float>(b.max_coord(k));
      if (item.hi[k] < b.max_coord(k)) item.hi[k] = std::nextafter(item.hi[k], std::numeric_limits<float>::infinity());
    }
    item.box = box;
    item.triangle = b.info();
    return item;
  }
  // Bitwise and, not &&: one value to branch on (or none, above).
  static bool may_meet(const Item& p, const Item& q) {
    return !(p.hi[0] < q.lo[0]) & !(q.hi[0] < p.lo[0]) & !(p.hi[1] < q.lo[1]) & !(q.hi[1] < p.lo[1]) &
           !(p.hi[2] < q.lo[2]) & !(q.hi[2] < p.lo[2]);
  }

  // The cell of the lowest corner of two meeting boxes' intersection: its
  // coordinates are the larger of the two boxes' first cells (coordinate()
  // keeps the order of the numbers it is given).
  size_t owner(const Item& p, const Item& q) const {
    return grid_.index(std::max(p.first[0], q.first[0]), std::max(p.first[1], q.first[1]),
                       std::max(p.first[2], q.first[2]));
  }
  GridFrame grid_;
  std::vector<size_t> start_;  // per cell, its first entry in items_ (one more at the end)
  std::vector<Item> items_;    // per cell, its boxes, ascending
};

// The crossing pairs the grid finds (see BoxGrid), or nothing when the
// grid does not suit the boxes.
std::optional<long> count_by_grid(const SurfaceMesh& mesh, const std::vector<const Box*>& boxes, size_t wanted,
                                  BoxPairs& shared, const std::vector<char>& graph) {
  BoxGrid grid;
  if (!grid.build(boxes)) return std::nullopt;
  try {
    return grid.count(mesh, boxes, wanted, shared, graph);
  } catch (const OverBound&) {
    shared.over = true;
    return 0L;
  }
}

}  // namespace

// CGAL's own parallel mode shuffles the boxes and was slower here. Instead
// the slabs are checked each as a task of its own (beside the oracle's, so
// the cores share them). Pairs are counted, never stored: a mesh whose
// triangles nearly all cross (thousands of copies of one body) has a number
// of crossing pairs that grows as the square of its size.
SelfIntersectionCount check_self_intersections(const SurfaceMesh& mesh, long max_box_pairs) {
  SelfIntersectionCount result;
  for (const auto& t : mesh.triangles)
    if (degenerate(mesh, t)) {
      result.degenerate = true;
      return result;
    }
  std::vector<Box> boxes;
  boxes.reserve(mesh.triangles.size());
  for (size_t f = 0; f < mesh.triangles.size(); ++f) boxes.push_back(box_of(mesh, static_cast<int>(f)));
  BoxPairs shared;
  shared.max = max_box_pairs;
  std::vector<const Box*> every;
  every.reserve(boxes.size());
  for (const Box& b : boxes) every.push_back(&b);
  const auto counted = [&](long pairs) {
    result.box_pairs = shared.seen;
    result.over_bound = shared.over || result.box_pairs > max_box_pairs;
    result.pairs = pairs;
    return result;
  };
  const std::vector<char> graph = graph_stars(mesh, std::vector<char>(mesh.vertices.size(), 1));
  if (const std::optional<long> pairs = count_by_grid(mesh, every, every.size(), shared, graph)) {
    result.by_grid = true;
    return counted(*pairs);
  }
  // Two slabs from 180,000 triangles, else one: each slab costs the box
  // intersection more than its share, and more slabs were slower.
  const size_t slabs = std::clamp<size_t>(boxes.size() / 90000, 1, 2);
  std::vector<double> cut;
  std::vector<std::vector<const Box*>> slab = cut_into_slabs(boxes, slabs, cut);
  std::vector<long> crossing(slabs, 0);
  tbb::parallel_for(size_t{0}, slabs, [&](size_t k) { crossing[k] = count_slab(mesh, slab[k], k, cut, shared, graph); });
  long pairs = 0;
  for (long c : crossing) pairs += c;
  return counted(pairs);
}

namespace {

// The boxes of a changed and an unchanged triangle that may meet: the
// unchanged ones in a cell of a uniform grid that a changed box reaches,
// and (with `changed_too`) the changed ones in a cell that such an
// unchanged box reaches (two boxes that meet share a point, and so a
// cell; on a hinge frame 7,100 of 115,000 changed boxes). The cells are
// twice as wide as the median changed box, so a box reaches a few; every
// box of either kind when the grid would be larger than the changed boxes'
// count warrants (a few huge boxes).
struct NearPairs {
  std::vector<const Box*> changed, unchanged;
};

NearPairs near_changed(const std::vector<Box>& boxes, const std::vector<char>& changed, bool changed_too) {
  NearPairs out;
  if (std::find(changed.begin(), changed.end(), 1) == changed.end()) return out;
  GridFrame grid;
  const auto each_changed = [&](auto take) {
    for (size_t f = 0; f < boxes.size(); ++f)
      if (changed[f]) take(boxes[f]);
  };
  if (!grid.fit(each_changed, 16)) {
    for (size_t f = 0; f < boxes.size(); ++f)
      if (!changed[f] || changed_too) (changed[f] ? out.changed : out.unchanged).push_back(&boxes[f]);
    return out;
  }
  // Per cell: 1 when a changed box reaches it, 2 when a kept unchanged one does too.
  std::vector<char> mark(grid.cells(), 0);
  for (size_t f = 0; f < boxes.size(); ++f)
    if (changed[f]) grid.visit(boxes[f], [&](size_t c) { return mark[c] = 1, false; });
  for (size_t f = 0; f < boxes.size(); ++f)
    if (!changed[f] && grid.visit(boxes[f], [&](size_t c) { return mark[c] != 0; })) {
      out.unchanged.push_back(&boxes[f]);
      if (changed_too) grid.visit(boxes[f], [&](size_t c) { return mark[c] = mark[c] ? 2 : 0, false; });
    }
  if (changed_too)
    for (size_t f = 0; f < boxes.size(); ++f)
      if (changed[f] && grid.visit(boxes[f], [&](size_t c) { return mark[c] == 2; })) out.changed.push_back(&boxes[f]);
  return out;
}

}  // namespace

// The pairs of two changed triangles (one box self-intersection) and of a
// changed and an unchanged one near it (one bipartite box intersection),
// side by side. Pairs of two unchanged triangles are not looked at.
SelfIntersectionCount check_changed_self_intersections(const SurfaceMesh& mesh, const std::vector<char>& changed,
                                                       long max_box_pairs) {
  if (changed.size() != mesh.triangles.size())
    contract_error("check_changed_self_intersections: one flag per triangle");
  SelfIntersectionCount result;
  std::vector<Box> boxes;
  boxes.reserve(mesh.triangles.size());
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (changed[f] && degenerate(mesh, mesh.triangles[f])) {
      result.degenerate = true;
      return result;
    }
    boxes.push_back(box_of(mesh, static_cast<int>(f)));
  }
  std::vector<const Box*> among;  // the changed boxes
  for (size_t f = 0; f < boxes.size(); ++f)
    if (changed[f]) among.push_back(&boxes[f]);
  const bool all_changed = std::find(changed.begin(), changed.end(), 0) == changed.end();
  const std::vector<const Box*> unchanged =
      all_changed ? std::vector<const Box*>() : near_changed(boxes, changed, false).unchanged;
  BoxPairs shared;
  shared.max = max_box_pairs;
  const auto counted = [&](long pairs) {
    result.box_pairs = shared.seen;
    result.over_bound = shared.over || result.box_pairs > max_box_pairs;
    result.pairs = pairs;
    return result;
  };
  std::vector<const Box*> wanted = among;  // the changed boxes, then the unchanged ones near them
  wanted.insert(wanted.end(), unchanged.begin(), unchanged.end());
  // A pair with a changed triangle shares only that triangle's corners.
  std::vector<char> corners(mesh.vertices.size(), 0);
  for (size_t f = 0; f < changed.size(); ++f)
    if (changed[f])
      for (int v : mesh.triangles[f]) corners[static_cast<size_t>(v)] = 1;
  const std::vector<char> graph = graph_stars(mesh, corners);
  if (const std::optional<long> pairs = count_by_grid(mesh, wanted, among.size(), shared, graph)) {
    result.by_grid = true;
    return counted(*pairs);
  }
  NearPairs near = near_changed(boxes, changed, true);
  long both = 0, one = 0;
  tbb::parallel_invoke(
      [&] {
        both = count_pairs(PairCounter{mesh, shared, &graph}, [&](PairCounter& c) {
          CGAL::box_self_intersection_d<CGAL::Sequential_tag>(among.begin(), among.end(), std::ref(c), kBoxCutoff);
        });
      },
      [&] {
        one = count_pairs(PairCounter{mesh, shared, &graph}, [&](PairCounter& c) {
          CGAL::box_intersection_d<CGAL::Sequential_tag>(near.changed.begin(), near.changed.end(),
                                                         near.unchanged.begin(), near.unchanged.end(), std::ref(c),
                                                         kBoxCutoff);
        });
      });
  return counted(both + one);
}

long count_self_intersections(const SurfaceMesh& mesh) {
  const SelfIntersectionCount c = check_self_intersections(mesh, std::numeric_limits<long>::max());
  return c.degenerate ? -1 : c.pairs;
}

}  // namespace skinmesh
