// Local repair of a transported frame (private to morph/): the triangles
// that fail the frame's criteria, grown by a few rings, are remeshed by
// restricted Delaunay refinement of their own vertices (mesher's mesh_patch,
// with a ring of context vertices around them) and stitched back. The seam
// is checked: every vertex of the patch must end with one disk of
// triangles, and every new triangle must meet the criteria. Where it fails,
// the patch is grown around the faults and meshed again (only its pieces
// with faults, PatchPolicy::retry_in_pieces); when the attempts end with
// faults left, the repair reports failure and the caller remeshes the frame.
#pragma once

#include "repair_result.hpp"

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/repair_policy.hpp"

#include <array>
#include <string>
#include <vector>

namespace skinmesh::detail {

// A place where the skin's topology changes between the frames (a critical
// event's apex at the new frame): the triangles with a corner within
// `radius` of `point` join the patch.
struct TopologyChange {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double radius = 0;  // Angstrom
  // The patch is seeded with skin points found from six points half of
  // `size` (sqrt|R2|, at least 1e-3 A) away from `point` along the axes, in
  // `cell` of the complex, and, but for a birth, from `point` itself. A
  // birth: a component or a void born there, `point` the centre of the new
  // sphere (no vertex lies on it yet).
  bool birth = false;
  double size = 0;  // Angstrom
  int cell = -1;
  // The event's dimension, its change of the skin's Euler characteristic (0
  // when another event of the step cancels it) and, for a neck (dimension 1
  // or 2), its cell in the complex after the step (-1: not there), where
  // neck_surgery (necks.hpp) reads the skin's quadric.
  int dim = -1;
  int euler_change = 0;
  int neck_cell = -1;
};

struct LocalRepairOptions {
  PatchPolicy policy;          // rings, attempts, the largest patch (repair_policy.hpp)
  double crowded_below = 0.4;  // interior vertices this close (times the target length) are removed
  // Topology changes the patch must make (none: the topology must stay), and
  // the change of the Euler characteristic they add up to (the critical
  // events', events.hpp). The components may change by at most one a change.
  std::vector<TopologyChange> changes;
  long euler_change = 0;
  // The caller counts the patched mesh's components itself (MovingBalls'
  // certificate, mesh_topology) and remeshes when they are wrong: the patch
  // then checks the Euler characteristic alone, saving two passes over the
  // whole frame.
  bool components_certified_after = false;
};

// Skin points around the places where the topology changed, for a whole
// frame remeshed from its vertices (remesh_from_vertices' seeds): from each
// change's apex and from six points along the axes half its size (at least
// 1e-3 A) away, projected onto the skin. A neck that opened within the step
// can be too thin for any vertex to lie on it; refinement started from
// transported vertices then closed it again (the frame's Euler
// characteristic off by two), where these points make it resolve the neck.
// Points within 1e-6 A of one another are kept once.
std::vector<SkinSample> seeds_at_changes(const SkinComplex& complex, const std::vector<TopologyChange>& changes);

// `failing`: per triangle of `mesh`, non-zero where it fails `accept` on
// the skin of `complex` (all zero is fine when options.changes is not
// empty). The patch is refined to `repair` (stricter, for room before the
// next failure); its new triangles must meet `accept`.
// The result: ok, or failed_because; counts.insertions and patch_triangles,
// attempts and attempted_triangles.
RepairResult repair_locally(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                           const MeshingOptions& repair, const MeshingOptions& accept,
                           const LocalRepairOptions& options);

}  // namespace skinmesh::detail
