// Repair of a transported frame by local edits (private to morph/): each
// triangle that fails the frame's criteria is mended where it lies, by an
// edge flip, the contraction of a crowded edge, the split of its longest
// edge at a new point exactly on the skin, or (where transport turned a
// triangle over) moving a corner back among its neighbours, on the skin, and only the triangles an edit
// makes are judged again. The cost follows the failing triangles, not the
// frame. Every edit keeps the mesh a closed manifold of the same topology
// (flips keep it; a split adds a vertex inside an edge; a contraction is made
// only under the link condition), and the repair succeeds only when every
// triangle of the result meets the criteria but those no edit could mend
// (flagged); the caller remeshes those, or the frame, instead.
#pragma once

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"

#include <vector>

namespace skinmesh::detail {

struct EditRepairOptions {
  // An edge of a failing triangle shorter than this times the target edge
  // length at its ends is contracted (transport crowds vertices where a
  // patch shrinks; the same share as the whole-frame repair's).
  double crowded_below = 0.4;
  // Edits allowed per failing triangle (plus a few); past it the repair gives up.
  long edits_per_failing = 16;
};

struct EditRepair {
  bool ok = false;
  SurfaceMesh mesh;          // the whole frame after the repair (vertices no triangle uses dropped)
  std::vector<long> origin;  // per vertex: its index in the mesh before, or -1 when inserted
  long flips = 0, splits = 0, contractions = 0;
  long relocations = 0;      // vertices moved back among their neighbours (ids and triangles kept)
  long judged = 0;           // triangles judged again after an edit
  // Per triangle of `mesh`: 1 where no edit mended it (a turned-over
  // triangle whose corners cannot be contracted, an edge whose split point
  // is not near it); the caller remeshes those in patches.
  std::vector<char> failing;
  long stuck = 0;
};

// `failing`: per triangle of `mesh`, non-zero where it fails `accept` on the
// skin of `complex` (failing_triangles). Every triangle of the result not
// flagged in EditRepair::failing passes (triangle_passes). ok is false when
// the edits pass their budget.
EditRepair repair_by_edits(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                           const MeshingOptions& accept, const EditRepairOptions& options = {});

}  // namespace skinmesh::detail
