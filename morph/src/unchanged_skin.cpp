#include "unchanged_skin.hpp"

#include "skinmesh/core/cell_grid.hpp"
#include "skinmesh/core/error.hpp"

#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

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
  std::vector<Eigen::Vector3d> centers(places.size());
  for (size_t k = 0; k < places.size(); ++k) centers[k] = places[k].center;
  CellGridOptions grid_options;
  grid_options.cell = std::max(kCell, span.sizes().maxCoeff() / kMostCellsAcross);
  grid_options.counts = true;  // "any place near?" in constant time
  const CellGrid grid(std::move(centers), {}, span, grid_options);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, unchanged.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      if (!candidates[v] || !std::isfinite(radius[v])) continue;
      const Eigen::Vector3d& x0 = mesh.vertices[v];
      const double rho = radius[v];
      // No place within the bound's reach for the most g can be: no need to evaluate F.
      const std::optional<CellGrid::Cells> worst = grid.cells_met(x0, inactive_beyond(s, rho, g_most, heaviest, kOffSkin, kOffSkin));
      if (!worst || grid.count_in(*worst) == 0) {
        unchanged[v] = 1;
        continue;
      }
      const SkinEval e = from.evaluate(x0, mesh.cells[v]);
      const Eigen::Vector3d y = x0 - 0.5 * e.gradient;
      const double grad = e.gradient.norm();
      const double lost = std::max(e.value, 0.0) + grad * rho + rho * rho;
      const double reach = inactive_beyond(s, rho, 0.5 * grad, heaviest, e.value, kOffSkin);
      if (!std::isfinite(reach)) continue;  // unproven
      const double reach2 = reach * reach;
      unchanged[v] = !grid.any_near(x0, reach, [&](int k, const Eigen::Vector3d&) {
        const Place& p = places[static_cast<size_t>(k)];
        // The grid's cells cover a cube: past `reach` the bound above proves
        // a place inactive already, whatever its distance from y.
        const double d2 = (p.center - x0).squaredNorm();
        if (d2 >= reach2) return false;
        const double d = std::sqrt(d2);
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
