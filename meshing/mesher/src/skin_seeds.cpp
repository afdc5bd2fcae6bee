#include "skin_seeds.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <array>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace skinmesh::detail {

std::vector<SkinPoint> critical_point_seeds(const SkinComplex& complex) {
  const double s = complex.shrink();
  // Four directions along the vertices of a regular tetrahedron, turned to a
  // generic position. Only the points whose outward normal is +d are kept:
  // maxima and minima in one direction would be antipodal on a sphere patch,
  // and two antipodal pairs are coplanar and cocircular, which gives flat
  // Delaunay tetrahedra with no usable circumcentre.
  std::array<Eigen::Vector3d, 4> directions{{{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}};
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(0.4137, Eigen::Vector3d(0.3, 0.8, 0.52).normalized()) *
                                Eigen::AngleAxisd(1.1023, Eigen::Vector3d::UnitZ()))
                                   .toRotationMatrix();
  for (auto& d : directions) d = turn * d.normalized();
  // Up to one point per cell and direction, found in parallel (every morph
  // frame asks for them, over every overlay cell) and gathered in cell
  // order, so the seeds are the same with any number of threads.
  const auto& cells = complex.cells();
  std::vector<Eigen::Vector3d> found(4 * cells.size());
  std::vector<char> on_cell(4 * cells.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, cells.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t c = r.begin(); c != r.end(); ++c) {
      const MixedCell& cell = cells[c];
      const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
      const double scale = 1.0 + std::sqrt(std::abs(cell.R2));
      for (size_t k = 0; k < directions.size(); ++k) {
        const Eigen::Vector3d& d = directions[k];
        // u = M^-1 d; Q(z + alpha u) = alpha^2 kappa + s(1-s) R2.
        const Eigen::Vector3d u = (I - cell.P) * d / (1 - s) - cell.P * d / s;
        const double kappa = ((I - cell.P) * d).squaredNorm() / (1 - s) - (cell.P * d).squaredNorm() / s;
        if (kappa == 0.0) continue;
        const double alpha2 = -s * (1 - s) * cell.R2 / kappa;
        if (!(alpha2 > 0)) continue;
        // grad Q = 2 M (x - z) = 2 alpha d: alpha > 0 is the point with outward normal +d.
        const Eigen::Vector3d x = cell.center + std::sqrt(alpha2) * u;
        if (complex.membership_violation(static_cast<int>(c), x) <= 1e-9 * scale) {
          found[4 * c + k] = x;
          on_cell[4 * c + k] = 1;
        }
      }
    }
  });
  std::vector<SkinPoint> seeds;
  for (size_t i = 0; i < found.size(); ++i)
    if (on_cell[i]) seeds.push_back({found[i], static_cast<int>(i / 4)});
  // A critical point on a face shared by several cells is found once per cell.
  std::sort(seeds.begin(), seeds.end(), [](const SkinPoint& p, const SkinPoint& q) {
    return std::tie(p.point[0], p.point[1], p.point[2]) < std::tie(q.point[0], q.point[1], q.point[2]);
  });
  std::vector<SkinPoint> unique;
  for (const SkinPoint& p : seeds) {
    bool duplicate = false;
    for (auto it = unique.rbegin(); it != unique.rend() && p.point[0] - it->point[0] < 1e-7; ++it)
      if ((p.point - it->point).norm() < 1e-7) {
        duplicate = true;
        break;
      }
    if (!duplicate) unique.push_back(p);
  }
  return unique;
}

}  // namespace skinmesh::detail
