// Putting the target molecule in the source's frame before a morph: two
// molecules in their own coordinate frames give an almost empty skin in the
// middle (weights fall by t(1-t)|z_i - z_j|^2, docs/math.md section 1).
#pragma once

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/molecule.hpp"

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace skinmesh {

enum class AlignmentMethod {
  automatic,  // Kabsch when 90% of the smaller side's atoms match (one molecule, two conformations), else centroid
  none,       // as read
  centroid,   // the target's centroid onto the source's
  kabsch,     // the rigid motion of least RMSD over matched atoms (Kabsch 1976, with the reflection excluded)
};
const char* alignment_method_name(AlignmentMethod method);

struct RigidMotion {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // Angstrom
  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return rotation * x + translation; }
};

struct Alignment {
  AlignmentMethod used = AlignmentMethod::none;  // never automatic
  RigidMotion motion;  // maps the target's coordinates into the source's frame
  long matched = 0;    // atoms matched by chain, residue number, insertion code, residue and atom name (Kabsch)
  double rmsd = 0.0;   // Angstrom over the matched atoms after the motion (Kabsch)
};

// Pairs (source index, target index) of the atoms both sides have, matched
// by chain, residue number, insertion code, residue and atom name, in the
// target's order; a key seen twice on a side is ambiguous and left out.
std::vector<std::pair<size_t, size_t>> matched_atoms(const Molecule& source, const Molecule& target);

// Whether the two sides are one molecule (two conformations): at least 90%
// of the smaller side's atoms match. The rule AlignmentMethod::automatic
// and the morph's default pairing use.
bool same_molecule(const Molecule& source, const Molecule& target);

// Throws ContractError for kabsch when fewer than three atoms match.
Alignment align(const Molecule& source, const Molecule& target, AlignmentMethod method);

// The target with the motion applied to every atom.
Molecule moved(Molecule molecule, const RigidMotion& motion);

// Puts every target atom that lies within `within` (Angstrom) of its matched
// source atom (chain, residue number, insertion code, residue and atom name)
// exactly on it; returns how many. A fit of two identical conformations
// leaves them about 1e-14 A apart, and balls that near make B(t) nearly
// degenerate: the pairs of two unmoved atoms are left out of a morph only
// when the atoms are the same bit for bit (interpolation.hpp, kUnmovedWithin).
long snap_unmoved(const Molecule& source, Molecule& target, double within = kUnmovedWithin);

}  // namespace skinmesh
