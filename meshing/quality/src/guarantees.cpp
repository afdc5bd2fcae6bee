#include "skinmesh/quality/guarantees.hpp"

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/cell_grid.hpp"
#include "skinmesh/core/skin_oracle.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <optional>

namespace skinmesh {
namespace {

// Points by their exact coordinates: an open-addressing table of their
// numbers, a quarter full, probed linearly, so that each vertex of a frame
// finds the frame before's answer at its place in about one memory access.
class PointIndex {
 public:
  explicit PointIndex(const std::vector<Eigen::Vector3d>& points) : points_(points) {
    size_t size = 16;
    while (size < 4 * points.size()) size *= 2;
    slots_.assign(size, -1);
    for (size_t k = 0; k < points.size(); ++k) {
      size_t s = slot(points[k]);
      while (slots_[s] >= 0 && points_[static_cast<size_t>(slots_[s])] != points[k]) s = (s + 1) & (slots_.size() - 1);
      if (slots_[s] < 0) slots_[s] = static_cast<long>(k);  // a repeated point keeps its first number
    }
  }
  // The number of the point equal to x, or -1.
  long find(const Eigen::Vector3d& x) const {
    for (size_t s = slot(x);; s = (s + 1) & (slots_.size() - 1)) {
      const long k = slots_[s];
      if (k < 0 || points_[static_cast<size_t>(k)] == x) return k;
    }
  }

 private:
  size_t slot(const Eigen::Vector3d& x) const {
    uint64_t h = 0;
    for (int k = 0; k < 3; ++k) {
      uint64_t bits;
      std::memcpy(&bits, &x[k], sizeof bits);
      h = (h ^ bits) * 0x9E3779B97F4A7C15ULL;  // Fibonacci hashing of the coordinates' bits
      h ^= h >> 29;
    }
    return static_cast<size_t>(h) & (slots_.size() - 1);
  }
  const std::vector<Eigen::Vector3d>& points_;
  std::vector<long> slots_;
};

// Per vertex, the earlier answer that stands for `skin`'s balls
// (OracleAnswers), or -1: one at the same point whose reach holds no ball
// that changed, its old centre or its new one.
std::vector<long> standing_answers(const std::vector<Eigen::Vector3d>& vertices, const SkinReference& skin,
                                   const OracleAnswers& earlier) {
  std::vector<long> out(vertices.size(), -1);
  const std::vector<Ball>& now = skin.balls;
  if (earlier.balls.size() != now.size() || earlier.shrink != skin.shrink || now.empty() ||
      earlier.points.size() != earlier.distances.size())
    return out;
  const auto heaviest = [](const std::vector<Ball>& balls) {
    const auto lighter = [](const Ball& a, const Ball& b) { return a.weight < b.weight; };
    return std::max_element(balls.begin(), balls.end(), lighter)->weight;
  };
  if (heaviest(now) > heaviest(earlier.balls)) return out;
  // The changed balls' centres, old and new, in a grid with counts: most
  // vertices lie where no cell within their answer's reach holds one, and
  // are decided by one lookup of the summed counts.
  std::vector<Eigen::Vector3d> changed;
  for (size_t i = 0; i < now.size(); ++i)
    if (now[i].center != earlier.balls[i].center || now[i].weight != earlier.balls[i].weight) {
      changed.push_back(now[i].center);
      changed.push_back(earlier.balls[i].center);
    }
  CellGridOptions grid_options;
  grid_options.cell = 4.0;  // Angstrom: about an answer's reach
  grid_options.most_cells = 4.0 * static_cast<double>(vertices.size()) + 4096;
  grid_options.counts = true;
  const CellGrid near_changed(changed, {}, Eigen::AlignedBox3d(), grid_options);
  const PointIndex index(earlier.points);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const Eigen::Vector3d& x = vertices[v];
      const long answer = index.find(x);
      if (answer < 0) continue;
      const SkinDistance& d = earlier.distances[static_cast<size_t>(answer)];
      if (!d.certified || !std::isfinite(d.reach)) continue;
      const std::optional<CellGrid::Cells> cells = near_changed.cells_met(x, d.reach);
      const bool near = cells && near_changed.count_in(*cells) > 0 &&
                        near_changed.any_in(*cells, [&](int, const Eigen::Vector3d& c) { return (c - x).norm() <= d.reach; });
      if (!near) out[v] = answer;
    }
  });
  return out;
}

