// Format dispatch and the filters every format shares.
#include "reader_detail.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/file_names.hpp"
#include "skinmesh/core/radii.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <tuple>
#include <unordered_map>

namespace skinmesh {

// Coordinates beyond this make 1e-9 A accuracy on the skin meaningless in
// double precision (and are never real structures).
constexpr double kMaxCoordinate = 1.0e5;  // Angstrom

const char* format_name(MoleculeFormat format) {
  switch (format) {
    case MoleculeFormat::Pdb: return "PDB";
    case MoleculeFormat::Mmcif: return "mmCIF";
    case MoleculeFormat::Pqr: return "PQR";
    case MoleculeFormat::Xyzr: return "XYZR";
    case MoleculeFormat::Wpts: return "weighted points";
  }
  return "?";
}

namespace {

std::string where(const std::string& path, const Atom& atom) {
  std::ostringstream out;
  out << path;
  if (atom.line > 0) out << ":" << atom.line;
  out << " (atom " << atom.name << " " << atom.residue << " " << atom.chain << atom.residue_number << ")";
  return out.str();
}

std::vector<detail::RawModel> read_raw_models(const std::string& path, MoleculeFormat format, long long max_bytes,
                                              std::vector<std::string>& warnings) {
  std::string text = detail::read_file_text(path, max_bytes);
  switch (format) {
    case MoleculeFormat::Pdb:
    case MoleculeFormat::Mmcif: return detail::read_pdb_or_mmcif(path, std::move(text), format, warnings);
    case MoleculeFormat::Pqr: return detail::read_pqr(path, text);
    case MoleculeFormat::Xyzr: return detail::read_xyzr(path, text);
    case MoleculeFormat::Wpts: return detail::read_wpts(path, text);
  }
  return {};
}

// One conformer per residue (chain, residue number, insertion code): the
// alternate-location label with the highest mean occupancy over the
// residue's atoms that carry it (ties to the label met first), plus the
// residue's unlabelled atoms of that label's residue name. Choosing per atom
// would join conformers into a chimera; where one position holds two
// residue types (microheterogeneity, e.g. Pro or Ser) only one type is kept,
// and a warning names the residue.
std::vector<detail::RawAtom> pick_conformers(std::vector<detail::RawAtom> atoms, const std::string& path,
                                             long& dropped, std::vector<std::string>& warnings) {
  using Residue = std::tuple<std::string, int, char>;
  struct Label {
    double occupancy = 0;
    long count = 0;
    size_t first = 0;
    std::set<std::string> names;  // residue names carrying this label
  };
  std::map<Residue, std::map<char, Label>> labels;
  std::map<Residue, std::set<std::string>> names;
  for (size_t i = 0; i < atoms.size(); ++i) {
    const Atom& a = atoms[i].atom;
    const Residue r{a.chain, a.residue_number, a.insertion_code};
    names[r].insert(a.residue);
    if (a.altloc == ' ') continue;
    auto [it, fresh] = labels[r].try_emplace(a.altloc);
    if (fresh) it->second.first = i;
    it->second.occupancy += a.occupancy;
    ++it->second.count;
    it->second.names.insert(a.residue);
  }
  std::map<Residue, std::pair<char, std::set<std::string>>> chosen;  // label and its residue names
  for (const auto& [r, by_label] : labels) {
    const std::pair<const char, Label>* best = nullptr;
    for (const auto& entry : by_label) {
      const double mean = entry.second.occupancy / static_cast<double>(entry.second.count);
      if (!best) { best = &entry; continue; }
      const double best_mean = best->second.occupancy / static_cast<double>(best->second.count);
      if (mean > best_mean || (mean == best_mean && entry.second.first < best->second.first)) best = &entry;
    }
    chosen[r] = {best->first, best->second.names};
    if (names[r].size() > 1) {
      std::string kinds;
      for (const std::string& n : names[r]) kinds += (kinds.empty() ? "" : " or ") + n;
      warnings.push_back(path + ": chain " + std::get<0>(r) + " residue " + std::to_string(std::get<1>(r)) +
                         " is microheterogeneous (" + kinds + "); kept " + *best->second.names.begin() +
                         " (alternate location " + std::string(1, best->first) + ")");
    }
  }
  std::vector<detail::RawAtom> kept;
  kept.reserve(atoms.size());
  for (detail::RawAtom& raw : atoms) {
    const Atom& a = raw.atom;
    const auto it = chosen.find(Residue{a.chain, a.residue_number, a.insertion_code});
    const bool keep = it == chosen.end() ||
                      (a.altloc == ' ' ? it->second.second.count(a.residue) > 0 : a.altloc == it->second.first);
    if (!keep) {
      ++dropped;
      continue;
    }
    kept.push_back(std::move(raw));
  }
  return kept;
}

// The atoms of the selected chains, less waters and hydrogens unless kept,
// one conformer each; what was dropped is counted in m.skipped.
std::vector<detail::RawAtom> select_atoms(detail::RawModel raw, const ReadOptions& options, Molecule& m) {
  std::vector<detail::RawAtom> atoms;
  atoms.reserve(raw.size());
  for (detail::RawAtom& r : raw) {
    if (!options.chains.empty() &&
        std::find(options.chains.begin(), options.chains.end(), r.atom.chain) == options.chains.end()) {
      ++m.skipped["chain not selected"];
      continue;
    }
    if (r.water && !options.keep_waters) {
      ++m.skipped["water"];
      continue;
    }
    if (r.hydrogen && !options.keep_hydrogens) {
      ++m.skipped["hydrogen"];
      continue;
    }
    atoms.push_back(std::move(r));
  }
  long altloc_dropped = 0;
  atoms = pick_conformers(std::move(atoms), m.source, altloc_dropped, m.warnings);
  if (altloc_dropped) m.skipped["alternate location"] += altloc_dropped;
  return atoms;
}

// Checks each atom's coordinates and gives it its radius (Bondi's by element
// unless the file gave one); atoms of zero given radius are dropped.
void add_atoms_with_radii(const std::string& path, std::vector<detail::RawAtom> atoms, const ReadOptions& options,
                          Molecule& m) {
  for (detail::RawAtom& r : atoms) {
    Atom& a = r.atom;
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(a.position[k])) input_error(path, a.line, "non-finite coordinate in " + where(path, a));
      if (std::abs(a.position[k]) > kMaxCoordinate) {
        std::ostringstream msg;
        msg << "coordinate " << a.position[k] << " is beyond +-" << kMaxCoordinate
            << " Angstrom: not a molecular structure";
        input_error(path, a.line, msg.str());
      }
    }
    // Past these, squares and powers overflow or lose every digit of the
    // coordinates (a radius of 1e200 squares to infinity).
    if (r.radius_given && !(a.radius <= kMaxCoordinate)) {
      std::ostringstream msg;
      msg << "radius " << a.radius << " is beyond " << kMaxCoordinate << " Angstrom: not an atom";
      input_error(path, a.line, msg.str());
    }
    if (a.weight && !(std::abs(*a.weight) <= kMaxCoordinate * kMaxCoordinate)) {
      std::ostringstream msg;
      msg << "weight " << *a.weight << " is beyond +-" << kMaxCoordinate * kMaxCoordinate << " Angstrom^2";
      input_error(path, a.line, msg.str());
    }
    if (!r.radius_given) {
      if (auto radius = bondi_radius(a.element)) {
        a.radius = *radius;
      } else {
        if (options.strict_elements)
          input_error(path, a.line, "unknown element '" + a.element + "' (no Bondi radius) for " + where(path, a));
        a.radius = options.unknown_radius;
        ++m.unknown_elements[a.element.empty() ? "?" : a.element];
      }
    } else if (a.radius == 0.0 && !a.weight) {
      ++m.skipped["zero radius"];
      continue;
    }
    m.atoms.push_back(std::move(a));
  }
  for (const auto& [element, count] : m.unknown_elements) {
    std::ostringstream msg;
    msg << path << ": " << count << " atom(s) of element '" << element << "' have no Bondi radius; used "
        << options.unknown_radius << " A";
    m.warnings.push_back(msg.str());
  }
}

