// The interpolated ball set of a morph (docs/math.md sections 1 and 4):
// B(t) = { (1-t) a_i + t b_j }, and which of its m*n pairs matter.
#pragma once

#include "skinmesh/core/balls.hpp"

#include <vector>

namespace skinmesh {

struct BallPair {
  int source = 0, target = 0;  // indices into the source and target ball lists
  bool operator==(const BallPair& o) const { return source == o.source && target == o.target; }
  bool operator<(const BallPair& o) const {
    return source != o.source ? source < o.source : target < o.target;
  }
};

// b_ij(t): centre (1-t) z_i + t z_j, weight (1-t) w_i + t w_j - t(1-t) |z_i - z_j|^2.
Ball interpolate_ball(const Ball& a, const Ball& b, double t);

// Every pair (i, j), the m*n set.
std::vector<BallPair> all_pairs(size_t m, size_t n);

// The live pairs: those whose power cells, a_i's in the source's power
// diagram and b_j's in the target's, overlap in an open set. For every t in
// (0,1) these are exactly the balls of B(t) that are not hidden in its
// regular triangulation (its power diagram is the overlay of the two, docs/math.md
// section 4), about m + n of them. Found by a walk over the overlay from the
// pairs holding the balls' centres, each candidate tested by insertion into
// the regular triangulation of B(1/2). Sorted. Atoms that stay put make the
// two diagrams share facets, and pairs across a shared facet have overlay
// cells of no volume: a pair of two atoms that both stay put (a_i equal to
// some target ball, b_j to some source ball, a_i != b_j) is left out, since
// its ball is a convex combination of two others for every t; any other
// pair of zero volume is kept or dropped as CGAL's symbolic perturbation
// decides. Either way the skin of B(t) is the same.
std::vector<BallPair> live_pairs(const std::vector<Ball>& source, const std::vector<Ball>& target);

// How near (Angstrom) a ball of the target must be to a ball of the source,
// of the same weight, to count as the same ball unmoved: half the 1e-3 A to
// which PDB, PQR and mmCIF files state coordinates, so no motion a structure
// file states is lost. Balls nearer than this but not equal make B(t) of all
// pairs nearly degenerate beyond what double precision resolves (pept
// against its copy moved 3e-5 A fails the frames' guarantees, and one copy
// in three moved 1.5e-4 to 3e-4 A; every copy moved 4e-4 A or farther
// meshes).
constexpr double kUnmovedWithin = 5e-4;

// Every target ball within `within` of a source ball of the same weight put
// exactly on the nearest such ball; returns how many were moved or already
// there. Live pairs then leave out the pairs of two unmoved balls.
long snap_unmoved_balls(const std::vector<Ball>& source, std::vector<Ball>& target, double within = kUnmovedWithin);

// Moves the balls so that the mean of their centres is the origin (morphs
// between molecules in different frames are commonly taken centred).
void centre_balls(std::vector<Ball>& balls);

// The balls b_ij(t) of the given pairs, in their order.
std::vector<Ball> interpolated_balls(const std::vector<Ball>& source, const std::vector<Ball>& target,
                                     const std::vector<BallPair>& pairs, double t);

}  // namespace skinmesh
