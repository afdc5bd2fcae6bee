// The area of the skin itself, beside the area of the triangles that sample
// it: a boundary-element user's discretisation error of the surface.
#pragma once

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"

namespace skinmesh {

struct SkinArea {
  double area = 0;         // Angstrom^2: the curved surface the mesh's triangles span on the skin
  double uncertainty = 0;  // Angstrom^2: bound on |area - true area| from the extrapolation's last two levels
  long projections = 0;    // points put on the skin
  bool converged = false;  // every projection converged
};

// Every triangle of `mesh` (vertices on the skin of `complex`) is split
// into 4 and 16 sub-triangles whose new corners are projected onto the
// skin; the flat areas A0 (the mesh), A1, A2 converge as h^2 to the area of
// the skin patch the triangle spans, so Richardson's extrapolation
// (4 A_{k+1} - A_k) / 3 at levels 0-1 and 1-2 gives the area and, from
// their difference, its uncertainty.
SkinArea skin_area(const SkinComplex& complex, const SurfaceMesh& mesh);

}  // namespace skinmesh
