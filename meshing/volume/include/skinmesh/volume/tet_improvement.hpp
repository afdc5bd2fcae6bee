// Mending the tetrahedra TetGen leaves outside the quality bounds next to the
// surface it may not split: the points it added (those on no face of
// `mesh.faces`) are moved by pattern search, and edges on no face whose ring
// of tetrahedra can be retriangulated better are removed. The faces, the
// points on them and every region's volume stay as they are.
#pragma once

#include "skinmesh/core/tet_mesh.hpp"

namespace skinmesh {

struct TetBounds {
  double max_radius_edge = 2.0;  // circumradius / shortest edge (dimensionless, >= 1)
  double min_dihedral = 5.0;     // degrees
};

struct TetImprovement {
  long bad_before = 0, bad_after = 0;  // tetrahedra outside the bounds
  long moved = 0;                      // points moved
  long flips = 0;                      // edges removed (ring of tetrahedra retriangulated)
  bool timed_out = false;              // stopped at max_seconds with bad_after left
};

// max_seconds: the time it may take (0: no bound); past it the mesh is
// left as the improvement has it, valid, with timed_out set.
TetImprovement improve_tet_mesh(TetMesh& mesh, const TetBounds& bounds = {}, double max_seconds = 0);

}  // namespace skinmesh
