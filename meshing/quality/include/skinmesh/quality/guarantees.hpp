// The mesher's guarantees, measured on a finished mesh by means independent
// of the mesher: every smallest angle at least the bound, every vertex on the
// skin (an oracle that builds no triangulation: docs/math.md section 2, or
// section 4 for a frame of the m x n morph), a closed, consistently oriented
// 2-manifold enclosing positive volume, no self-intersections (exact,
// CGAL), and the skin's topology: components, voids and Euler characteristic
// those counted from the alpha complex of its balls (skin_topology). One
// check for `skinmesh mesh`, `skinmesh volume`, the tests and every frame of
// a morph.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/quality/on_surface_error.hpp"

#include <Eigen/Core>

#include <functional>
#include <optional>
#include <vector>

namespace skinmesh {

// The skin a mesh claims to approximate, as the check sees it.
struct SkinReference {
  // Its balls: the topology comes from their alpha complex, and a vertex the
  // oracle cannot certify is measured on their complex built from scratch.
  std::vector<Ball> balls;
  double shrink = 0.5;
  // The oracle; empty: the static oracle of `balls` (SkinOracle).
  PointOracle oracle;
  // Per vertex, or empty: where the oracle's solve starts at it
  // (OracleStart, indices into `balls`; a mesher's vertex: its mixed cell's
  // balls). The oracle certifies its answer whatever the start.
  std::vector<OracleStart> starts;
  // The skin's topology when the caller has counted it already, by
  // skin_topology on these same balls (the moving-balls engine does at every
  // step); empty: counted here.
  std::optional<SkinTopology> topology;
};

// The static oracle's answers at a checked mesh's vertices, for the check
// of a later mesh of nearly the same balls (a frame of moving atoms): an
// answer at the same point stands, not asked again, when no ball within
// its reach changed (by index, centre and weight), the balls are as many,
// none weighs more than the heaviest did, and the shrink is the same
// (OracleResult::reach).
struct OracleAnswers {
  std::vector<Ball> balls;
  double shrink = 0;
  std::vector<Eigen::Vector3d> points;
  std::vector<SkinDistance> distances;  // per point
};

struct GuaranteeOptions {
  double min_angle = 30.0;           // degrees: the bound every triangle's smallest angle must meet
  double on_skin_tolerance = 1e-9;   // Angstrom: largest distance of a vertex from the skin
  SelfIntersectionCheck self_intersections = SelfIntersectionCheck::exact;
  // Per triangle, changed since a certified frame (GradeOptions::changed); null: every pair tested.
  const std::vector<char>* changed_triangles = nullptr;
  bool topology = true;              // components, voids and Euler characteristic those of the skin
  // With the static oracle (SkinReference::oracle empty): earlier answers
  // that stand for these balls are kept (OracleAnswers); null: every vertex asked.
  const OracleAnswers* earlier = nullptr;
  bool report_distances = false;     // GuaranteeReport::distances filled (for the next frame's `earlier`)
};

struct GuaranteeReport {
  MeshQuality quality;                         // the full grade of the mesh
  // Distances of the vertices: by the oracle, and where it could not
  // certify (counted in `uncertified`), on the balls' complex built from scratch.
  SurfaceError surface_error;
  std::vector<SkinDistance> distances;         // per vertex, by the oracle, with GuaranteeOptions::report_distances
  long distances_kept = 0;                     // vertices whose answer came from GuaranteeOptions::earlier
  std::optional<SkinTopology> skin;            // the skin's topology, when checked
  bool angle = false;                          // some triangle, and every smallest angle >= the bound
  bool on_skin = false;                        // every vertex within the tolerance
  bool closed_oriented_manifold = false;       // closed, manifold, consistently oriented, positive volume
  std::optional<bool> no_self_intersections;   // empty when the check was skipped
  std::optional<bool> topology;                // empty when the check was skipped
  bool all_hold() const {
    return angle && on_skin && closed_oriented_manifold && no_self_intersections.value_or(true) &&
           topology.value_or(true);
  }
};

GuaranteeReport check_guarantees(const SurfaceMesh& mesh, const SkinReference& skin,
                                 const GuaranteeOptions& options = {});

// The skin of `balls` at `shrink`, by the static oracle.
GuaranteeReport check_guarantees(const SurfaceMesh& mesh, const std::vector<Ball>& balls, double shrink,
                                 const GuaranteeOptions& options = {});

}  // namespace skinmesh
