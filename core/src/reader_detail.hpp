// Private to core/: what each format reader hands to the common filter.
#pragma once

#include "skinmesh/core/molecule.hpp"

#include <string>
#include <vector>

namespace skinmesh::detail {

struct RawAtom {
  Atom atom;
  bool radius_given = false;  // PQR/XYZR carry their own radius
  bool hydrogen = false;
  bool water = false;
};
using RawModel = std::vector<RawAtom>;

// Whole file as text, gunzipped when it starts with the gzip magic. Throws
// InputError when the file is missing, not a regular file, unreadable, empty,
// or more than max_bytes of text (gunzipped size included).
std::string read_file_text(const std::string& path, long long max_bytes);

// Every model in file order. Each throws InputError naming file and line.
std::vector<RawModel> read_pdb_or_mmcif(const std::string& path, std::string text,
                                        MoleculeFormat format, std::vector<std::string>& warnings);
std::vector<RawModel> read_pqr(const std::string& path, const std::string& text);
std::vector<RawModel> read_xyzr(const std::string& path, const std::string& text);
std::vector<RawModel> read_wpts(const std::string& path, const std::string& text);

bool is_water_residue(const std::string& residue_name);

// Parses a whole field as a finite double; false on anything else (text, NaN, inf).
bool parse_finite_double(const std::string& field, double& value);

}  // namespace skinmesh::detail
