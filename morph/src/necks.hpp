// Necks that open or pinch, mended by surgery (private to morph/): at a
// critical event of dimension 1 or 2 the skin near the event's apex turns
// from two caps facing each other across the cell's axis into a tube around
// it (a neck opens: the skin's Euler characteristic falls by 2), or back (a
// neck pinches: it rises by 2). In the event's mixed cell the skin is the
// cell's quadric, in cylindrical coordinates about the axis
// r^2 = alpha h^2 + beta (docs/math.md section 6): a tube when beta > 0, two
// caps when beta < 0.
//
// The surgery follows Stander and Hart (1997), who change an implicit
// surface's mesh at each critical point by the handle it attaches: the
// triangles with a corner in a cylinder about the axis are cut out, which
// must leave two boundary loops that each wind once around the axis, one on
// either side of the apex; a neck that opens joins the loops by a tube of
// rings of skin points, one that pinches closes each loop by a cap at the
// skin's point on the axis. The new triangles are left failing, for the
// edits (surgery.hpp) to refine; the frame's certificate checks the result.
#pragma once

#include "local_repair.hpp"
#include "repair_result.hpp"

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"

#include <vector>

namespace skinmesh::detail {

// The changes of dimension 1 or 2 with a neck cell (TopologyChange::dim,
// euler_change, neck_cell) cut and joined or capped where their cut leaves
// two loops around the axis; `done` (per change) marks those made. The
// result: ok when at least one was made; its mesh, `origin` (per vertex, the
// index before or -1 for a new one), `failing` (the triangles kept keep
// `failing`'s verdict, new ones are 1) and `left`. A tube's rings and their
// points are spaced by the target edge length of `criteria`.
RepairResult neck_surgery(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                          const std::vector<TopologyChange>& changes, const MeshingOptions& criteria,
                          std::vector<char>& done);

// The changes `done` marks (neck_surgery's) taken out of local.changes,
// and the Euler characteristic they made out of local.euler_change, which
// the patch must then make for the rest. Returns how many were taken.
long take_done_changes(const std::vector<char>& done, LocalRepairOptions& local);

}  // namespace skinmesh::detail
