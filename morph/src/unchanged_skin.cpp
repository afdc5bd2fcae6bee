#include "unchanged_skin.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/point_grid.hpp"

#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace skinmesh::detail {

std::vector<double> judged_reach(const SurfaceMesh& mesh, double tolerance, const std::vector<char>& marked) {
  if (marked.size() != mesh.vertices.size()) contract_error("judged_reach: marks do not match the mesh");
  const auto any_marked = [&](const std::array<int, 3>& t) {
    return marked[static_cast<size_t>(t[0])] || marked[static_cast<size_t>(t[1])] || marked[static_cast<size_t>(t[2])];
  };
  std::vector<double> per_triangle(mesh.triangles.size(), 0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, per_triangle.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f != r.end(); ++f) {
      const auto& t = mesh.triangles[f];
      if (!any_marked(t)) continue;
      const Eigen::Vector3d& p0 = mesh.vertices[static_cast<size_t>(t[0])];
      const Eigen::Vector3d u = mesh.vertices[static_cast<size_t>(t[1])] - p0;
      const Eigen::Vector3d w = mesh.vertices[static_cast<size_t>(t[2])] - p0;
      const Eigen::Vector3d uxw = u.cross(w);
      const double cross2 = uxw.squaredNorm();
      if (!(cross2 > 0)) {  // judged without a segment: no reach proves its verdict
        per_triangle[f] = std::numeric_limits<double>::infinity();
        continue;
      }
      const double radius = ((u.squaredNorm() * w.cross(uxw) + w.squaredNorm() * uxw.cross(u)) / (2.0 * cross2)).norm();
      // The circumcentre is `radius` from every corner.
      per_triangle[f] = std::isfinite(radius) ? radius + std::min(tolerance, radius)
                                              : std::numeric_limits<double>::infinity();
    }
  });
  std::vector<double> reach(mesh.vertices.size(), 0.0);
  for (size_t f = 0; f < per_triangle.size(); ++f)
    if (per_triangle[f] != 0)
      for (int v : mesh.triangles[f])
        if (marked[static_cast<size_t>(v)]) reach[static_cast<size_t>(v)] = std::max(reach[static_cast<size_t>(v)], per_triangle[f]);
  return reach;
}

namespace {

// One place of a ball that moved in the step: before it, or after.
struct Place {
  Eigen::Vector3d center;
  double weight;
};

// The smallest distance d from x0 beyond which a place of weight at most
// `weight` is proven inactive everywhere within rho of x0, by `margin`
// (the bound in skin_unchanged_near), whatever its distance e from y: the
// larger root of
//   s d^2 - 2 (rho + (1-s) a) d - ((1-s) a^2 + s w + f0 + 2 g rho + margin) = 0,
// a = g + rho / (1-s), from e <= d + g; at least rho.
double inactive_beyond(double s, double rho, double g, double weight, double f0, double margin) {
  const double a = g + rho / (1 - s);
  const double half_b = rho + (1 - s) * a;
  const double c = (1 - s) * a * a + s * weight + std::max(f0, 0.0) + 2 * g * rho + margin;
  return std::max(rho, (half_b + std::sqrt(half_b * half_b + s * c)) / s);
}

// The places in cubic cells over their bounding box, each cell's places in
// one run (`first`), with a summed table of the counts: how many places
// lie in the cells a box meets is a constant-time question.
class PlaceGrid {
 public:
  PlaceGrid(const std::vector<Place>& places, double cell) : cell_(cell) {
    low_ = places.front().center;
    Eigen::Vector3d high = low_;
    for (const Place& p : places) {
      low_ = low_.cwiseMin(p.center);
      high = high.cwiseMax(p.center);
    }
    for (int k = 0; k < 3; ++k) size_[k] = static_cast<int>(std::floor((high[k] - low_[k]) / cell_)) + 1;
    const size_t cells = static_cast<size_t>(size_[0]) * static_cast<size_t>(size_[1]) * static_cast<size_t>(size_[2]);
    first_.assign(cells + 1, 0);
    std::vector<size_t> at(places.size());
    for (size_t k = 0; k < places.size(); ++k) {
      at[k] = index(clamped(places[k].center));
      ++first_[at[k] + 1];
    }
    for (size_t c = 0; c < cells; ++c) first_[c + 1] += first_[c];
    items_.resize(places.size());
    std::vector<int> fill(first_.begin(), first_.end() - 1);
    for (size_t k = 0; k < places.size(); ++k) items_[static_cast<size_t>(fill[at[k]]++)] = static_cast<int>(k);
    // sums_(i, j, k): the places in cells [0, i) x [0, j) x [0, k).
    sums_.assign(static_cast<size_t>(size_[0] + 1) * static_cast<size_t>(size_[1] + 1) * static_cast<size_t>(size_[2] + 1), 0);
    for (int i = 1; i <= size_[0]; ++i)
      for (int j = 1; j <= size_[1]; ++j)
        for (int k = 1; k <= size_[2]; ++k) {
          const size_t c = index({i - 1, j - 1, k - 1});
          sum(i, j, k) = (first_[c + 1] - first_[c]) + sum(i - 1, j, k) + sum(i, j - 1, k) + sum(i, j, k - 1) -
                         sum(i - 1, j - 1, k) - sum(i - 1, j, k - 1) - sum(i, j - 1, k - 1) + sum(i - 1, j - 1, k - 1);
        }
  }
  // Whether any place lies in a cell that the cube of half-width r about x meets.
  bool any_within(const Eigen::Vector3d& x, double r) const {
    Eigen::Vector3i lo, hi;
    return cells_met(x, r, lo, hi) && count(lo, hi) > 0;
  }
  // Calls visit(place index) for the places in the cells the cube meets,
  // until it returns true; returns whether it did. A row of cells holds
  // its places in one run.
  template <class Visit>
  bool any_of(const Eigen::Vector3d& x, double r, Visit visit) const {
    Eigen::Vector3i lo, hi;
    if (!cells_met(x, r, lo, hi)) return false;
    for (int i = lo[0]; i <= hi[0]; ++i)
      for (int j = lo[1]; j <= hi[1]; ++j) {
        for (int m = first_[index({i, j, lo[2]})], end = first_[index({i, j, hi[2]}) + 1]; m < end; ++m)
          if (visit(items_[static_cast<size_t>(m)])) return true;
      }
    return false;
  }

