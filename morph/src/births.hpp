// Components and voids born in a step, mended by surgery (private to
// morph/): at a critical event of dimension 0 or 3 that raises the skin's
// Euler characteristic by 2 (TopologyChange::birth) a new sphere of skin
// appears in the event's mixed cell, where the skin is the cell's quadric
// (docs/math.md section 3): |x - z|^2 = -s R2 about the ball of a vertex
// cell (a component, facing out) and |x - z|^2 = (1-s) R2 about the
// orthocentre of a tetrahedron (a void, facing its centre). As Stander and
// Hart (1997) attach a new sphere at an index-0 critical point of an
// implicit surface, the sphere is meshed as a component of its own: an
// icosahedron on it, its triangles split in four (midpoints put back on
// the sphere) until every one passes the frame judge (judge.hpp).
#pragma once

#include "local_repair.hpp"
#include "repair_result.hpp"

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/repair_policy.hpp"

#include <optional>
#include <vector>

namespace skinmesh::detail {

// The birth's sphere as a closed mesh (vertices exactly on it, all in the
// change's cell, with cells and normals; triangles facing as the skin
// does), every triangle passing `criteria`; empty when the change is not a
// birth of dimension 0 or 3 with a cell, a vertex would lie outside the
// cell (the skin there is not the sphere), or four splits do not pass.
std::optional<SurfaceMesh> born_sphere(const SkinComplex& complex, const TopologyChange& change,
                                       const MeshingOptions& criteria);

// The births among `changes` that `done` (one entry per change) does not
// mark, in whose cell no vertex of `mesh` lies, and that born_sphere
// meshes, added to `r` as components of their own and marked in `done`.
// `r` is the frame after a surgery before this one
// (neck_surgery's result, when ok) or, when not ok, nothing yet: it then
// becomes `mesh` with `failing` (origin the identity) once a sphere is
// added. New vertices have origin -1; new triangles pass (failing 0).
// Returns how many births were added.
long add_born_spheres(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                      const std::vector<TopologyChange>& changes, const MeshingOptions& criteria, RepairResult& r,
                      std::vector<char>& done);

// Surgery at a step's topology events, as `policy` allows (neck_surgery,
// birth_surgery): necks cut and joined or capped (necks.hpp), then births
// meshed as spheres. `result` as neck_surgery's (ok when one was made);
// the changes made are taken out of `local` (take_done_changes), and
// `necks` and `births` count them.
struct EventSurgery {
  RepairResult result;
  long necks = 0, births = 0;
};
EventSurgery surgery_at_events(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                               const MeshingOptions& criteria, const RepairPolicy& policy, LocalRepairOptions& local);

}  // namespace skinmesh::detail