void require_atoms(const std::string& path, const Molecule& m) {
  if (!m.atoms.empty()) return;
  std::ostringstream msg;
  msg << "no atoms left after filtering";
  if (!m.skipped.empty()) {
    msg << " (dropped:";
    for (const auto& [reason, count] : m.skipped) msg << " " << count << " " << reason;
    msg << "; keep hydrogens or waters, or select other chains, to keep more)";
  }
  input_error(path, 0, msg.str());
}

// Atoms at one position: geometrically the smaller ball is hidden (a
// duplicate is hidden by its twin), so this is a warning, not an error.
void warn_coincident_atoms(const std::string& path, Molecule& m) {
  struct Hash {
    size_t operator()(const Eigen::Vector3d& p) const {
      std::hash<double> h;
      return h(p[0]) ^ (h(p[1]) * 31) ^ (h(p[2]) * 131);
    }
  };
  struct Equal {
    bool operator()(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const { return a == b; }
  };
  std::unordered_map<Eigen::Vector3d, size_t, Hash, Equal> seen;
  long coincident = 0;
  std::string first_pair;
  for (size_t i = 0; i < m.atoms.size(); ++i) {
    auto [it, inserted] = seen.emplace(m.atoms[i].position, i);
    if (!inserted && coincident++ == 0)
      first_pair = where(path, m.atoms[it->second]) + " and " + where(path, m.atoms[i]);
  }
  if (coincident)
    m.warnings.push_back(path + ": " + std::to_string(coincident) +
                         " atom(s) share a position with another atom, first " + first_pair +
                         "; the smaller ball of each group is hidden");
}

Molecule filter_model(const std::string& path, MoleculeFormat format, detail::RawModel raw, int model_number,
                      int models_in_file, const ReadOptions& options, const std::vector<std::string>& warnings) {
  Molecule m;
  m.source = path;
  m.format = format;
  m.model = model_number;
  m.models_in_file = models_in_file;
  m.warnings = warnings;
  add_atoms_with_radii(path, select_atoms(std::move(raw), options, m), options, m);
  require_atoms(path, m);
  warn_coincident_atoms(path, m);
  return m;
}

}  // namespace