 private:
  Eigen::Vector3i clamped(const Eigen::Vector3d& p) const {
    Eigen::Vector3i c;
    for (int k = 0; k < 3; ++k)
      c[k] = static_cast<int>(std::clamp(std::floor((p[k] - low_[k]) / cell_), 0.0, static_cast<double>(size_[k] - 1)));
    return c;
  }
  // The cells the cube of half-width r about x meets, clamped to the grid; false when none.
  bool cells_met(const Eigen::Vector3d& x, double r, Eigen::Vector3i& lo, Eigen::Vector3i& hi) const {
    for (int k = 0; k < 3; ++k) {
      const double a = std::floor((x[k] - r - low_[k]) / cell_), b = std::floor((x[k] + r - low_[k]) / cell_);
      if (b < 0 || a > size_[k] - 1) return false;
      lo[k] = static_cast<int>(std::max(a, 0.0));
      hi[k] = static_cast<int>(std::min(b, static_cast<double>(size_[k] - 1)));
    }
    return true;
  }
  // The places in cells lo..hi (inclusive) from the summed table.
  int count(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) const {
    const int a0 = lo[0], a1 = lo[1], a2 = lo[2], b0 = hi[0] + 1, b1 = hi[1] + 1, b2 = hi[2] + 1;
    return sum(b0, b1, b2) - sum(a0, b1, b2) - sum(b0, a1, b2) - sum(b0, b1, a2) + sum(a0, a1, b2) + sum(a0, b1, a2) +
           sum(b0, a1, a2) - sum(a0, a1, a2);
  }
  size_t index(const Eigen::Vector3i& c) const {
    return (static_cast<size_t>(c[0]) * static_cast<size_t>(size_[1]) + static_cast<size_t>(c[1])) *
               static_cast<size_t>(size_[2]) +
           static_cast<size_t>(c[2]);
  }
  int& sum(int i, int j, int k) {
    return sums_[(static_cast<size_t>(i) * static_cast<size_t>(size_[1] + 1) + static_cast<size_t>(j)) *
                     static_cast<size_t>(size_[2] + 1) +
                 static_cast<size_t>(k)];
  }
  int sum(int i, int j, int k) const { return const_cast<PlaceGrid*>(this)->sum(i, j, k); }

  double cell_;
  Eigen::Vector3d low_;
  std::array<int, 3> size_{};
  std::vector<int> first_, items_, sums_;
};

}  // namespace

