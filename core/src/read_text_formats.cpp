// PQR (whitespace-separated, as written by pdb2pqr and APBS), XYZR ("x y z r"
// per line, MSMS's input; anything after r is ignored) and weighted points
// ("x y z w" per line, exactly four numbers; '#' starts a comment).
#include "reader_detail.hpp"

#include "skinmesh/core/error.hpp"

#include <cctype>
#include <cmath>
#include <sstream>

namespace skinmesh::detail {
namespace {

std::vector<std::string> split_whitespace(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  std::string field;
  while (in >> field) fields.push_back(field);
  return fields;
}

template <class Visit>
void for_each_line(const std::string& text, Visit visit) {
  long number = 0;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    visit(++number, line);
    start = end + 1;
  }
}

// PQR has no element column: the element is read from the atom name the way
// PDB names are built (leading digits skipped; two-letter ions when the residue
// is named after them, e.g. "CL" in residue "CL").
std::string element_from_name(const std::string& name, const std::string& residue) {
  size_t i = 0;
  while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
  std::string letters;
  for (; i < name.size() && std::isalpha(static_cast<unsigned char>(name[i])) && letters.size() < 2; ++i)
    letters += static_cast<char>(std::toupper(static_cast<unsigned char>(name[i])));
  if (letters.empty()) return "X";
  if (letters.size() == 2 && name.size() <= 2 && residue == letters) return letters;
  return letters.substr(0, 1);
}

Eigen::Vector3d parse_xyz(const std::string& path, long line, const std::string& sx, const std::string& sy,
                          const std::string& sz) {
  Eigen::Vector3d p;
  const std::string* fields[3] = {&sx, &sy, &sz};
  static const char* const axes[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k)
    if (!parse_finite_double(*fields[k], p[k]))
      input_error(path, line, std::string("malformed or non-finite ") + axes[k] + " coordinate '" + *fields[k] + "'");
  return p;
}

double parse_radius(const std::string& path, long line, const std::string& field) {
  double r = 0;
  if (!parse_finite_double(field, r)) input_error(path, line, "malformed or non-finite radius '" + field + "'");
  if (r < 0) input_error(path, line, "negative radius " + field);
  return r;
}

}  // namespace

std::vector<RawModel> read_pqr(const std::string& path, const std::string& text) {
  RawModel model;
  for_each_line(text, [&](long number, const std::string& line) {
    if (line.compare(0, 4, "ATOM") != 0 && line.compare(0, 6, "HETATM") != 0) return;
    const auto f = split_whitespace(line);
    // ATOM serial name resName [chain] resSeq x y z charge radius
    if (f.size() < 10)
      input_error(path, number,
                  "PQR atom record needs at least 10 fields (ATOM serial name residue [chain] "
                  "resSeq x y z charge radius), found " + std::to_string(f.size()));
    const size_t n = f.size();
    RawAtom r;
    r.atom.position = parse_xyz(path, number, f[n - 5], f[n - 4], f[n - 3]);
    double charge = 0;
    if (!parse_finite_double(f[n - 2], charge)) input_error(path, number, "malformed charge '" + f[n - 2] + "'");
    r.atom.radius = parse_radius(path, number, f[n - 1]);
    r.radius_given = true;
    r.atom.name = f[2];
    r.atom.residue = f[3];
    if (n >= 11 && !std::isdigit(static_cast<unsigned char>(f[4][0])) && f[4][0] != '-') r.atom.chain = f[4];
    try {
      r.atom.residue_number = std::stoi(f[n - 6]);
    } catch (...) {
      r.atom.residue_number = 0;
    }
    r.atom.element = element_from_name(r.atom.name, r.atom.residue);
    r.atom.line = number;
    r.hydrogen = r.atom.element == "H" || r.atom.element == "D";
    r.water = is_water_residue(r.atom.residue);
    model.push_back(std::move(r));
  });
  if (model.empty()) input_error(path, 0, "no ATOM/HETATM records found (not a PQR file?)");
  return {model};
}

std::vector<RawModel> read_xyzr(const std::string& path, const std::string& text) {
  RawModel model;
  for_each_line(text, [&](long number, const std::string& line) {
    const auto f = split_whitespace(line);
    if (f.empty() || f[0][0] == '#') return;
    if (f.size() < 4)
      input_error(path, number, "XYZR line needs 4 numbers 'x y z r', found " + std::to_string(f.size()) + " fields");
    RawAtom r;
    r.atom.position = parse_xyz(path, number, f[0], f[1], f[2]);
    r.atom.radius = parse_radius(path, number, f[3]);
    r.radius_given = true;
    r.atom.line = number;
    // MSMS's xyzrn form carries the atom name in field 6 (after a flag).
    if (f.size() >= 6) r.atom.name = f[5];
    model.push_back(std::move(r));
  });
  if (model.empty()) input_error(path, 0, "no atoms found (expected lines 'x y z r')");
  return {model};
}

std::vector<RawModel> read_wpts(const std::string& path, const std::string& text) {
  RawModel model;
  for_each_line(text, [&](long number, const std::string& line) {
    auto f = split_whitespace(line.substr(0, line.find('#')));
    if (f.empty()) return;
    if (f.size() != 4)
      input_error(path, number,
                  "weighted point line needs exactly 4 numbers 'x y z w', found " + std::to_string(f.size()) +
                      " fields");
    RawAtom r;
    r.atom.position = parse_xyz(path, number, f[0], f[1], f[2]);
    double w = 0;
    if (!parse_finite_double(f[3], w)) input_error(path, number, "malformed or non-finite weight '" + f[3] + "'");
    r.atom.weight = w;
    r.atom.radius = w > 0 ? std::sqrt(w) : 0.0;  // for display only; the weight is what counts
    r.radius_given = true;
    r.atom.line = number;
    model.push_back(std::move(r));
  });
  if (model.empty()) input_error(path, 0, "no weighted points found (expected lines 'x y z w')");
  return {model};
}

}  // namespace skinmesh::detail
