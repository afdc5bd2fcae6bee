// The interpolated set of a morph and its live pairs (see interpolation.hpp).
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/error.hpp"

#include "regular_triangulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <deque>
#include <set>
#include <stdexcept>
#include <unordered_set>

namespace skinmesh {
namespace {

using K = detail::RtKernel;
using Regular = detail::RegularTriangulation<long>;
using Weighted = K::Weighted_point_3;

Weighted weighted(const Ball& b) { return Weighted(K::Point_3(b.center[0], b.center[1], b.center[2]), b.weight); }

// The regular triangulation of one ball set: who is hidden, who neighbours
// whom (power cells sharing a facet), and whose cell holds a point.
struct PowerDiagram {
  Regular rt;
  std::vector<Regular::Vertex_handle> vertex;  // null for hidden balls
  explicit PowerDiagram(const std::vector<Ball>& balls) : vertex(balls.size()) {
    for (size_t i = 0; i < balls.size(); ++i) {
      const auto v = rt.insert(weighted(balls[i]));
      if (v != Regular::Vertex_handle()) v->info() = static_cast<long>(i);
    }
    for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v)
      vertex[static_cast<size_t>(v->info())] = v;
  }
  std::vector<int> neighbours(int i) const {
    std::vector<int> out;
    const auto v = vertex[static_cast<size_t>(i)];
    if (v == Regular::Vertex_handle() || rt.dimension() < 1) return out;
    std::vector<Regular::Vertex_handle> adjacent;
    rt.finite_adjacent_vertices(v, std::back_inserter(adjacent));
    for (const auto& a : adjacent) out.push_back(static_cast<int>(a->info()));
    return out;
  }
  int owner(const Eigen::Vector3d& x) const {
    return static_cast<int>(rt.nearest_power_vertex(K::Point_3(x[0], x[1], x[2]))->info());
  }
};

// Per ball of `of`: the index of a ball of `in` with the same centre and
// weight, bit for bit, or -1.
std::vector<int> twins(const std::vector<Ball>& of, const std::vector<Ball>& in) {
  using Key = std::array<double, 4>;
  std::map<Key, int> index;
  for (size_t k = 0; k < in.size(); ++k)
    index.emplace(Key{in[k].center[0], in[k].center[1], in[k].center[2], in[k].weight}, static_cast<int>(k));
  std::vector<int> out(of.size(), -1);
  for (size_t k = 0; k < of.size(); ++k) {
    const auto it = index.find(Key{of[k].center[0], of[k].center[1], of[k].center[2], of[k].weight});
    if (it != index.end()) out[k] = it->second;
  }
  return out;
}

}  // namespace

Ball interpolate_ball(const Ball& a, const Ball& b, double t) {
  return {(1 - t) * a.center + t * b.center,
          (1 - t) * a.weight + t * b.weight - t * (1 - t) * (a.center - b.center).squaredNorm()};
}

std::vector<BallPair> all_pairs(size_t m, size_t n) {
  std::vector<BallPair> out;
  out.reserve(m * n);
  for (size_t i = 0; i < m; ++i)
    for (size_t j = 0; j < n; ++j) out.push_back({static_cast<int>(i), static_cast<int>(j)});
  return out;
}