// Each vertex's distance by the oracle (or kept from `earlier`, with the
// static oracle); a vertex it cannot certify is measured on the complex of
// the skin's balls built from scratch (the skin function, |F| / |grad F|),
// which no mesher's state enters either.
SurfaceError distances(const std::vector<Eigen::Vector3d>& vertices, const SkinReference& skin,
                       const OracleAnswers* earlier, std::vector<SkinDistance>& d, long& kept) {
  std::optional<SkinOracle> own_oracle;
  if (!skin.oracle) own_oracle.emplace(skin.balls, skin.shrink);
  const PointOracle oracle = skin.oracle ? skin.oracle : point_oracle(*own_oracle);
  const bool with_starts = skin.starts.size() == vertices.size();
  const std::vector<long> standing =
      earlier && !skin.oracle ? standing_answers(vertices, skin, *earlier) : std::vector<long>(vertices.size(), -1);
  d.assign(vertices.size(), SkinDistance{});
  tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      d[v] = standing[v] >= 0 ? earlier->distances[static_cast<size_t>(standing[v])]
                              : oracle(vertices[v], with_starts ? skin.starts[v] : kNoStart);
  });
  kept = std::count_if(standing.begin(), standing.end(), [](long e) { return e >= 0; });
  std::vector<double> off(d.size());
  SurfaceError e;
  for (size_t v = 0; v < d.size(); ++v) {
    off[v] = d[v].distance;
    e.uncertified += !d[v].certified;
  }
  if (e.uncertified > 0) {
    const SkinComplex own = build_skin_complex(skin.balls, {skin.shrink});
    for (size_t v = 0; v < off.size(); ++v)
      if (!d[v].certified) {
        const SkinEval f = own.evaluate(vertices[v]);
        const double g = f.gradient.norm();
        off[v] = g > 0 ? std::abs(f.value) / g : INFINITY;
      }
  }
  if (off.empty()) return e;
  e.max = *std::max_element(off.begin(), off.end());
  e.mean = std::accumulate(off.begin(), off.end(), 0.0) / static_cast<double>(off.size());
  return e;
}

}  // namespace

GuaranteeReport check_guarantees(const SurfaceMesh& mesh, const SkinReference& skin, const GuaranteeOptions& options) {
  GuaranteeReport r;
  GradeOptions grade;
  grade.self_intersections = options.self_intersections;
  grade.changed = options.changed_triangles;
  // The grade (its exact self-intersection test is serial) beside the
  // oracle's distances (parallel over the vertices) and the skin's alpha
  // complex: together they keep both cores busy.
  tbb::parallel_invoke([&] { r.quality = grade_mesh(mesh, grade); },
                       [&] {
                         r.surface_error = distances(mesh.vertices, skin, options.earlier, r.distances, r.distances_kept);
                       },
                       [&] {
                         if (options.topology) r.skin = skin.topology ? *skin.topology : skin_topology(skin.balls);
                       });
  if (!options.report_distances) std::vector<SkinDistance>().swap(r.distances);
  const MeshQuality& q = r.quality;
  // The bound is met to rounding: angles are computed from the written
  // doubles, and a triangle refined to exactly 30 degrees reads 30 - 1e-14.
  r.angle = q.triangles > 0 && q.min_angle >= options.min_angle - 1e-9;
  r.on_skin = r.surface_error.max <= options.on_skin_tolerance;
  r.closed_oriented_manifold = q.closed && q.manifold && q.oriented && q.volume > 0;
  if (options.self_intersections == SelfIntersectionCheck::exact)
    r.no_self_intersections = q.self_intersections_checked && q.self_intersecting_pairs == 0;
  if (r.skin)
    r.topology = q.components == r.skin->components && q.cavities == r.skin->voids && q.euler == r.skin->euler;
  return r;
}

GuaranteeReport check_guarantees(const SurfaceMesh& mesh, const std::vector<Ball>& balls, double shrink,
                                 const GuaranteeOptions& options) {
  return check_guarantees(mesh, SkinReference{balls, shrink, {}, {}, {}}, options);
}

}  // namespace skinmesh
