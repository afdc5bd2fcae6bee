#include "skinmesh/morph/events.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/quadratic.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace skinmesh {
namespace {

// The source balls X and target balls Y of a cell's pairs.
using BallSets = std::pair<std::set<int>, std::set<int>>;

BallSets ball_sets(const MixedCell& cell, const std::vector<BallPair>& pairs) {
  BallSets xy;
  for (int k = 0; k <= cell.dim; ++k) {
    const BallPair& p = pairs[static_cast<size_t>(cell.balls[static_cast<size_t>(k)])];
    xy.first.insert(p.source);
    xy.second.insert(p.target);
  }
  return xy;
}

bool is_overlay_cell(const MixedCell& cell, const std::vector<BallPair>& pairs) {
  const BallSets xy = ball_sets(cell, pairs);
  return cell.dim == static_cast<int>(xy.first.size() + xy.second.size()) - 2;
}

// The change of the skin's Euler characteristic at a critical point of
// index `dim` (Morse theory, as in Edelsbrunner 1999): the body grows
// through it when the cell's R2 falls (R2 is the squared radius of the
// sphere orthogonal to the cell's balls, -w for a lone ball), which attaches
// a dim-handle to the body and changes its Euler characteristic by
// (-1)^dim; the skin bounds the body, so its own changes by twice that.
int euler_change(int dim, double slope) {
  if (slope == 0) return 0;  // the size touches zero and turns back
  const int handle = dim % 2 == 0 ? 2 : -2;
  return slope < 0 ? handle : -handle;
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
  // Compared by each side's balls, not by pairs: on an overlay cell that is
  // not a simplex the minimiser's pair weights are not unique (only their
  // marginals are, docs/math.md section 4), so the pairs the oracle names
  // need not be one simplex's. Compared by pairs, and with every simplex of
  // such a cell an event of its own, the events' Euler changes missed the
  // skin's in some steps (against the static mesher's meshes); now in none.
  std::map<BallSets, std::vector<double>> found;  // per overlay cell: its critical times
  std::vector<TopologyEvent> critical;
  for (const TopologyEvent& e : events) {
    const MixedCell& cell = middle.cell(e.cell);
    const BallSets own = ball_sets(cell, pairs);
    const CellSize& size = sizes[static_cast<size_t>(e.cell)];
    const MorphOracleResult o = oracle.evaluate(size.center(e.t), e.t);
    BallSets support;
    for (const auto& [pair, weight] : o.support) {
      support.first.insert(pair.source);
      support.second.insert(pair.target);
    }
    if (support != own) continue;
    std::vector<double>& times = found[own];
    if (std::any_of(times.begin(), times.end(), [&](double u) { return std::abs(u - e.t) <= 1e-9; })) continue;
    times.push_back(e.t);
    TopologyEvent c = e;
    c.dim = cell.dim;
    c.euler_change = euler_change(cell.dim, 2 * size.a * e.t + size.b);
    critical.push_back(c);
  }
  return critical;
}

std::vector<int> cancelling_partners(const std::vector<TopologyEvent>& events, const std::vector<CellSize>& sizes,
                                     double from, double to, const std::vector<char>& skip, double same_place) {
  if (skip.size() != events.size()) contract_error("cancelling_partners: one skip mark per event");
  std::vector<size_t> step;  // the events in (from, to]: a few of the morph's thousands
  for (size_t i = 0; i < events.size(); ++i)
    if (events[i].t > from && events[i].t <= to) step.push_back(i);
  const auto apex = [&](const TopologyEvent& e) { return sizes[static_cast<size_t>(e.cell)].center(e.t); };
  std::vector<int> partner(events.size(), -1);
  for (size_t i : step) {
    const TopologyEvent& gone = events[i];
    const bool vanishing = (gone.dim == 0 || gone.dim == 3) && gone.euler_change < 0;
    if (skip[i] || !vanishing) continue;
    const int opening_dim = gone.dim == 3 ? 2 : 1;
    double nearest = same_place;
    for (size_t j : step) {
      const TopologyEvent& made = events[j];
      if (j == i || partner[j] >= 0 || made.t > gone.t || made.dim != opening_dim ||
          made.euler_change != -gone.euler_change)
        continue;
      const double d = (apex(made) - apex(gone)).norm();
      if (d < nearest) {
        nearest = d;
        partner[i] = static_cast<int>(j);
      }
    }
    if (partner[i] >= 0) partner[static_cast<size_t>(partner[i])] = static_cast<int>(i);
  }
  return partner;
}

}  // namespace skinmesh
