#include "skinmesh/morph/alignment.hpp"

#include "skinmesh/core/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

namespace skinmesh {
namespace {

// chain, residue number, insertion code, residue name, atom name: without the
// residue name the backbone atoms of any two proteins numbered alike match.
using AtomKey = std::tuple<std::string, int, char, std::string, std::string>;

AtomKey key_of(const Atom& a) { return {a.chain, a.residue_number, a.insertion_code, a.residue, a.name}; }

// `automatic` takes two sides for one molecule (two conformations) when this
// share of the smaller side's atoms match; otherwise the match is chance.
constexpr double kSameMolecule = 0.9;

}  // namespace

std::vector<std::pair<size_t, size_t>> matched_atoms(const Molecule& source, const Molecule& target) {
  std::map<AtomKey, std::pair<int, size_t>> in_source;  // times seen, index
  for (size_t k = 0; k < source.atoms.size(); ++k) {
    auto [it, fresh] = in_source.try_emplace(key_of(source.atoms[k]), 1, k);
    if (!fresh) ++it->second.first;
  }
  std::map<AtomKey, int> seen_in_target;
  for (const Atom& b : target.atoms) ++seen_in_target[key_of(b)];
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t k = 0; k < target.atoms.size(); ++k) {
    const AtomKey key = key_of(target.atoms[k]);
    const auto it = in_source.find(key);
    if (it != in_source.end() && it->second.first == 1 && seen_in_target[key] == 1)
      pairs.emplace_back(it->second.second, k);
  }
  return pairs;
}

namespace {

std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> matched_positions(const Molecule& source,
                                                                           const Molecule& target) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> out;
  for (const auto& [i, j] : matched_atoms(source, target))
    out.emplace_back(source.atoms[i].position, target.atoms[j].position);
  return out;
}

Eigen::Vector3d centroid(const std::vector<Atom>& atoms) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Atom& a : atoms) c += a.position;
  return atoms.empty() ? c : Eigen::Vector3d(c / static_cast<double>(atoms.size()));
}

// Kabsch: the rotation R minimising sum |R b + t - a|^2 is V diag(1,1,d) U^T
// from the SVD of the covariance H = sum (b - b0)(a - a0)^T = U S V^T, with
// d = sign(det(V U^T)) so that R is a rotation, not a reflection.
Alignment kabsch(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& pairs) {
  Eigen::Vector3d a0 = Eigen::Vector3d::Zero(), b0 = Eigen::Vector3d::Zero();
  for (const auto& [a, b] : pairs) a0 += a, b0 += b;
  a0 /= static_cast<double>(pairs.size());
  b0 /= static_cast<double>(pairs.size());
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (const auto& [a, b] : pairs) H += (b - b0) * (a - a0).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  Alignment out;
  out.used = AlignmentMethod::kabsch;
  out.motion.rotation = svd.matrixV() * D * svd.matrixU().transpose();
  out.motion.translation = a0 - out.motion.rotation * b0;
  out.matched = static_cast<long>(pairs.size());
  double sum = 0;
  for (const auto& [a, b] : pairs) sum += (out.motion.apply(b) - a).squaredNorm();
  out.rmsd = std::sqrt(sum / static_cast<double>(pairs.size()));
  return out;
}

}  // namespace

const char* alignment_method_name(AlignmentMethod method) {
  static const char* const names[] = {"automatic", "none", "centroid", "kabsch"};  // in the enum's order
  return names[static_cast<int>(method)];
}

Alignment align(const Molecule& source, const Molecule& target, AlignmentMethod method) {
  Alignment out;
  if (method == AlignmentMethod::none) return out;
  if (method == AlignmentMethod::kabsch || method == AlignmentMethod::automatic) {
    const auto pairs = matched_positions(source, target);
    if (pairs.size() >= 3 && (method == AlignmentMethod::kabsch || same_molecule(source, target))) return kabsch(pairs);
    if (method == AlignmentMethod::kabsch)
      contract_error("Kabsch alignment needs at least three atoms matched by chain, residue and name; " +
                     std::to_string(pairs.size()) + " match");
  }
  out.used = AlignmentMethod::centroid;
  out.motion.translation = centroid(source.atoms) - centroid(target.atoms);
  return out;
}

bool same_molecule(const Molecule& source, const Molecule& target) {
  const double smaller = static_cast<double>(std::min(source.atoms.size(), target.atoms.size()));
  return static_cast<double>(matched_atoms(source, target).size()) >= kSameMolecule * smaller;
}

Molecule moved(Molecule molecule, const RigidMotion& motion) {
  for (Atom& a : molecule.atoms) a.position = motion.apply(a.position);
  return molecule;
}

long snap_unmoved(const Molecule& source, Molecule& target, double within) {
  long snapped = 0;
  for (const auto& [i, j] : matched_atoms(source, target)) {
    const Eigen::Vector3d& a = source.atoms[i].position;
    Eigen::Vector3d& b = target.atoms[j].position;
    if ((b - a).norm() <= within) {
      b = a;
      ++snapped;
    }
  }
  return snapped;
}

}  // namespace skinmesh
