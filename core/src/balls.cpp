#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/error.hpp"
#include "skinmesh/core/number_text.hpp"

#include "skinmesh/core/molecule.hpp"

#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace skinmesh {

const char* convention_name(WeightConvention convention) {
  return convention == WeightConvention::GrowBySkin ? "r^2/s" : "r^2";
}

std::vector<Ball> balls_from_molecule(const Molecule& molecule, double shrink,
                                      WeightConvention convention) {
  if (!(shrink > 0.0 && shrink < 1.0))
    contract_error("shrink factor must lie in (0,1), got " + std::to_string(shrink));
  std::vector<Ball> balls;
  balls.reserve(molecule.atoms.size());
  for (const Atom& atom : molecule.atoms) {
    const double r2 = atom.radius * atom.radius;
    if (atom.weight) balls.push_back({atom.position, *atom.weight});
    else balls.push_back({atom.position, convention == WeightConvention::GrowBySkin ? r2 / shrink : r2});
  }
  return balls;
}

namespace {

void write_comment(std::ostream& out, const std::string& comment) {
  std::istringstream lines(comment);
  std::string line;
  while (std::getline(lines, line)) out << "# " << line << '\n';
}

}  // namespace

void write_wpts(std::ostream& out, const std::vector<Ball>& balls, const std::string& comment) {
  out << "# skinmesh weighted points: x y z w (Angstrom, Angstrom^2); power distance |x - z|^2 - w\n";
  write_comment(out, comment);
  for (const Ball& b : balls)
    out << exact_number_text(b.center[0]) << ' ' << exact_number_text(b.center[1]) << ' '
        << exact_number_text(b.center[2]) << ' ' << exact_number_text(b.weight) << '\n';
}

void write_xyzr(std::ostream& out, const Molecule& molecule, const std::string& comment) {
  out << "# skinmesh atoms: x y z r (Angstrom)\n";
  write_comment(out, comment);
  for (const Atom& a : molecule.atoms)
    out << exact_number_text(a.position[0]) << ' ' << exact_number_text(a.position[1]) << ' '
        << exact_number_text(a.position[2]) << ' ' << exact_number_text(a.radius) << '\n';
}

}  // namespace skinmesh
