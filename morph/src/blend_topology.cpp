#include "skinmesh/morph/blend_topology.hpp"

#include "skinmesh/core/quadratic.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace skinmesh {
namespace {

// A time near which a size curve is zero, with the half-width of the
// window its measured error allows around it.
struct NearRoot {
  double t = 0, half_width = 0;
};

// Where |R2(t)| <= tolerance can hold in (0,1): each root of the fitted
// curve, widened by how far the tolerance moves it (by the slope there, or
// at a double root by the curvature), and the curve's turning point when it
// comes within the tolerance of zero without crossing. A curve within the
// tolerance of zero over the whole interval gives one window over it.
std::vector<NearRoot> near_roots(const CellSize& q, double tolerance) {
  constexpr double floor = 1e-6;  // of t: the roots' own rounding
  const double largest = std::max({std::abs(q.at(0)), std::abs(q.at(0.5)), std::abs(q.at(1))});
  if (!std::isfinite(tolerance) || !std::isfinite(largest) || largest <= tolerance) return {{0.5, 0.5 + floor}};
  std::vector<NearRoot> found;
  double roots[2];
  const int count = quadratic_roots(q.a, q.b, q.c, 1e-14, roots);
  for (int k = 0; k < count; ++k) {
    const double slope = std::abs(2 * q.a * roots[k] + q.b);
    double width = slope > 0 ? tolerance / slope : 1.0;
    if (q.a != 0) width = std::min(width, std::sqrt(tolerance / std::abs(q.a)));
    found.push_back({roots[k], floor + width});
  }
  if (q.a != 0) {
    const double turn = -q.b / (2 * q.a);
    if (std::abs(q.at(turn)) <= tolerance) found.push_back({turn, floor + std::sqrt(2 * tolerance / std::abs(q.a))});
  }
  return found;
}

// Whether F_t may have a critical point at the cell's centre near `root`:
// the oracle's gradient there, certified against every pair, is not
// clearly away from zero. `start`: the cell's pairs.
bool may_be_critical(const CellSize& q, const NearRoot& root, const std::vector<BallPair>& start,
                     const MorphOracle& oracle, double gradient_below) {
  const double t = std::clamp(root.t, 1e-12, 1 - 1e-12);
  const MorphOracleResult r = oracle.evaluate(q.center(t), t, start);
  const double reach = gradient_below + 4 * q.center_slope.norm() * root.half_width;  // |grad F| = 2|x - Z l*|
  return !r.certified || r.gradient.norm() <= reach;
}

std::vector<BallPair> cell_pairs(const MixedCell& cell, const std::vector<BallPair>& pairs) {
  std::vector<BallPair> own;
  for (int k = 0; k <= cell.dim; ++k) own.push_back(pairs[static_cast<size_t>(cell.balls[static_cast<size_t>(k)])]);
  return own;
}

// Each cell's size R2 at t, from `middle` moved to B(t); the moved complex is let go at once.
std::vector<double> sizes_at(const SkinComplex& middle, const std::vector<Ball>& source,
                             const std::vector<Ball>& target, const std::vector<BallPair>& pairs, double t) {
  const SkinComplex moved = middle.with_balls(interpolated_balls(source, target, pairs, t));
  std::vector<double> sizes;
  sizes.reserve(moved.cells().size());
  for (const MixedCell& cell : moved.cells()) sizes.push_back(cell.R2);
  return sizes;
}

void merge(std::vector<std::pair<double, double>>& windows) {
  std::sort(windows.begin(), windows.end());
  std::vector<std::pair<double, double>> merged;
  for (const auto& w : windows) {
    if (merged.empty() || w.first > merged.back().second) merged.push_back(w);
    else merged.back().second = std::max(merged.back().second, w.second);
  }
  windows = std::move(merged);
}

}  // namespace

bool TopologyWindows::meets(double a, double b) const {
  if (a > b) std::swap(a, b);
  // The first window that ends at or after a; the windows are disjoint and ascending.
  const auto w = std::lower_bound(windows.begin(), windows.end(), a,
                                  [](const std::pair<double, double>& x, double t) { return x.second < t; });
  return w != windows.end() && w->first <= b;
}

TopologyWindows topology_change_windows(const SkinComplex& middle, const std::vector<CellSize>& sizes,
                                        const std::vector<Ball>& source, const std::vector<Ball>& target,
                                        const std::vector<BallPair>& pairs, const MorphOracle& oracle,
                                        const TopologyWindowOptions& options) {
  // Two sizes more than cell_sizes fitted its curves to measure each curve's error.
  const std::vector<double> at_04 = sizes_at(middle, source, target, pairs, 0.4);
  const std::vector<double> at_06 = sizes_at(middle, source, target, pairs, 0.6);
  TopologyWindows out;
  std::vector<std::pair<size_t, NearRoot>> roots;  // (cell, root)
  for (size_t c = 0; c < sizes.size(); ++c) {
    const CellSize& q = sizes[c];
    const double error = std::max(std::abs(q.at(0.4) - at_04[c]), std::abs(q.at(0.6) - at_06[c]));
    // An overlay cell's curve is a quadratic whatever its error (which then widens its windows).
    if (!q.overlay_cell && !(error <= options.not_quadratic_above)) continue;
    ++out.curves;
    for (const NearRoot& root : near_roots(q, 1e-9 + 10 * error))
      if (root.t + root.half_width > 0 && root.t - root.half_width < 1) roots.emplace_back(c, root);
  }
  out.roots = static_cast<long>(roots.size());
  std::vector<char> critical(roots.size(), 0);  // an oracle solve each: tens of thousands on a large pair
  tbb::parallel_for(tbb::blocked_range<size_t>(0, roots.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const auto& [c, root] = roots[k];
      const std::vector<BallPair> start = cell_pairs(middle.cells()[c], pairs);
      critical[k] = may_be_critical(sizes[c], root, start, oracle, options.gradient_below);
    }
  });
  for (size_t k = 0; k < roots.size(); ++k)
    if (critical[k]) out.windows.emplace_back(roots[k].second.t - roots[k].second.half_width,
                                              roots[k].second.t + roots[k].second.half_width);
  merge(out.windows);
  return out;
}

CountedTopology CarriedTopology::at(double t, const std::vector<Ball>& balls) {
  const auto inside = [](double x) { return x > 0 && x < 1; };
  if (last_.counted_at >= 0 && inside(t) && inside(last_.counted_at) && !windows_.meets(last_.counted_at, t)) {
    ++carried_;
    return last_;
  }
  last_ = {skin_topology(balls), t};
  ++counted_;
  return last_;
}

}  // namespace skinmesh
