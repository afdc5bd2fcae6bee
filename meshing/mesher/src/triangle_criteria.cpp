// The mesher's criteria for one restricted triangle and its size field (see
// skin_mesher.hpp), in the style of Cheng and Shi's restricted Delaunay
// refinement of the skin and Boissonnat and Oudot's surface Delaunay balls.
#include "skinmesh/mesher/skin_mesher.hpp"

#include "criteria_constants.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace skinmesh {

using detail::kToleranceMargin;

const char* triangle_defect_name(TriangleDefect defect) {
  switch (defect) {
    case TriangleDefect::none: return "none";
    case TriangleDefect::topology: return "topology";
    case TriangleDefect::size: return "size";
    case TriangleDefect::distance: return "distance";
    case TriangleDefect::shape: return "shape";
  }
  return "unknown";
}

std::optional<RestrictedTriangle> restricted_triangle(const SkinComplex& complex,
                                                      const std::array<Eigen::Vector3d, 3>& corners, double reach,
                                                      int hint) {
  const Eigen::Vector3d& p0 = corners[0];
  const Eigen::Vector3d u = corners[1] - p0, w = corners[2] - p0;
  const Eigen::Vector3d uxw = u.cross(w);
  const double cross2 = uxw.squaredNorm();
  if (!(cross2 > 0)) return std::nullopt;
  const Eigen::Vector3d circumcenter =
      p0 + (u.squaredNorm() * w.cross(uxw) + w.squaredNorm() * uxw.cross(u)) / (2.0 * cross2);
  const Eigen::Vector3d normal = uxw / std::sqrt(cross2);
  // Corners on the skin and a triangle small against the curvature radius
  // 1/k put the skin within r^2 k / 2 < r of the circumcentre along the
  // normal (r the circumradius): a crossing farther than r is another piece
  // of skin (the far side of a thin void or neck), not this triangle's.
  const double window = std::min(reach, std::sqrt((circumcenter - p0).squaredNorm()));
  // One buffer a thread: a morph judges thousands of triangles a frame, and
  // allocating a vector for each costs about an eighth of the segment's walk.
  thread_local std::vector<SegmentCrossing> hits;
  complex.intersect_segment(circumcenter - window * normal, circumcenter + window * normal, hint, &hits);
  if (hits.empty()) return std::nullopt;
  const auto nearest = std::min_element(hits.begin(), hits.end(), [&](const SegmentCrossing& a, const SegmentCrossing& b) {
    return (a.point - circumcenter).squaredNorm() < (b.point - circumcenter).squaredNorm();
  });
  RestrictedTriangle t;
  t.corners = corners;
  t.ball_center = nearest->point;
  t.ball_cell = nearest->cell;
  t.crossings = static_cast<int>(hits.size());
  return t;
}

TriangleDefect triangle_defect(const SkinComplex& complex, const RestrictedTriangle& triangle,
                               const MeshingOptions& options) {
  if (triangle.crossings > 1) return TriangleDefect::topology;
  const Eigen::Vector3d& p0 = triangle.corners[0];
  const Eigen::Vector3d u = triangle.corners[1] - p0, w = triangle.corners[2] - p0;
  const Eigen::Vector3d uxw = u.cross(w);
  const double cross2 = uxw.squaredNorm();
  if (!(cross2 > 0)) return TriangleDefect::shape;  // collinear corners: no triangle
  const Eigen::Vector3d circumcenter =
      p0 + (u.squaredNorm() * w.cross(uxw) + w.squaredNorm() * uxw.cross(u)) / (2.0 * cross2);
  const double radius = std::sqrt((triangle.ball_center - p0).squaredNorm());
  const double target = target_edge_length(complex, triangle.ball_center, triangle.ball_cell, options);
  if (radius > target / std::sqrt(3.0)) return TriangleDefect::size;
  if ((triangle.ball_center - circumcenter).norm() > kToleranceMargin * options.tolerance)
    return TriangleDefect::distance;
  return shape_passes(triangle.corners, options.min_angle) ? TriangleDefect::none : TriangleDefect::shape;
}

bool shape_passes(const std::array<Eigen::Vector3d, 3>& corners, double min_angle) {
  const Eigen::Vector3d& p0 = corners[0];
  const Eigen::Vector3d u = corners[1] - p0, w = corners[2] - p0;
  const Eigen::Vector3d uxw = u.cross(w);
  const double cross2 = uxw.squaredNorm();
  if (!(cross2 > 0)) return false;
  const Eigen::Vector3d circumcenter =
      p0 + (u.squaredNorm() * w.cross(uxw) + w.squaredNorm() * uxw.cross(u)) / (2.0 * cross2);
  // Circumradius over shortest edge, at most 1 / (2 sin(min_angle)).
  const double circumradius = std::sqrt((circumcenter - p0).squaredNorm());
  const double shortest =
      std::sqrt(std::min({u.squaredNorm(), w.squaredNorm(), (corners[2] - corners[1]).squaredNorm()}));
  // The bound is the same for every triangle a run judges: its sine is kept.
  thread_local double last_angle = std::numeric_limits<double>::quiet_NaN(), last_bound = 0;
  if (!(min_angle == last_angle)) {
    last_bound = 1.0 / (2.0 * std::sin(min_angle * M_PI / 180.0));
    last_angle = min_angle;
  }
  const double max_radius_edge = last_bound;
  return circumradius <= max_radius_edge * shortest;
}

bool faces_outward(const SkinComplex& complex, const RestrictedTriangle& triangle) {
  const auto& c = triangle.corners;
  // The ball centre is a crossing found in ball_cell: no walk to locate it,
  // which cost about a sixth of judging a triangle.
  const Eigen::Vector3d outward = complex.gradient(triangle.ball_cell, triangle.ball_center);
  return (c[1] - c[0]).cross(c[2] - c[0]).dot(outward) > 0;
}

double target_edge_length(const SkinComplex& complex, const Eigen::Vector3d& x, int cell,
                          const MeshingOptions& options) {
  // The curvature-relative size is what keeps the topology (a sample dense
  // with respect to the local radius of curvature sees every handle and
  // neck); a requested edge length can only make triangles smaller. A
  // strictly uniform 1 A mesh of 1ubi loses one of its 68 handles.
  // One curvature evaluation for both sizes below: this runs for every
  // triangle a frame judges.
  const double length = local_length(complex, x, cell);
  double base = size_for_length(length, options.sizing);
  if (options.edge_length > 0) base = std::min(base, options.edge_length);
  // Sphere patches (vertex and tetrahedron cells) have constant curvature, so
  // they need no floor against runaway refinement; without one, a tiny void
  // (a concave sphere a thousandth of an Angstrom across, which real proteins
  // have) is meshed as the closed component it is instead of one lost sample.
  const int dim = complex.cell(cell).dim;
  if (dim == 0 || dim == 3) return std::min(base, options.sizing.epsilon * length);
  return base;
}

}  // namespace skinmesh
