// Tetrahedral meshes bounded by a skin mesh, made by TetGen's library
// (Debian's `libtet1.5-dev`, called in memory): the molecule's interior, the solvent between the skin
// and a box around it, or both, with region and boundary markers
// (core/tet_mesh.hpp). The skin's triangles stay as they are (no Steiner
// points on the surface), so the tet mesh's boundary is the surface mesh
// itself; the few tetrahedra TetGen then leaves outside the quality bounds
// are mended by improve_tet_mesh (tet_improvement.hpp).
#pragma once

#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/core/tet_mesh.hpp"
#include "skinmesh/volume/tet_improvement.hpp"

#include <string>

namespace skinmesh {

enum class VolumeDomain { interior, exterior, both };
enum class Cavities { keep, fill };  // keep: mesh enclosed voids as region kRegionCavity; fill: leave them empty

struct VolumeOptions {
  VolumeDomain domain = VolumeDomain::interior;
  double box_margin = 10.0;        // Angstrom between the skin's bounding box and the outer box
  TetBounds bounds;                // radius-edge (TetGen -q) and dihedral (degrees) bounds
  double max_volume = 0.0;         // Angstrom^3: largest tetrahedron, 0 for no bound (TetGen -a)
  Cavities cavities = Cavities::keep;
  // Refused up front (status over_budget) when the estimate of TetGen's
  // tetrahedra (tet_estimate.hpp) passes this even at its low end. About
  // 10^7 tetrahedra take TetGen 2 GB.
  long max_tetrahedra = 10'000'000;
  // TetGen's run, bounded: the memory it may take (bytes; a run whose
  // estimate passes it is refused up front too) and its time (seconds);
  // past either it stops with status tetgen_failed and a message naming the
  // bound. 0: none.
  double max_memory_bytes = 0;
  double max_seconds = 0;
};

// Angstrom between the grid lines of the outer box's sides: TetGen may not
// split boundary facets (-Y), so two huge triangles a side would leave
// slivers against them.
inline constexpr double kBoxSpacing = 3.0;

// The bounds TetGen itself is asked for (tighter than the options' own,
// volume_mesh.cpp says why).
double tetgen_ratio(const TetBounds& bounds);
double tetgen_dihedral(const TetBounds& bounds);

enum class VolumeStatus {
  ok,
  surface_not_closed,  // the surface is not a closed, consistently oriented manifold: it bounds no volume
  tetgen_failed,       // TetGen stopped with an error (out of memory, self-intersecting input, ...)
  over_budget,         // the estimate passes max_tetrahedra or max_memory_bytes (nothing run)
};
const char* volume_status_name(VolumeStatus status);

struct VolumeMeshResult {
  VolumeStatus status = VolumeStatus::ok;
  std::string message;             // what went wrong, when status != ok
  TetMesh mesh;                    // empty unless status == ok
  TetImprovement improvement;      // what improve_tet_mesh did to TetGen's output
  double estimated_tetrahedra = 0; // tet_estimate.hpp's expected count, before TetGen ran
  double estimated_low = 0;        // and its low end, what a refusal is judged by
};

// The surface must be closed, manifold and outward oriented (as skinmesh
// writes it); components with negative enclosed volume are cavities. Throws
// ContractError for options out of range.
VolumeMeshResult tetrahedralize(const SurfaceMesh& surface, const VolumeOptions& options = {});

// A second opinion on self-intersections, independent of CGAL: TetGen's -d
// check of the surface. The number of triangles that meet another one (0
// when none do), or -1 when TetGen stopped with an error.
long tetgen_self_intersections(const SurfaceMesh& surface);

}  // namespace skinmesh
