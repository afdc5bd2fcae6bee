// The table of a mesh's atoms, written beside it (OUT.atoms.tsv, a morph's
// source_atoms.tsv and target_atoms.tsv): what the per-vertex atom indices
// of the mesh files name. UTF-8 text, tab-separated, the header
//   index chain residue_number insertion_code residue_name atom_name element radius
// then one line per atom, index 0-based in the molecule's order after its
// filters (the order of its balls). A field the input does not give is
// empty: XYZR and .wpts carry no residues, .wpts no radius, XYZR and .wpts
// no element.
#pragma once

#include "skinmesh/core/molecule.hpp"

#include <ostream>

namespace skinmesh {

void write_atom_table(std::ostream& out, const Molecule& molecule);

}  // namespace skinmesh
