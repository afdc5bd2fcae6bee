// Part of a frame's mesh, renumbered (private to morph/): what the local
// repair, the edits and the dropping of vanished components keep of a mesh.
#pragma once

#include "repair_result.hpp"

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"

#include <vector>

namespace skinmesh::detail {

// The triangles of `mesh` where keep_triangle[f] is non-zero (all of them
// when it is empty) and the vertices they use, with their cells and
// normals, in the mesh's order. kept_from[k]: the index in `mesh` of the
// part's vertex k.
SurfaceMesh used_part(const SurfaceMesh& mesh, const std::vector<char>& keep_triangle, std::vector<int>& kept_from);

// Every vertex marked in `lost` (one transport could not put on the new
// skin) merged into its nearest neighbour that is not lost, along their
// edge, where the link condition holds: the two ends share exactly the two
// neighbours opposite the edge, each keeps three or more neighbours and
// each opposite corner three or more triangles, so the mesh stays a closed
// 2-manifold of the same topology. Lost neighbours of a lost vertex are
// merged first where they can be. The triangles that kept a merged vertex's
// place are left to be judged (they may fail the frame's criteria). True,
// with `mesh` renumbered (kept_from[k]: the old index of vertex k), `lost`
// all zero and `touched` marking per vertex the corners of the triangles
// that changed, when every lost vertex went; false, with `mesh` and `lost`
// as they were, otherwise.
bool merge_lost_vertices(SurfaceMesh& mesh, std::vector<char>& lost, std::vector<int>& kept_from,
                         std::vector<char>& touched);

// Before a frame is remeshed from its vertices: along every mesh edge
// shorter than `below` times the smaller target edge length (`criteria`) at
// its ends, the vertex with the larger index is marked in `drop` (unless
// its partner is marked already); transport crowds vertices where a patch
// shrinks. Returns how many were marked.
long mark_crowded(const SkinComplex& complex, const SurfaceMesh& mesh, const MeshingOptions& criteria, double below,
                  std::vector<char>& drop);

// How many times denser `mesh` is than a fresh mesh of the same skin would
// be: its triangle count over the sum, per triangle, of its area divided by
// the area of an equilateral triangle of the target edge length
// (`criteria`) at its corners, the size the mesher refines to. About 1 to 2
// for a mesh the mesher made; transport onto a shrinking skin raises it
// without bound, as it never removes a vertex.
double density_over_fresh(const SkinComplex& complex, const SurfaceMesh& mesh, const MeshingOptions& criteria);

// The frame remeshed from its vertices not marked in `drop` (remesh_skin);
// `origin` maps the result's vertices to `mesh`'s. Not ok (the mesher's
// message in failed_because) when the mesher cannot.
// `seeds`: more skin points to start from, none of them a vertex of `mesh`
// (new vertices, origin -1).
RepairResult remesh_from_vertices(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& drop,
                                  const MeshingOptions& criteria, const std::vector<SkinSample>& seeds = {});

}  // namespace skinmesh::detail
