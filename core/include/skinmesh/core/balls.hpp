// Weighted points (balls) and the weight convention that turns atoms into them.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace skinmesh {

struct Molecule;

// A weighted point b = (z, w): power distance pi_b(x) = |x - z|^2 - w (MATH.md 1).
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

std::vector<Ball> balls_from_molecule(const Molecule& molecule, double shrink,
                                      WeightConvention convention = WeightConvention::GrowBySkin);

}  // namespace skinmesh
