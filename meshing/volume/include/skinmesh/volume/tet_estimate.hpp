// How many tetrahedra (and how much memory) TetGen will make of a domain,
// known before it runs, so that a job past --max-tetrahedra or --max-memory
// is refused at once with the numbers and what would fit, instead of running
// TetGen for minutes into its run-time bounds.
//
// Without a volume bound TetGen grades its tetrahedra from the boundary's
// triangles, so their number follows the boundary: the skin's triangles and
// the outer box's (a grid of about 3 A, so their number grows with the square
// of the margin), scaled by how tight the quality bounds are; a volume bound
// adds about one tetrahedron per max_volume of the domain. The constants
// were measured on pept, 1ubi and 3al1 (docs/volume-meshes.md, "Knowing the
// size before running").
#pragma once

#include "skinmesh/volume/volume_mesh.hpp"

#include <Eigen/Core>

#include <string>

namespace skinmesh {

// Measured counts lay within this factor of the estimate (above it, not
// below, at the tightest bounds: the quality factor is taken from the
// measured grid on the side of looser bounds).
inline constexpr double kTetEstimateSpread = 1.25;

// What TetGen is given, besides the options: the skin's triangles, the
// extent of their bounding box (Angstrom) and the volume they enclose.
struct TetDomain {
  double skin_triangles = 0;
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
  double enclosed = 0;  // Angstrom^3
};

// The domain of a closed surface enclosing `enclosed` Angstrom^3.
TetDomain tet_domain(const SurfaceMesh& surface, double enclosed);

struct TetEstimate {
  double tetrahedra = 0;      // expected count
  double box_triangles = 0;   // of the outer box, 0 for the interior alone
  double volume = 0;          // Angstrom^3 of the domain to fill
  double peak_bytes = 0;      // expected peak memory of the run
  // The low end, what a refusal is judged by: never below the volume to
  // fill over max_volume, which is a hard lower bound.
  double low = 0;
  double low_bytes = 0;
};

TetEstimate estimate_tetrahedra(const TetDomain& domain, const VolumeOptions& options);

// Triangles of the outer box around an extent (Angstrom) grown by `margin`
// on every side, as add_box makes it (no overflow for any margin).
double box_triangles(const Eigen::Vector3d& extent, double margin);

// When the estimate's low end passes options.max_tetrahedra or
// options.max_memory_bytes (when set): the message, with the estimate and
// the options that would fit; empty when it fits.
std::string tet_budget_refusal(const TetDomain& domain, const VolumeOptions& options);

}  // namespace skinmesh
