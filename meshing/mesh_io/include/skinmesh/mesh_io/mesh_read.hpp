// Reading surface meshes from other tools as polygon soups (so that a broken
// mesh can be graded, not rejected): OFF, OBJ, STL (ASCII and binary), PLY
// (ASCII and binary little/big endian), Gmsh 4.x ASCII (.msh), and MSMS
// .vert/.face pairs.
#pragma once

#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/core/tet_mesh.hpp"

#include <map>
#include <string>
#include <vector>

namespace skinmesh {

// Chooses the format from the extension (.off .obj .stl .ply .msh .vert .face; for
// MSMS either file of the pair). Polygons with more than three corners are fanned
// into triangles. STL corners are merged when their coordinates are identical.
// Throws InputError naming the file and line.
SurfaceMesh read_surface_mesh(const std::string& path);

// A PLY file with its per-vertex scalar properties kept by name (a mesh's
// `patch` and `atom`, a morph frame's `id`, `source_atom`, `target_atom`,
// normals...), each one value per vertex, as doubles. Throws InputError.
struct PlyMesh {
  SurfaceMesh mesh;
  std::map<std::string, std::vector<double>> vertex_properties;  // every scalar one but x, y, z
};
PlyMesh read_ply_with_properties(const std::string& path);

// A tetrahedral mesh: TetGen's .node/.ele/.face set (any one of the three
// names; the .face file is optional) with regions from the first .ele
// attribute and face markers, or a Gmsh 4.x ASCII .msh whose tetrahedra take
// their volume entity's tag as region and triangles their surface entity's tag
// as marker. Throws InputError naming the file and line.
TetMesh read_tet_mesh(const std::string& path);

// Everything in a Gmsh 4.x ASCII file as a TetMesh: its tetrahedra (possibly
// none) and its triangles with their markers, read once; `quality` grades it
// as a volume when it has tetrahedra and as a surface otherwise.
TetMesh read_gmsh_volume(const std::string& path);

}  // namespace skinmesh
