#include "skinmesh/core/balls.hpp"

#include "skinmesh/core/molecule.hpp"

#include <stdexcept>

namespace skinmesh {

const char* convention_name(WeightConvention convention) {
  return convention == WeightConvention::GrowBySkin ? "r^2/s" : "r^2";
}

std::vector<Ball> balls_from_molecule(const Molecule& molecule, double shrink,
                                      WeightConvention convention) {
  if (!(shrink > 0.0 && shrink < 1.0))
    throw std::invalid_argument("shrink factor must lie in (0,1), got " + std::to_string(shrink));
  std::vector<Ball> balls;
  balls.reserve(molecule.atoms.size());
  for (const Atom& atom : molecule.atoms) {
    const double r2 = atom.radius * atom.radius;
    balls.push_back({atom.position, convention == WeightConvention::GrowBySkin ? r2 / shrink : r2});
  }
  return balls;
}

}  // namespace skinmesh
