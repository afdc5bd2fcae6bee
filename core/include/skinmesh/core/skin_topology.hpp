// The topology of a ball set's skin counted without meshing it: the body the
// skin bounds is homotopy equivalent to the union of the balls, and so to the
// dual complex K of that union (H. Edelsbrunner, "Deformable smooth surface
// design", Discrete Comput. Geom. 21 (1999) 87-115; for every shrink factor
// in (0,1)). K is the weighted alpha complex at alpha = 0: the simplices of
// the regular triangulation whose Voronoi faces meet the union. Classified
// on CGAL's regular triangulation with the kernel's exact predicates, as
// CGAL's alpha shapes classify it (tests/core/test_skin_topology.cpp holds it
// to CGAL's Fixed_alpha_shape_3), independently of the mixed complex, so that
// a mesh's topology can be certified against it.
#pragma once

#include "skinmesh/core/balls.hpp"

#include <string>
#include <vector>

namespace skinmesh {

struct SkinTopology {
  long components = 0;  // connected components of the skin (outer surfaces and voids' surfaces)
  long voids = 0;       // bounded components of the body's complement (each one a component of the skin)
  long euler = 0;       // Euler characteristic of the skin: twice the body's
  bool operator==(const SkinTopology& o) const {
    return components == o.components && voids == o.voids && euler == o.euler;
  }
  bool operator!=(const SkinTopology& o) const { return !(*this == o); }
  std::string text() const;  // "C component(s) (V voids), Euler characteristic E"
};

// Balls of weight <= 0 have no body and are left out. Throws ContractError
// for a non-finite ball.
SkinTopology skin_topology(const std::vector<Ball>& balls);

}  // namespace skinmesh