std::vector<BallPair> live_pairs(const std::vector<Ball>& source, const std::vector<Ball>& target) {
  if (source.empty() || target.empty()) contract_error("live_pairs: an empty ball set");
  const PowerDiagram a(source), b(target);
  const long n = static_cast<long>(target.size());
  // The overlay's cells are connected through facets, and a facet between
  // cells (i, j) and (i', j') lies on a facet of one diagram (i' a neighbour
  // of i, or j' of j) or of both at once (coincident facets, when atoms do
  // not move). Every live pair is thus reached from another live pair by
  // changing i, j or both to a neighbour. A candidate hidden among the pairs
  // inserted so far is hidden among all of them, so it is dead for good;
  // one inserted alive may be hidden later, and the triangulation's
  // vertices at the end are the live set.
  // Atoms that do not move: when a_i equals b_i' and b_j equals a_j', then
  // for every t, b_ij(t) = (1-t) b_ii'(t) + t b_j'j(t) (b_ii'(t) = a_i and
  // b_j'j(t) = b_j), a convex combination of two balls of B(t): it lies in
  // conv B(t) and changes no skin (docs/math.md section 4), and its overlay
  // cell, a piece of the facet the two identical diagrams share, has no
  // volume. Kept, such balls made B(t) so degenerate that the mesher's
  // refinement stalled (a molecule morphed onto itself). They are left out
  // and not walked through: the cells with volume are connected by facets
  // among themselves.
  // Compared by the balls, not by index: a side may hold the same ball
  // twice (a duplicated atom), and the pair of a ball with its own copy is
  // that ball, never redundant.
  const std::vector<int> source_twin = twins(source, target), target_twin = twins(target, source);
  auto redundant = [&](const BallPair& p) {
    const Ball& a = source[static_cast<size_t>(p.source)];
    const Ball& b = target[static_cast<size_t>(p.target)];
    const bool same = a.center == b.center && a.weight == b.weight;
    return source_twin[static_cast<size_t>(p.source)] >= 0 && target_twin[static_cast<size_t>(p.target)] >= 0 && !same;
  };
  Regular overlay;
  std::unordered_set<long> seen;
  std::deque<BallPair> queue;
  auto push = [&](int i, int j) {
    if (seen.insert(static_cast<long>(i) * n + j).second) queue.push_back({i, j});
  };
  // Seeds: the pairs whose overlay cells hold the balls' centres.
  for (const Ball& ball : source) push(a.owner(ball.center), b.owner(ball.center));
  for (const Ball& ball : target) push(a.owner(ball.center), b.owner(ball.center));
  while (!queue.empty()) {
    const BallPair p = queue.front();
    queue.pop_front();
    if (redundant(p)) continue;
    const Ball mid = interpolate_ball(source[static_cast<size_t>(p.source)], target[static_cast<size_t>(p.target)], 0.5);
    const auto v = overlay.insert(weighted(mid));
    if (v == Regular::Vertex_handle()) continue;  // hidden
    v->info() = static_cast<long>(p.source) * n + p.target;
    const std::vector<int> ni = a.neighbours(p.source), nj = b.neighbours(p.target);
    for (int i : ni) push(i, p.target);
    for (int j : nj) push(p.source, j);
    for (int i : ni)
      for (int j : nj) push(i, j);
  }
  std::vector<BallPair> out;
  for (auto v = overlay.finite_vertices_begin(); v != overlay.finite_vertices_end(); ++v)
    out.push_back({static_cast<int>(v->info() / n), static_cast<int>(v->info() % n)});
  std::sort(out.begin(), out.end());
  return out;
}

long snap_unmoved_balls(const std::vector<Ball>& source, std::vector<Ball>& target, double within) {
  if (!(within > 0) || !std::isfinite(within)) contract_error("snap_unmoved_balls: `within` must be positive");
  // Source balls by grid cell `within` wide: a target ball's partner lies in
  // one of the 27 cells around its own.
  using Cell = std::array<long long, 3>;
  const auto cell_of = [&](const Eigen::Vector3d& x) {
    return Cell{static_cast<long long>(std::floor(x[0] / within)), static_cast<long long>(std::floor(x[1] / within)),
                static_cast<long long>(std::floor(x[2] / within))};
  };
  std::map<Cell, std::vector<int>> grid;
  for (size_t k = 0; k < source.size(); ++k) grid[cell_of(source[k].center)].push_back(static_cast<int>(k));
  long snapped = 0;
  for (Ball& b : target) {
    const Cell c = cell_of(b.center);
    int nearest = -1;
    double best = within;
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(Cell{c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == grid.end()) continue;
          for (int k : it->second) {
            const Ball& a = source[static_cast<size_t>(k)];
            const double d = (a.center - b.center).norm();
            if (a.weight == b.weight && d <= best) {
              best = d;
              nearest = k;
            }
          }
        }
    if (nearest < 0) continue;
    b.center = source[static_cast<size_t>(nearest)].center;
    ++snapped;
  }
  return snapped;
}

void centre_balls(std::vector<Ball>& balls) {
  if (balls.empty()) return;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Ball& b : balls) c += b.center;
  c /= static_cast<double>(balls.size());
  for (Ball& b : balls) b.center -= c;
}

std::vector<Ball> interpolated_balls(const std::vector<Ball>& source, const std::vector<Ball>& target,
                                     const std::vector<BallPair>& pairs, double t) {
  std::vector<Ball> out;
  out.reserve(pairs.size());
  for (const BallPair& p : pairs)
    out.push_back(interpolate_ball(source.at(static_cast<size_t>(p.source)), target.at(static_cast<size_t>(p.target)), t));
  return out;
}

}  // namespace skinmesh
