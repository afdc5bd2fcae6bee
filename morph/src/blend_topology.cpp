#include "skinmesh/morph/blend_topology.hpp"

#include "skinmesh/core/quadratic.hpp"

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

}  // namespace

TopologyWindows::TopologyWindows(const std::vector<std::pair<double, double>>& windows) {
  for (const auto& [from, to] : windows) candidates_.push_back({from, to, (from + to) / 2, 0, -1, 1});
  std::sort(candidates_.begin(), candidates_.end(),
            [](const Candidate& x, const Candidate& y) { return x.from < y.from; });
  for (const Candidate& c : candidates_) reach_.push_back(reach_.empty() ? c.to : std::max(reach_.back(), c.to));
}

TopologyWindows::TopologyWindows(const SkinComplex& middle, const std::vector<CellSize>& sizes,
                                 const std::vector<Ball>& source, const std::vector<Ball>& target,
                                 const std::vector<BallPair>& pairs, const MorphOracle& oracle,
                                 const TopologyWindowOptions& options)
    : oracle_(oracle) {
  // Two sizes more than cell_sizes fitted its curves to measure each curve's error.
  const std::vector<double> at_04 = sizes_at(middle, source, target, pairs, 0.4);
  const std::vector<double> at_06 = sizes_at(middle, source, target, pairs, 0.6);
  for (size_t c = 0; c < sizes.size(); ++c) {
    const CellSize& q = sizes[c];
    const double error = std::max(std::abs(q.at(0.4) - at_04[c]), std::abs(q.at(0.6) - at_06[c]));
    // An overlay cell's curve is a quadratic whatever its error (which then widens its windows).
    if (!q.overlay_cell && !(error <= options.not_quadratic_above)) continue;
    ++curves_;
    const int cell = static_cast<int>(cells_.size());
    bool any = false;
    for (const NearRoot& root : near_roots(q, 1e-9 + 10 * error)) {
      if (root.t + root.half_width <= 0 || root.t - root.half_width >= 1) continue;
      // |grad F| = 2|x - Z l*|: twice what the centre moves within the window, and more.
      const double below = options.gradient_below + 4 * q.center_slope.norm() * root.half_width;
      candidates_.push_back({root.t - root.half_width, root.t + root.half_width, root.t, below, cell, -1});
      any = true;
    }
    if (any) cells_.push_back({q.center_half, q.center_slope, cell_pairs(middle.cells()[c], pairs)});
  }
  std::sort(candidates_.begin(), candidates_.end(),
            [](const Candidate& x, const Candidate& y) { return x.from < y.from; });
  for (const Candidate& c : candidates_) reach_.push_back(reach_.empty() ? c.to : std::max(reach_.back(), c.to));
}

// A possible change where the morph oracle's gradient at the cell's centre
// (certified against every pair) is not clearly away from zero.
bool TopologyWindows::decide(Candidate& c) {
  if (c.possible < 0) {
    const Cell& cell = cells_[static_cast<size_t>(c.cell)];
    const double t = std::clamp(c.t, 1e-12, 1 - 1e-12);
    const MorphOracleResult r = oracle_->evaluate(cell.center_half + (t - 0.5) * cell.center_slope, t, cell.start);
    c.possible = !r.certified || r.gradient.norm() <= c.gradient_below;
  }
  return c.possible == 1;
}

bool TopologyWindows::meets(double a, double b) {
  if (a > b) std::swap(a, b);
  // Candidates whose window starts by b, back from the last, while one of them or an earlier one reaches a.
  const auto end = std::upper_bound(candidates_.begin(), candidates_.end(), b,
                                    [](double t, const Candidate& c) { return t < c.from; });
  for (auto k = end - candidates_.begin(); k-- > 0 && reach_[static_cast<size_t>(k)] >= a;) {
    Candidate& c = candidates_[static_cast<size_t>(k)];
    if (c.to >= a && decide(c)) return true;
  }
  return false;
}

long TopologyWindows::decided() const {
  return std::count_if(candidates_.begin(), candidates_.end(), [](const Candidate& c) { return c.possible >= 0; });
}

long TopologyWindows::possible() const {
  return std::count_if(candidates_.begin(), candidates_.end(), [](const Candidate& c) { return c.possible == 1; });
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
