#include "skinmesh/quality/guarantees.hpp"

#include <tbb/parallel_invoke.h>

namespace skinmesh {

GuaranteeReport check_guarantees(const SurfaceMesh& mesh, const std::vector<Ball>& balls, double shrink,
                                 const GuaranteeOptions& options) {
  GuaranteeReport r;
  GradeOptions grade;
  grade.self_intersections = options.self_intersections;
  // The grade (its exact self-intersection test is serial) beside the
  // oracle's distances (parallel over the vertices): together they keep both
  // cores busy.
  tbb::parallel_invoke([&] { r.quality = grade_mesh(mesh, grade); },
                       [&] { r.surface_error = on_surface_error(mesh.vertices, balls, shrink); });
  const MeshQuality& q = r.quality;
  // The bound is met to rounding: angles are computed from the written
  // doubles, and a triangle refined to exactly 30 degrees reads 30 - 1e-14.
  r.angle = q.triangles > 0 && q.min_angle >= options.min_angle - 1e-9;
  r.on_skin = r.surface_error.max <= options.on_skin_tolerance;
  r.closed_oriented_manifold = q.closed && q.manifold && q.oriented && q.volume > 0;
  if (options.self_intersections == SelfIntersectionCheck::exact)
    r.no_self_intersections = q.self_intersections_checked && q.self_intersecting_pairs == 0;
  return r;
}

}  // namespace skinmesh
