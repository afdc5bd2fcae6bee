// Per-vertex colours for the files that carry them (PLY red/green/blue,
// glTF COLOR_0), by a field the user chooses with --colour.
#pragma once

#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"

#include <string>
#include <vector>

namespace skinmesh::app {

// none: no colours written. chain, residue, element: the vertex's atom's
// (residue: a spectrum from blue at the molecule's first residue to red at
// its last, in file order). patch: blue on one atom's sphere, yellow and
// orange on the hyperboloids between two and three atoms, red on the
// concave sphere between four. quality: the smallest angle of the vertex's
// triangles, red at 20 degrees or less through yellow at 40 to blue at 60.
enum class Colouring { none, chain, residue, element, patch, quality };
inline const char* colouring_help() {
  return "per-vertex colours of PLY and glTF files: none, chain, residue (a spectrum along the residues), element, "
         "patch (sphere, hyperboloid, concave) or quality (smallest angle)";
}
const std::vector<std::string>& colouring_names();
Colouring colouring_from_name(const std::string& name);
bool colours_by_atom(Colouring c);  // chain, residue, element

// Each atom's colour, for chain, residue and element.
std::vector<Rgb> atom_colours(Colouring c, const std::vector<Atom>& atoms);

// Per vertex: `atom_colour` (one per vertex, the colour of its atom) when
// colouring by atom; else from the patch types or the mesh. Empty for none.
std::vector<Rgb> vertex_colours(Colouring c, const SurfaceMesh& mesh, const std::vector<int>& patch,
                                const std::vector<Rgb>& atom_colour);

}  // namespace skinmesh::app
