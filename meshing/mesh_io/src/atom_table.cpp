#include "skinmesh/mesh_io/atom_table.hpp"

#include "skinmesh/core/error.hpp"

#include <cstdio>
#include <string>

namespace skinmesh {
namespace {

// A field as the table holds it: no tab or line break inside (they would
// split it), bytes that are not UTF-8 as U+FFFD.
std::string field(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      out.push_back(c == '\t' || c == '\n' || c == '\r' ? ' ' : static_cast<char>(c));
      ++i;
      continue;
    }
    const size_t length = c >= 0xF0 && c < 0xF5 ? 4 : c >= 0xE0 && c < 0xF0 ? 3 : c >= 0xC2 && c < 0xE0 ? 2 : 0;
    bool valid = length > 0 && i + length <= text.size();
    for (size_t k = 1; valid && k < length; ++k) valid = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    if (valid) {
      out.append(text, i, length);
      i += length;
    } else {
      out += "\xef\xbf\xbd";
      ++i;
    }
  }
  return out;
}

}  // namespace

void write_atom_table(std::ostream& out, const Molecule& molecule) {
  const bool residues = molecule.format != MoleculeFormat::Xyzr && molecule.format != MoleculeFormat::Wpts;
  const bool radii = molecule.format != MoleculeFormat::Wpts;
  out << "index\tchain\tresidue_number\tinsertion_code\tresidue_name\tatom_name\telement\tradius\n";
  for (size_t i = 0; i < molecule.atoms.size(); ++i) {
    const Atom& a = molecule.atoms[i];
    char radius[32] = "";
    if (radii) std::snprintf(radius, sizeof radius, "%.6g", a.radius);
    out << i << '\t' << field(a.chain) << '\t' << (residues ? std::to_string(a.residue_number) : "") << '\t'
        << (a.insertion_code == ' ' || a.insertion_code == '\0' ? "" : field(std::string(1, a.insertion_code)))
        << '\t' << field(a.residue) << '\t' << field(a.name) << '\t' << field(a.element) << '\t' << radius << '\n';
  }
  if (!out) output_error("", "writing the atom table failed");
}

}  // namespace skinmesh
