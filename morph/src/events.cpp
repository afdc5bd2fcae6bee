#include "skinmesh/morph/events.hpp"

#include "skinmesh/core/quadratic.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace skinmesh {
namespace {

bool is_overlay_cell(const MixedCell& cell, const std::vector<BallPair>& pairs) {
  std::set<int> x, y;
  for (int k = 0; k <= cell.dim; ++k) {
    const BallPair& p = pairs[static_cast<size_t>(cell.balls[static_cast<size_t>(k)])];
    x.insert(p.source);
    y.insert(p.target);
  }
  return cell.dim == static_cast<int>(x.size() + y.size()) - 2;
}

}  // namespace

std::vector<CellSize> cell_sizes(const SkinComplex& middle, const std::vector<Ball>& source,
                                 const std::vector<Ball>& target, const std::vector<BallPair>& pairs) {
  const SkinComplex q1 = middle.with_balls(interpolated_balls(source, target, pairs, 0.25));
  const SkinComplex q3 = middle.with_balls(interpolated_balls(source, target, pairs, 0.75));
  std::vector<CellSize> sizes(middle.cells().size());
  for (size_t c = 0; c < sizes.size(); ++c) {
    // Newton's form through (1/4, r1), (1/2, r2), (3/4, r3) with step h = 1/4.
    const double r1 = q1.cells()[c].R2, r2 = middle.cells()[c].R2, r3 = q3.cells()[c].R2;
    const double h = 0.25;
    const double a = (r3 - 2 * r2 + r1) / (2 * h * h);
    const double slope_mid = (r3 - r1) / (2 * h);  // R2'(1/2)
    sizes[c].a = a;
    sizes[c].b = slope_mid - a;                     // R2'(t) = 2 a t + b
    sizes[c].c = r2 - a * 0.25 - sizes[c].b * 0.5;  // R2(1/2) = a/4 + b/2 + c
    sizes[c].overlay_cell = is_overlay_cell(middle.cells()[c], pairs);
    sizes[c].center_half = middle.cells()[c].center;
    sizes[c].center_slope = (q3.cells()[c].center - q1.cells()[c].center) / (2 * h);
  }
  return sizes;
}

std::vector<TopologyEvent> topology_events(const std::vector<CellSize>& sizes) {
  std::vector<TopologyEvent> events;
  for (int c = 0; c < static_cast<int>(sizes.size()); ++c) {
    const CellSize& q = sizes[static_cast<size_t>(c)];
    if (!q.overlay_cell) continue;
    double roots[2];
    const int count = quadratic_roots(q.a, q.b, q.c, 1e-14, roots);
    for (int k = 0; k < count; ++k)
      if (roots[k] > 0 && roots[k] < 1) events.push_back({roots[k], c});
  }
  std::sort(events.begin(), events.end(),
            [](const TopologyEvent& x, const TopologyEvent& y) { return x.t < y.t; });
  return events;
}

std::vector<TopologyEvent> critical_events(const std::vector<TopologyEvent>& events,
                                           const std::vector<CellSize>& sizes, const SkinComplex& middle,
                                           const std::vector<BallPair>& pairs, const MorphOracle& oracle) {
  std::vector<TopologyEvent> critical;
  for (const TopologyEvent& e : events) {
    const MixedCell& cell = middle.cell(e.cell);
    std::set<BallPair> own;
    for (int k = 0; k <= cell.dim; ++k) own.insert(pairs[static_cast<size_t>(cell.balls[static_cast<size_t>(k)])]);
    const MorphOracleResult o = oracle.evaluate(sizes[static_cast<size_t>(e.cell)].center(e.t), e.t);
    std::set<BallPair> support;
    for (const auto& [pair, weight] : o.support) support.insert(pair);
    if (support == own) critical.push_back(e);
  }
  return critical;
}

}  // namespace skinmesh