// MATH.md section 2: F(x) = min over l in the simplex of
// (1-s)|x - Zl|^2 + s sum_i l_i pi_i(x). With y = Z l* the optimum over the
// balls that stayed (U), a ball j is inactive at x (l*_j = 0 in every
// optimum over U and j) iff its KKT slack is positive:
//   g_j(x) = |x - z_j|^2 - (1-s)|z_j - y|^2 - s w_j - F_U(x) > 0.
// Then F and the support of l* (the mixed cell) are those of U. Within rho
// of x0, y moves at most rho / (1-s) (y = z_X + P_X (x - z_X) / (1-s) in a
// mixed cell, continuous across them) and F_U(x) <= F_U(x0) +
// |grad F_U(x0)| rho + rho^2 (F_U is a minimum of functions with Hessian
// 2I), so with d = |x0 - z_j| >= rho and e = |z_j - y(x0)|
//   g_j(x) >= (d - rho)^2 - (1-s)(e + rho/(1-s))^2 - s w_j - F(x0) - |grad F(x0)| rho - rho^2.
// Both places of j must pass, so that U's optimum is optimal before the
// step and after it. At x0 on the skin, |x0 - y|^2 = (F(x0) - s sum l_i
// pi_i(x0)) / (1-s) <= (F(x0) + s max w) / (1-s), the largest weight of
// any ball: places farther than the bound with that g are passed over
// before F is evaluated at all.
std::vector<char> skin_unchanged_near(const SkinComplex& from, const std::vector<Ball>& to, const SurfaceMesh& mesh,
                                      const std::vector<double>& radius, const std::vector<char>& candidates) {
  const std::vector<Ball>& before = from.balls();
  if (to.size() != before.size() || radius.size() != mesh.vertices.size() ||
      candidates.size() != mesh.vertices.size())
    contract_error("skin_unchanged_near: balls, radii or marks do not match");
  const double s = from.shrink();
  std::vector<Place> places;
  double heaviest = 0;  // of the balls that moved
  double heaviest_of_all = 0;  // of every ball: y at x0 is a combination of any of them
  for (size_t b = 0; b < before.size(); ++b) {
    heaviest_of_all = std::max({heaviest_of_all, before[b].weight, to[b].weight});
    if (before[b].center == to[b].center && before[b].weight == to[b].weight) continue;
    places.push_back({before[b].center, before[b].weight});
    places.push_back({to[b].center, to[b].weight});
    heaviest = std::max({heaviest, before[b].weight, to[b].weight});
  }
  std::vector<char> unchanged(mesh.vertices.size(), 0);
  if (places.empty()) {
    for (size_t v = 0; v < unchanged.size(); ++v) unchanged[v] = candidates[v] && std::isfinite(radius[v]);
    return unchanged;
  }
  constexpr double kOffSkin = 1e-9;  // slack for a vertex a little off the skin (it is within 1e-12 A)
  constexpr double kCell = 2.0;      // Angstrom, where the places span at most kMostCellsAcross cells
  constexpr double kMostCellsAcross = 96;  // memory stays bounded however far apart the atoms are
  const double g_most = std::sqrt(std::max((s * heaviest_of_all + kOffSkin) / (1 - s), 0.0)) + kOffSkin;
  Eigen::AlignedBox3d span;
  for (const Place& p : places) span.extend(p.center);
  const PlaceGrid grid(places, std::max(kCell, span.sizes().maxCoeff() / kMostCellsAcross));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, unchanged.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      if (!candidates[v] || !std::isfinite(radius[v])) continue;
      const Eigen::Vector3d& x0 = mesh.vertices[v];
      const double rho = radius[v];
      // No place within the bound's reach for the most g can be: no need to evaluate F.
      if (!grid.any_within(x0, inactive_beyond(s, rho, g_most, heaviest, kOffSkin, kOffSkin))) {
        unchanged[v] = 1;
        continue;
      }
      const SkinEval e = from.evaluate(x0, mesh.cells[v]);
      const Eigen::Vector3d y = x0 - 0.5 * e.gradient;
      const double grad = e.gradient.norm();
      const double lost = std::max(e.value, 0.0) + grad * rho + rho * rho;
      const double reach = inactive_beyond(s, rho, 0.5 * grad, heaviest, e.value, kOffSkin);
      if (!std::isfinite(reach)) continue;  // unproven
      unchanged[v] = !grid.any_of(x0, reach, [&](int k) {
        const Place& p = places[static_cast<size_t>(k)];
        const double d = (p.center - x0).norm();
        if (!(d > rho)) return true;
        const double spread = (p.center - y).norm() + rho / (1 - s);
        return !((d - rho) * (d - rho) - (1 - s) * spread * spread - s * p.weight - lost > kOffSkin);
      });
    }
  });
  return unchanged;
}

std::vector<Ball> balls_moving_with(const RigidMotion& motion, const std::vector<Ball>& before,
                                    const std::vector<Ball>& after) {
  if (before.size() != after.size()) contract_error("balls_moving_with: the ball counts differ");
  std::vector<Ball> seen(after.size());
  for (size_t b = 0; b < after.size(); ++b)
    seen[b] = motion.carries(before[b], after[b])
                  ? before[b]
                  : Ball{motion.rotation.transpose() * (after[b].center - motion.translation), after[b].weight};
  return seen;
}

}  // namespace skinmesh::detail
