// Weighted points (balls) and the weight convention that turns atoms into them.
#pragma once

#include <Eigen/Core>

#include <ostream>
#include <string>
#include <vector>

namespace skinmesh {

struct Molecule;

// A weighted point b = (z, w): power distance pi_b(x) = |x - z|^2 - w (docs/math.md 1).
struct Ball {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // Angstrom
  double weight = 0.0;                               // Angstrom^2 (may be negative in a morph)
  double power(const Eigen::Vector3d& x) const { return (x - center).squaredNorm() - weight; }
};

// How an atom of radius r becomes a ball for shrink factor s.
//  GrowBySkin: w = r^2 / s. The skin of a lone atom is then the van der Waals sphere
//              and the skin hugs the vdW surface (CGAL Skin_surface_3's grow_balls).
//  Raw:        w = r^2. The skin of a lone atom has radius r*sqrt(s).
enum class WeightConvention { GrowBySkin, Raw };
const char* convention_name(WeightConvention convention);

// Atoms with a weight of their own (read from .wpts) keep it, whatever the
// convention.
std::vector<Ball> balls_from_molecule(const Molecule& molecule, double shrink,
                                      WeightConvention convention = WeightConvention::GrowBySkin);

// The weighted-point format (.wpts): one ball per line, "x y z w" with the
// weight w in Angstrom^2 (negative allowed), '#' comments; written with 17
// significant digits so that reading it back gives the same doubles.
void write_wpts(std::ostream& out, const std::vector<Ball>& balls, const std::string& comment = "");
// The atoms as XYZR at full precision (%.17g): reading the file back gives
// the same balls bit for bit.
void write_xyzr(std::ostream& out, const Molecule& molecule, const std::string& comment = "");

}  // namespace skinmesh
