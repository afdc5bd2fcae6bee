// Tangential relaxation of a transported frame.
//
// Transport (eq. 19) is a similarity per mixed cell: a triangle whose
// corners lie in one cell keeps its angles and its size against the local
// curvature, but neighbouring cells scale by different factors, so the
// triangles across cell faces are sheared every step. Moving every vertex
// part of the way to the centroid of its neighbours, along the skin's
// tangent plane, and projecting it back onto the skin undoes much of that
// shear (Laplacian smoothing on the surface, as in Botsch et al., "Polygon
// Mesh Processing", 2010, section 6.4, with the exact skin as the surface).
#pragma once

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"

#include <vector>

namespace skinmesh {

struct RelaxationOptions {
  int passes = 3;         // Jacobi passes over every vertex
  double weight = 0.5;    // share of the tangential way to the neighbours' centroid (dimensionless, (0,1])
  // A vertex whose tangential way to the centroid is shorter than this
  // times its mean distance to its neighbours stays where it is (no
  // projection: most of a pass's cost). Dimensionless; default 0.06; 0:
  // every vertex moves. Leaving settled vertices alone makes frames faster.
  double settled_below = 0.06;
};

// Every vertex of `mesh` (on the skin of `complex`, its cells and unit
// normals those of that skin; normals computed when absent) moved as
// above and projected onto the skin (1e-14 A), unless it is settled
// (RelaxationOptions::settled_below); its cell and normal follow.
// A vertex whose projection does not converge, or lands farther than the
// way to the centroid, stays. Deterministic for any number of threads.
// With `movable` (per vertex), only the vertices marked non-zero move: the
// moving-balls engine relaxes the corners of failing triangles alone.
// Returns how many vertex moves were refused (counted over all passes).
long relax_tangentially(const SkinComplex& complex, SurfaceMesh& mesh, const RelaxationOptions& options,
                        const std::vector<char>* movable = nullptr);

}  // namespace skinmesh
