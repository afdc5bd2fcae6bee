// Molecules as lists of atoms, read from PDB, mmCIF (plain or gzipped, through
// gemmi), PQR and XYZR files, with the filters a structural biologist expects;
// and weighted point sets (.wpts: "x y z w" per line), which carry the balls'
// weights themselves, negative ones included (an interpolated set of a morph).
#pragma once

#include <Eigen/Core>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace skinmesh {

struct Atom {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // Angstrom
  double radius = 0.0;          // Angstrom (van der Waals, or as given by PQR/XYZR)
  std::string element;          // upper-case symbol ("C", "FE"); empty when the format has none
  std::string name;             // atom name ("CA")
  std::string residue;          // residue name ("ALA")
  std::string chain;            // chain id (author's)
  int residue_number = 0;
  char insertion_code = ' ';
  char altloc = ' ';            // ' ' when the atom has a single conformer
  double occupancy = 1.0;
  long line = 0;                // 1-based line in the source file; 0 when unknown (mmCIF)
  // The ball's weight as given by a .wpts file (Angstrom^2, any sign):
  // balls_from_molecule takes it as is, with no radius convention.
  std::optional<double> weight;
};

// Input formats, chosen from the file name (a trailing .gz is looked through).
enum class MoleculeFormat { Pdb, Mmcif, Pqr, Xyzr, Wpts };
const char* format_name(MoleculeFormat format);

struct ReadOptions {
  bool keep_hydrogens = false;       // hydrogens (and deuterium) are dropped by default
  bool keep_waters = false;          // HOH, WAT, DOD, ... are dropped by default
  int model = 1;                     // 1-based position of the model in the file
  std::vector<std::string> chains;   // chains to keep; empty keeps every chain
  double unknown_radius = 1.80;      // Angstrom, for elements missing from the Bondi table
  bool strict_elements = false;      // true: an unknown element is an error, not a warning
  // Bytes of text a molecule file may hold, after gunzipping: a larger file
  // (or a small gzip that inflates past it) is refused before it fills the
  // memory. 1 GiB holds a PDB file of about 12 million atoms.
  long long max_bytes = 1LL << 30;
};

// What a reader kept, dropped (and why), and had to guess.
struct Molecule {
  std::string source;                       // file path as given
  MoleculeFormat format = MoleculeFormat::Pdb;
  int model = 1;                            // 1-based model read
  int models_in_file = 1;
  std::vector<Atom> atoms;
  std::map<std::string, long> skipped;      // reason -> number of atoms dropped
  std::map<std::string, long> unknown_elements;  // element -> atoms given unknown_radius
  std::vector<std::string> warnings;        // human-readable, each names the file
};

// Reads one model. Throws InputError (file and line) on anything it cannot read
// or when no atom is left after filtering.
Molecule read_molecule(const std::string& path, const ReadOptions& options = {});

// Every model of the file, in order, each filtered like read_molecule (options.model
// is ignored). Text formats (PQR, XYZR) hold one model.
std::vector<Molecule> read_all_models(const std::string& path, const ReadOptions& options = {});

MoleculeFormat format_from_path(const std::string& path);

}  // namespace skinmesh
