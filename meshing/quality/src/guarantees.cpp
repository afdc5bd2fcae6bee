#include "skinmesh/quality/guarantees.hpp"

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace skinmesh {
namespace {

// Each vertex's distance by the oracle; a vertex it cannot certify is
// measured on the complex of the skin's balls built from scratch (the
// skin function, |F| / |grad F|), which no mesher's state enters either.
SurfaceError distances(const std::vector<Eigen::Vector3d>& vertices, const SkinReference& skin) {
  std::optional<SkinOracle> own_oracle;
  if (!skin.oracle) own_oracle.emplace(skin.balls, skin.shrink);
  const std::vector<SkinDistance> d =
      oracle_distances(vertices, skin.oracle ? skin.oracle : point_oracle(*own_oracle),
                       skin.starts.size() == vertices.size() ? skin.starts : std::vector<OracleStart>{});
  std::vector<double> off(d.size());
  SurfaceError e;
  for (size_t v = 0; v < d.size(); ++v) {
    off[v] = d[v].distance;
    e.uncertified += !d[v].certified;
  }
  if (e.uncertified > 0) {
    const SkinComplex own = build_skin_complex(skin.balls, {skin.shrink});
    for (size_t v = 0; v < off.size(); ++v)
      if (!d[v].certified) {
        const SkinEval f = own.evaluate(vertices[v]);
        const double g = f.gradient.norm();
        off[v] = g > 0 ? std::abs(f.value) / g : INFINITY;
      }
  }
  if (off.empty()) return e;
  e.max = *std::max_element(off.begin(), off.end());
  e.mean = std::accumulate(off.begin(), off.end(), 0.0) / static_cast<double>(off.size());
  return e;
}

}  // namespace

GuaranteeReport check_guarantees(const SurfaceMesh& mesh, const SkinReference& skin, const GuaranteeOptions& options) {
  GuaranteeReport r;
  GradeOptions grade;
  grade.self_intersections = options.self_intersections;
  grade.changed = options.changed_triangles;
  // The grade (its exact self-intersection test is serial) beside the
  // oracle's distances (parallel over the vertices) and the skin's alpha
  // complex: together they keep both cores busy.
  tbb::parallel_invoke([&] { r.quality = grade_mesh(mesh, grade); },
                       [&] { r.surface_error = distances(mesh.vertices, skin); },
                       [&] {
                         if (options.topology) r.skin = skin.topology ? *skin.topology : skin_topology(skin.balls);
                       });
  const MeshQuality& q = r.quality;
  // The bound is met to rounding: angles are computed from the written
  // doubles, and a triangle refined to exactly 30 degrees reads 30 - 1e-14.
  r.angle = q.triangles > 0 && q.min_angle >= options.min_angle - 1e-9;
  r.on_skin = r.surface_error.max <= options.on_skin_tolerance;
  r.closed_oriented_manifold = q.closed && q.manifold && q.oriented && q.volume > 0;
  if (options.self_intersections == SelfIntersectionCheck::exact)
    r.no_self_intersections = q.self_intersections_checked && q.self_intersecting_pairs == 0;
  if (r.skin)
    r.topology = q.components == r.skin->components && q.cavities == r.skin->voids && q.euler == r.skin->euler;
  return r;
}

GuaranteeReport check_guarantees(const SurfaceMesh& mesh, const std::vector<Ball>& balls, double shrink,
                                 const GuaranteeOptions& options) {
  return check_guarantees(mesh, SkinReference{balls, shrink, {}, {}, {}}, options);
}

}  // namespace skinmesh