MoleculeFormat format_from_path(const std::string& path) {
  std::string name = lowercase(path);
  if (has_extension(name, ".gz")) name.resize(name.size() - 3);
  if (has_extension(name, ".cif") || has_extension(name, ".mmcif")) return MoleculeFormat::Mmcif;
  if (has_extension(name, ".pqr")) return MoleculeFormat::Pqr;
  if (has_extension(name, ".xyzr") || has_extension(name, ".xyzrn")) return MoleculeFormat::Xyzr;
  if (has_extension(name, ".wpts")) return MoleculeFormat::Wpts;
  return MoleculeFormat::Pdb;  // .pdb, .ent and anything else: PDB, which gemmi reads leniently
}

Molecule read_molecule(const std::string& path, const ReadOptions& options) {
  const MoleculeFormat format = format_from_path(path);
  std::vector<std::string> warnings;
  std::vector<detail::RawModel> models = read_raw_models(path, format, options.max_bytes, warnings);
  const int count = static_cast<int>(models.size());
  if (options.model < 1 || options.model > count)
    input_error(path, 0,
                "model " + std::to_string(options.model) + " requested, but the file has " + std::to_string(count) +
                    " model(s)");
  return filter_model(path, format, std::move(models[options.model - 1]), options.model, count, options, warnings);
}

std::vector<Molecule> read_all_models(const std::string& path, const ReadOptions& options) {
  const MoleculeFormat format = format_from_path(path);
  std::vector<std::string> warnings;
  std::vector<detail::RawModel> models = read_raw_models(path, format, options.max_bytes, warnings);
  std::vector<Molecule> out;
  const int count = static_cast<int>(models.size());
  for (int i = 0; i < count; ++i)
    out.push_back(filter_model(path, format, std::move(models[i]), i + 1, count, options, warnings));
  return out;
}

}  // namespace skinmesh
