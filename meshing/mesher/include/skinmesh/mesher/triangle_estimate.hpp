// How many triangles (and how much memory) mesh_skin will need, known from the
// mixed complex before any refinement, so that a job too big for its budget is
// refused within seconds with a number and the sizes that would fit.
//
// The skin's area is integrated per mixed cell over the Gauss map: on the
// quadric of a cell each outward normal d is taken at exactly one point,
// x = z + alpha M^-1 d (M the quadric's matrix), and the area element is
// d(solid angle) / |K| with K the Gaussian curvature there. Directions whose
// point lies outside the cell are dropped. The refiner's size bounds depend on
// the skin only through the largest principal curvature (target_edge_length,
// and the distance tolerance through the sagitta of a triangle on a sphere of
// that curvature), so the area is kept in bins of the radius of curvature and
// one profile answers for any meshing options.
#pragma once

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"

#include <vector>

namespace skinmesh {

struct SkinAreaOptions {
  // Directions sampled per mixed cell (a Fibonacci sphere turned at random
  // per cell, so that the estimate is unbiased over many cells).
  int directions_per_cell = 96;
  // At least this many in all: a small complex (a few balls) has few cells
  // to average over, so each gets more directions; costs little.
  long directions_in_all = 200'000;
};

struct SkinAreaBin {
  double area = 0;        // Angstrom^2 of skin whose radius of curvature falls in the bin
  double area_rho = 0;    // sum of area * radius of curvature (area-weighted mean = area_rho / area)
};

struct SkinAreaProfile {
  double area = 0;                      // Angstrom^2, the whole skin
  // Radius of curvature 1/max|k| in log bins (kBinsPerDecade from 1e-6 A);
  // sphere patches (vertex and tetrahedron cells) apart from hyperboloid
  // patches, for the mesher floors the size on hyperboloids only.
  std::vector<SkinAreaBin> sphere, hyperboloid;
  long cells_with_skin = 0;             // mixed cells in which some sampled direction hit the skin
  static constexpr int kBinsPerDecade = 20;
  static constexpr double kSmallestRadius = 1e-6;
};

SkinAreaProfile skin_area_profile(const SkinComplex& complex, const SkinAreaOptions& options = {});

// Measured triangle counts lie within this factor of the estimate either way
// at the default shrink factor (docs/benchmarks.md, "Knowing the size before
// meshing"); at larger shrink factors the estimate can fall short, never over.
inline constexpr double kTriangleEstimateSpread = 1.25;
// Where the skin's creases make most of the estimate (a shrink factor near
// 1), measured counts spread wider around it (docs/benchmarks.md).
inline constexpr double kCreaseEstimateSpread = 1.4;

struct TriangleEstimate {
  double triangles = 0;      // expected triangle count of mesh_skin at these options
  double size_bound = 0;     // of which where the size bound binds (epsilon, edge length, min and max size)
  double distance_bound = 0; // of which where the distance tolerance binds
  double per_cell = 0;       // of which the few every small patch takes whatever its size
  double creases = 0;        // of which along necks bending at radii under 0.01 A (a shrink factor near 1),
                             // whatever the size options
  double peak_bytes = 0;     // expected peak memory of mesh_skin (the complex excluded)
  // The low end, what a refusal is judged by: the area terms alone (the per
  // cell term overcounts meshes coarser than the default, whose triangles
  // span several cells) less their spread, the crease term less its own.
  double low() const {
    return (size_bound + distance_bound) / kTriangleEstimateSpread + creases / kCreaseEstimateSpread;
  }
  double low_peak_bytes() const { return triangles > 0 ? peak_bytes * low() / triangles : 0; }
};

// The expected output of mesh_skin(complex, options) for the complex whose
// profile is given, calibrated on the molecules in data/.
TriangleEstimate estimate_triangles(const SkinAreaProfile& profile, const MeshingOptions& options);
// The triangle count `options` can afford: max_triangles, or fewer when
// max_memory_bytes is set and the memory estimate per triangle says so.
double affordable_triangles(const MeshingOptions& options);

// For each size option in turn, the nearest value (coarser than today's) at
// which the whole estimate times kTriangleEstimateSpread is at most
// `triangles` (so it fits even if the estimate is short);
// options that cannot reach it alone (or, for the edge length, are not set)
// are left out. When none can, every size scaled by one factor f (the
// tolerance by f^2, as the sagitta of a triangle grows with its size
// squared), if some f fits.
std::vector<FittingSize> sizes_that_fit(const SkinAreaProfile& profile, const MeshingOptions& options,
                                        double triangles);

// When the creases of a skin with shrink factor `shrink` leave no room in
// `triangles` (with kCreaseEstimateSpread to spare), the largest shrink factor,
// rounded down to two significant digits of 1 - s, whose creases would; 0
// when there are no creases or the other terms alone do not fit.
double shrink_that_fits(const TriangleEstimate& estimate, double shrink, double triangles);

}  // namespace skinmesh
