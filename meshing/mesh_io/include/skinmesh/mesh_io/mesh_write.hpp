// Writing the flat exchange mesh in the formats solvers and viewers read.
// Coordinates go out at full double precision unless single precision is
// asked for: a vertex exactly on the skin stays on it in the file.
#pragma once

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/surface_mesh.hpp"

#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace skinmesh {

enum class MeshFormat { ply, off, obj, stl, vtp, msms, gmsh };

// From the file name: .ply .off .obj .stl .vtp .vert (MSMS: .vert and .face).
// Throws ContractError for anything else.
MeshFormat mesh_format_from_path(const std::string& path);
const char* mesh_format_name(MeshFormat format);

// Per-vertex attributes written where the format has room for them (PLY, VTP,
// MSMS): the patch type (dimension of the mixed cell's Delaunay simplex: 0 and
// 3 sphere, 1 and 2 hyperboloid) and the owning atom (0-based index into the
// molecule's atoms).
struct VertexAttributes {
  std::vector<int> patch;
  std::vector<int> atom;
  // Further integer properties by name, one value per vertex (a morph frame's
  // id, source_atom, target_atom); PLY and VTP only.
  std::vector<std::pair<std::string, std::vector<int>>> more;
};

struct MeshWriteOptions {
  bool single_precision = false;  // PLY float properties, 9 significant digits in text
};

// Every format but MSMS, whose two files have their own writers below.
void write_mesh(std::ostream& out, const SurfaceMesh& mesh, MeshFormat format, const VertexAttributes* attributes,
                const MeshWriteOptions& options = {});

// MSMS .vert: x y z nx ny nz 0 sphere atom (1-based atom, as MSMS numbers them);
// MSMS .face: v1 v2 v3 1 sphere (1-based vertices).
void write_msms_vert(std::ostream& out, const SurfaceMesh& mesh, const VertexAttributes* attributes,
                     const MeshWriteOptions& options = {});
void write_msms_face(std::ostream& out, const SurfaceMesh& mesh, const VertexAttributes* attributes);

}  // namespace skinmesh
