// PDB and mmCIF through gemmi. A pre-pass over PDB text validates coordinate
// columns (so a malformed or NaN coordinate is reported with its line) and
// blanks columns 73-80 when they hold old-style identification and sequence
// numbers (e.g. "1HPV 186"), which gemmi would otherwise read as element and
// formal charge and reject ("Wrong format for charge").
#include "reader_detail.hpp"

#include "skinmesh/core/error.hpp"

#include <gemmi/cif.hpp>
#include <gemmi/mmcif.hpp>
#include <gemmi/pdb.hpp>

#include <algorithm>
#include <cctype>
#include <map>
#include <utility>

namespace skinmesh::detail {
namespace {

// Columns 77-78 (element) and 79-80 (charge) as the PDB format defines them.
bool plausible_element_and_charge(const std::string& line) {
  if (line.size() <= 76) return true;
  auto at = [&](size_t i) { return i < line.size() ? line[i] : ' '; };
  const char e1 = at(76), e2 = at(77), c1 = at(78), c2 = at(79);
  const auto letter_or_blank = [](char c) { return c == ' ' || std::isalpha(static_cast<unsigned char>(c)); };
  if (!letter_or_blank(e1) || !letter_or_blank(e2)) return false;
  const bool blank_charge = (c1 == ' ' || c1 == '\r' || c1 == '\n') && (c2 == ' ' || c2 == '\r' || c2 == '\n');
  if (blank_charge) return true;
  const bool digit_sign = std::isdigit(static_cast<unsigned char>(c1)) && (c2 == '+' || c2 == '-');
  const bool sign_digit = (c1 == '+' || c1 == '-') && std::isdigit(static_cast<unsigned char>(c2));
  return digit_sign || sign_digit;
}

// A PDB coordinate is a plain decimal (format F8.3): strtod also takes hex
// floats and exponents ("0x1p3", "1e2"), which gemmi reads otherwise (as 0).
bool plain_decimal(const std::string& field) {
  const size_t first = field.find_first_not_of(' ');
  if (first == std::string::npos) return false;
  const size_t last = field.find_last_not_of(" \r");
  size_t i = first;
  if (field[i] == '+' || field[i] == '-') ++i;
  bool digits = false, point = false;
  for (; i <= last; ++i) {
    const char c = field[i];
    if (std::isdigit(static_cast<unsigned char>(c))) digits = true;
    else if (c == '.' && !point) point = true;
    else return false;
  }
  return digits;
}

struct PdbPrepass {
  std::string text;                              // sanitised copy handed to gemmi
  std::map<std::pair<int, int>, long> line_of;   // (model ordinal, serial) -> line
  bool blanked_old_ids = false;
};

PdbPrepass prepass_pdb(const std::string& path, const std::string& text) {
  PdbPrepass out;
  out.text.reserve(text.size());
  int model = 1;
  bool seen_model_record = false;
  long line_number = 0;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    ++line_number;
    // PDB is printable ASCII. gemmi compares record and residue names
    // through int shifts that a byte above 0x7f makes undefined, and it
    // reads a long line as several, so such a byte anywhere may reach a
    // record name; a NUL would cut gemmi's copy of the line short. In the
    // names of an atom record such a byte is an error, elsewhere it
    // becomes '?'.
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const bool atom_record = line.compare(0, 6, "ATOM  ") == 0 || line.compare(0, 6, "HETATM") == 0;
    for (size_t i = 0; i < line.size(); ++i) {
      const unsigned char c = static_cast<unsigned char>(line[i]);
      if (c <= 0x7f && (c >= 0x20 || c == '\t')) continue;
      if (atom_record && i < 27)
        input_error(path, line_number, "a byte that is not printable ASCII in column " + std::to_string(i + 1) +
                                           " (atom and residue names are ASCII in PDB)");
      line[i] = '?';
    }
    // Columns past a line's end are blank in PDB; gemmi reads some fields
    // at fixed columns without checking the line's length (an SSBOND
    // distance at columns 74-78 of a 75-column line, found by fuzzing:
    // reads past the line's memory), so every line is padded to 80.
    const size_t columns = line.size();
    if (line.size() < 80) line.resize(80, ' ');
    if (line.compare(0, 5, "MODEL") == 0) {
      if (seen_model_record) ++model;
      seen_model_record = true;
    }
    if (line.compare(0, 6, "ATOM  ") == 0 || line.compare(0, 6, "HETATM") == 0) {
      const std::string body = line.substr(0, columns);  // as given, without the padding
      if (body.size() < 54)
        input_error(path, line_number,
                    "coordinate record too short (" + std::to_string(body.size()) +
                        " columns; x, y, z need columns 31-54)");
      static const char* const axes[] = {"x", "y", "z"};
      for (int k = 0; k < 3; ++k) {
        const std::string field = body.substr(30 + 8 * k, 8);
        double value = 0;
        if (!plain_decimal(field) || !parse_finite_double(field, value))
          input_error(path, line_number,
                      std::string("malformed or non-finite ") + axes[k] + " coordinate '" + field +
                          "' (columns " + std::to_string(31 + 8 * k) + "-" + std::to_string(38 + 8 * k) + ")");
      }
      if (!plausible_element_and_charge(body)) {
        for (size_t i = 72; i < body.size() && i < 80; ++i) line[i] = ' ';
        out.blanked_old_ids = true;
      }
      int serial = 0;
      try {
        serial = std::stoi(body.substr(6, 5));
      } catch (...) {
        serial = 0;  // hybrid-36 or blank serial: no line mapping, not an error
      }
      out.line_of.emplace(std::make_pair(model, serial), line_number);
    }
    out.text += line;
    out.text += '\n';
    start = end + 1;
  }
  return out;
}

// gemmi skips an _atom_site table without coordinates, which would leave
// "no atoms found"; name the column instead.
void check_atom_site_columns(gemmi::cif::Document& doc, const std::string& path) {
  for (gemmi::cif::Block& block : doc.blocks) {
    if (!block.find_mmcif_category("_atom_site.").ok()) continue;
    for (const char* tag : {"_atom_site.Cartn_x", "_atom_site.Cartn_y", "_atom_site.Cartn_z"})
      if (!block.has_tag(tag))
        input_error(path, 0, std::string("data block '") + block.name + "': the _atom_site table has no " + tag +
                                 " column");
    // Residue names go through gemmi's int-shift comparisons (as in PDB).
    for (const char* tag : {"_atom_site.label_comp_id", "_atom_site.auth_comp_id"})
      for (const std::string& value : block.find_values(tag))
        if (std::any_of(value.begin(), value.end(), [](char c) { return static_cast<unsigned char>(c) > 0x7f; }))
          input_error(path, 0, std::string("data block '") + block.name + "': a residue name in " + tag +
                                   " is not ASCII");
  }
}

}  // namespace

