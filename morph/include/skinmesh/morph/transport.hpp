// Moving a skin point from one frame of a morph to another inside its mixed
// cell (Yan, Cheng et al., GMSSTF, eq. 19; docs/math.md section 4). Both
// frames are complexes of one combinatorics (SkinComplex::with_balls of the
// same live pairs), so a cell index names the same overlay cell in both.
#pragma once

#include "skinmesh/core/skin_complex.hpp"

#include <Eigen/Core>

namespace skinmesh {

enum class TransportStatus {
  in_cell,        // the moved point lies in its cell at the new frame: exactly on the new skin
  left_cell,      // the cell deformed unevenly and the moved point left it (on its cell's quadric, not
                  // necessarily on the skin): it must be relocated
  size_vanished,  // R2 is zero at one frame or changes sign between them: a topology event in this cell
};

struct TransportedPoint {
  TransportStatus status = TransportStatus::in_cell;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // z(t1) + (p - z(t0)) sqrt(R2(t1) / R2(t0)), when defined
};

// p: a point on the skin of `from`, in mixed cell `cell`. The cell's quadric
// keeps its directions, its centre moves and its size scales, so the scaled
// point lies on the cell's quadric at the new frame exactly.
TransportedPoint transport(const SkinComplex& from, const SkinComplex& to, int cell, const Eigen::Vector3d& p);

}  // namespace skinmesh
