// The mesher's guarantees, measured on a finished mesh by means independent
// of the mesher: every smallest angle at least the bound, every vertex on the
// skin (the oracle of docs/math.md section 2), a closed, consistently
// oriented 2-manifold enclosing positive volume, and no self-intersections
// (exact, CGAL). One check for `skinmesh mesh`, `skinmesh volume`, the tests
// and every frame of a morph.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/quality/on_surface_error.hpp"

#include <optional>
#include <vector>

namespace skinmesh {

struct GuaranteeOptions {
  double min_angle = 30.0;           // degrees: the bound every triangle's smallest angle must meet
  double on_skin_tolerance = 1e-9;   // Angstrom: largest oracle distance of a vertex from the skin
  SelfIntersectionCheck self_intersections = SelfIntersectionCheck::exact;
};

struct GuaranteeReport {
  MeshQuality quality;                         // the full grade of the mesh
  SurfaceError surface_error;                  // oracle distances of the vertices
  bool angle = false;                          // some triangle, and every smallest angle >= the bound
  bool on_skin = false;                        // every vertex within the tolerance (uncertified ones counted in surface_error)
  bool closed_oriented_manifold = false;       // closed, manifold, consistently oriented, positive volume
  std::optional<bool> no_self_intersections;   // empty when the check was skipped
  bool all_hold() const {
    return angle && on_skin && closed_oriented_manifold && no_self_intersections.value_or(true);
  }
};

// `balls` and `shrink` define the skin the mesh claims to approximate.
GuaranteeReport check_guarantees(const SurfaceMesh& mesh, const std::vector<Ball>& balls, double shrink,
                                 const GuaranteeOptions& options = {});

}  // namespace skinmesh