std::vector<RawModel> read_pdb_or_mmcif(const std::string& path, std::string text, MoleculeFormat format,
                                        std::vector<std::string>& warnings) {
  gemmi::Structure structure;
  PdbPrepass prepass;
  try {
    if (format == MoleculeFormat::Pdb) {
      prepass = prepass_pdb(path, text);
      if (prepass.blanked_old_ids)
        warnings.push_back(path +
                           ": columns 73-80 hold old-style identification/sequence numbers, not "
                           "element and charge; elements were taken from the atom names");
      structure = gemmi::read_pdb_from_memory(prepass.text.data(), prepass.text.size(), path);
    } else {
      gemmi::cif::Document doc = gemmi::cif::read_memory(text.data(), text.size(), path.c_str());
      check_atom_site_columns(doc, path);
      structure = gemmi::make_structure(doc);
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    // gemmi's messages usually carry the line already ("...:12:..." or "line 12").
    input_error(path, 0, std::string("cannot read ") + format_name(format) + ": " + e.what());
  }

  std::vector<RawModel> models;
  int ordinal = 0;
  for (const gemmi::Model& model : structure.models) {
    ++ordinal;
    RawModel raw;
    for (const gemmi::Chain& chain : model.chains)
      for (const gemmi::Residue& residue : chain.residues)
        for (const gemmi::Atom& a : residue.atoms) {
          RawAtom r;
          r.atom.position = Eigen::Vector3d(a.pos.x, a.pos.y, a.pos.z);
          r.atom.element = a.element.uname();
          if (a.element == gemmi::El::X) r.atom.element = "X";
          r.atom.name = a.name;
          r.atom.residue = residue.name;
          r.atom.chain = chain.name;
          r.atom.residue_number = residue.seqid.num.has_value() ? residue.seqid.num.value : 0;
          r.atom.insertion_code = residue.seqid.icode;
          r.atom.altloc = a.altloc == '\0' ? ' ' : a.altloc;
          r.atom.occupancy = a.occ;
          if (format == MoleculeFormat::Pdb) {
            auto it = prepass.line_of.find({ordinal, a.serial});
            if (it != prepass.line_of.end()) r.atom.line = it->second;
          }
          r.hydrogen = a.element == gemmi::El::H || a.element == gemmi::El::D;
          r.water = is_water_residue(residue.name);
          raw.push_back(std::move(r));
        }
    models.push_back(std::move(raw));
  }
  if (models.empty()) input_error(path, 0, std::string("no atoms found (not a ") + format_name(format) + " file?)");
  return models;
}

}  // namespace skinmesh::detail
