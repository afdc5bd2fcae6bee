// Where a step of moving balls leaves the skin the same function (private
// to morph/): the judge keeps the verdict of a triangle whose corners did
// not move and around which nothing the judge reads changed.
#pragma once

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"

#include <vector>

namespace skinmesh::detail {

// Per vertex of `mesh` marked in `marked`, the radius (Angstrom) of a
// ball about it that holds everything the frame judge reads for each
// triangle around it: the segment of the triangle's normal line through
// its circumcentre within min(tolerance, circumradius) of it
// (restricted_triangle); infinite next to a degenerate triangle. 0 for a
// vertex not marked or no triangle uses.
std::vector<double> judged_reach(const SurfaceMesh& mesh, double tolerance, const std::vector<char>& marked);

// Per vertex of `mesh` marked in `candidates`, 1 where the skin of `from`
// and of the balls `to` (the same balls after a step: same count, each
// moved or not) is the same function, with the same mixed cells, within
// radius[v] of the vertex; 0 where that is not proven. MATH.md section 2:
// F is the value of a convex QP over the simplex, and a ball that moved is
// inactive wherever its KKT slack against the optimum over the balls that
// stayed is positive, at its place before the step and after it. The
// vertices must lie on the skin of `from` to 1e-9 Angstrom^2 in F (the
// engine's lie within 1e-12 A); what is proven is the function and its
// mixed cells, so a judge that locates a cell within its tolerances of a
// boundary between two cells of atoms that stayed may still pick the
// other one.
std::vector<char> skin_unchanged_near(const SkinComplex& from, const std::vector<Ball>& to, const SurfaceMesh& mesh,
                                      const std::vector<double>& radius, const std::vector<char>& candidates);

// A rigid motion: x -> rotation x + translation (Angstrom).
struct RigidMotion {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const { return rotation * x + translation; }
  // Whether the motion took ball `before` to `after`, to 1e-9 A (as the
  // judge's carried triangles, judge.hpp), its weight kept.
  bool carries(const Ball& before, const Ball& after) const {
    return before.weight == after.weight && ((*this)(before.center) - after.center).norm() <= 1e-9;
  }
};

// The balls after a step (`after`) as seen by one who moved with `motion`:
// a ball that `motion` carried (to 1e-9 A, its weight kept) at its place
// before the step, bit for bit; every other one taken back by the motion's
// inverse. Where skin_unchanged_near(from, these, ...) proves the skin of
// `from` unchanged near a vertex x, the skin after the step is that skin
// moved by `motion`: F after at motion(x) is F before at x, with the
// same mixed cells moved, so a triangle carried by `motion` sees a
// congruent skin within the judge's reach.
std::vector<Ball> balls_moving_with(const RigidMotion& motion, const std::vector<Ball>& before,
                                    const std::vector<Ball>& after);

}  // namespace skinmesh::detail
