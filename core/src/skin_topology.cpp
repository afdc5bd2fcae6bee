// The skin's topology from the dual complex of the union of balls
// (dual_complex.hpp) on a regular triangulation of its own: independent of
// the mixed complex, and three-dimensional whatever the balls. CGAL stays
// in core/src.
#include "skinmesh/core/skin_topology.hpp"

#include "dual_complex.hpp"
#include "regular_triangulation.hpp"

#include "skinmesh/core/error.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace skinmesh {
namespace {

using Regular = detail::RegularTriangulation<int>;
using K = detail::RtKernel;

}  // namespace

std::string SkinTopology::text() const {
  return std::to_string(components) + " component(s) (" + std::to_string(voids) + " voids), Euler characteristic " +
         std::to_string(euler);
}

SkinTopology skin_topology(const std::vector<Ball>& balls) {
  std::vector<std::pair<Regular::Weighted_point, int>> points;
  for (const Ball& b : balls) {
    if (!b.center.allFinite() || !std::isfinite(b.weight)) contract_error("skin_topology: a ball is not finite");
    if (b.weight > 0)
      points.emplace_back(Regular::Weighted_point(K::Point_3(b.center.x(), b.center.y(), b.center.z()), b.weight),
                          static_cast<int>(points.size()));
  }
  SkinTopology out;
  if (points.empty()) return out;
  // Four balls of no body far around the rest make the triangulation
  // three-dimensional whatever the input (the Gabriel tests need it): their
  // power is huge near the balls, so they take no part of the union's power
  // cells, and every simplex they belong to lies outside K.
  Eigen::Vector3d low = balls.front().center, high = low;
  for (const Ball& b : balls) {
    low = low.cwiseMin(b.center);
    high = high.cwiseMax(b.center);
  }
  double reach = 0;
  for (const Ball& b : balls) reach = std::max(reach, std::sqrt(std::max(b.weight, 0.0)));
  const Eigen::Vector3d mid = (low + high) / 2;
  const double far = 10 * ((high - low).norm() + reach) + 100;
  for (const Eigen::Vector3d& corner : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, -1), Eigen::Vector3d(-1, 1, -1),
                                        Eigen::Vector3d(-1, -1, 1)}) {
    const Eigen::Vector3d x = mid + far * corner;
    points.emplace_back(Regular::Weighted_point(K::Point_3(x.x(), x.y(), x.z()), -1.0), static_cast<int>(points.size()));
  }
  Regular rt(points.begin(), points.end());
  if (rt.dimension() < 3) contract_error("skin_topology: the triangulation with its four far balls is not three-dimensional");
  return detail::count_dual_complex(rt, points.size());
}

}  // namespace skinmesh
