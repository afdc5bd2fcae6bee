// Components and voids that vanish between two frames (private to morph/):
// a critical event of dimension 0 or 3 that lowers the Euler characteristic
// by 2 (events.hpp) takes a whole sphere-like component of the skin away, a
// blob of the body that shrinks to its apex or a void that closes there.
// Its vertices have nowhere to go on the new skin, so the component is
// found in the frame before the step and dropped, and the rest of the frame
// is mended as any other (edits, patches), instead of the whole frame being
// remeshed.
#pragma once

#include "skinmesh/core/surface_mesh.hpp"

#include <vector>

namespace skinmesh::detail {

// Where a component vanishes: the event's apex z and size at the frame
// before the step; its component lies within `reach` of `center`.
struct VanishingSphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double reach = 0;  // Angstrom
};

// Per vertex of `mesh` (the frame before the step): 1 on a component taken
// by one of `spheres`. A component is taken by a sphere when it is the only
// one that lies wholly within the sphere's reach, is a sphere itself (Euler
// characteristic 2), and none of its vertices stayed in its cell at the
// step (`stayed_in_cell`, per vertex: transport found the vertex's cell
// still holding skin there). found[k]: whether spheres[k] took one.
std::vector<char> vanishing_components(const SurfaceMesh& mesh, const std::vector<char>& stayed_in_cell,
                                       const std::vector<VanishingSphere>& spheres, std::vector<char>& found);

}  // namespace skinmesh::detail
