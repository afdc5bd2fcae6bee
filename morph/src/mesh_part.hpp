// Part of a frame's mesh, renumbered (private to morph/): what the local
// repair, the edits and the dropping of vanished components keep of a mesh.
#pragma once

#include "skinmesh/core/surface_mesh.hpp"

#include <vector>

namespace skinmesh::detail {

// The triangles of `mesh` where keep_triangle[f] is non-zero (all of them
// when it is empty) and the vertices they use, with their cells and
// normals, in the mesh's order. kept_from[k]: the index in `mesh` of the
// part's vertex k.
SurfaceMesh used_part(const SurfaceMesh& mesh, const std::vector<char>& keep_triangle, std::vector<int>& kept_from);

}  // namespace skinmesh::detail
