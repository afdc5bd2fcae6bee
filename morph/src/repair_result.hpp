// What one rung of the repair ladder made of a frame (private to morph/):
// the edits (surgery.hpp), a local patch (local_repair.hpp) or the whole
// frame remeshed from its vertices (mesh_part.hpp). Every rung says where
// each vertex of its mesh came from, so both engines carry their ids
// through any rung by one call (carry_ids) and add its counts in one place.
#pragma once

#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/morph/morph.hpp"

#include <string>
#include <vector>

namespace skinmesh::detail {

struct RepairCounts {
  long splits = 0, flips = 0, contractions = 0;  // edits
  long insertions = 0;       // refinement insertions, each at a failing triangle (patches, remeshes)
  long patch_triangles = 0;  // triangles a patch replaced
};

struct RepairResult {
  bool ok = false;
  std::string failed_because;  // when !ok: which check gave up
  SurfaceMesh mesh;            // the whole frame after the rung
  std::vector<long> origin;    // per vertex of `mesh`: its index in the mesh before, or -1 when new
  std::vector<char> failing;   // edits: per triangle of `mesh`, still failing the frame criteria
  long left = 0;               // edits: triangles still failing
  long thin_tried = 0;         // edits: edges thinning tried to contract
  long attempts = 0;           // local patch: attempts made (with a second round whole, both rounds')
  long attempted_triangles = 0;  // local patch: triangles of the region each attempt remeshed, summed
  long context_vertices = 0;     // local patch: context vertices each attempt's refinement held, summed
  bool wrong_topology = false;   // local patch: the seam held, the Euler characteristic or components did not
  RepairCounts counts;
};

// The ids of the mesh before (per vertex) carried to `origin`'s mesh: a
// vertex that came from one keeps its id, a new one takes next_id, next_id + 1, ...
inline std::vector<long> carry_ids(const std::vector<long>& origin, const std::vector<long>& ids, long& next_id) {
  std::vector<long> out(origin.size());
  for (size_t v = 0; v < out.size(); ++v) out[v] = origin[v] >= 0 ? ids[static_cast<size_t>(origin[v])] : next_id++;
  return out;
}

// A rung that made the frame (r.ok): the frame's ids carried to its mesh
// and its counts added to the frame's stats, the one place both engines do
// it. The mesh stays in `r` for the caller.
inline void take_ids_and_counts(const RepairResult& r, std::vector<long>& ids, long& next_id, FrameStats& stats) {
  ids = carry_ids(r.origin, ids, next_id);
  stats.split += r.counts.splits;
  stats.flipped += r.counts.flips;
  stats.contracted += r.counts.contractions;
  stats.repairs += r.counts.insertions;
  stats.patch_triangles += r.counts.patch_triangles;
  stats.repaired = true;
}

}  // namespace skinmesh::detail
