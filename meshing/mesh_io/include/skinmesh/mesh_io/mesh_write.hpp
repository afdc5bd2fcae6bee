// Writing the flat exchange mesh in the formats solvers and viewers read.
// Coordinates go out at full double precision unless single precision is
// asked for: a vertex exactly on the skin stays on it in the file.
#pragma once

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/surface_mesh.hpp"

#include <array>
#include <cstdint>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace skinmesh {

enum class MeshFormat { ply, off, obj, stl, vtp, msms, gmsh, glb };

// From the file name: .ply .off .obj .stl .vtp .msh .glb .vert (MSMS: .vert and .face).
// Throws ContractError for anything else.
MeshFormat mesh_format_from_path(const std::string& path);
const char* mesh_format_name(MeshFormat format);

// Per-vertex attributes written where the format has room for them (PLY, VTP,
// MSMS): the patch type (dimension of the mixed cell's Delaunay simplex: 0 and
// 3 sphere, 1 and 2 hyperboloid) and the owning atom (0-based index into the
// molecule's atoms).
// How a further property is typed in the file. Viewers read an atom index
// as unsigned (Mol* groups a PLY by `atomid` and sizes a table by the
// largest), so atom columns are uint32 and never hold a negative value.
enum class PropertyType { int32, uint32, uint8 };
struct VertexProperty {
  std::string name;
  PropertyType type = PropertyType::int32;
  std::vector<int> values;  // one per vertex; the unsigned types' non-negative (checked when written)
};
using Rgb = std::array<std::uint8_t, 3>;  // sRGB, 0-255

struct VertexAttributes {
  std::vector<int> patch;
  std::vector<int> atom;
  // Further integer properties, one value per vertex (atomid; a morph
  // frame's id, source_atom, has_source_atom, ...); PLY and VTP only.
  std::vector<VertexProperty> more;
  // Per-vertex colours, or empty: PLY red/green/blue, glTF COLOR_0.
  std::vector<Rgb> colours;
};

struct MeshWriteOptions {
  bool single_precision = false;  // PLY float properties, 9 significant digits in text
  bool ascii = false;             // PLY and VTP as text (17 or 9 significant digits): PyMOL 2.5 reads text PLY only
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
