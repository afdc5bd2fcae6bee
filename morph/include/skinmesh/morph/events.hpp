// When the skin's topology can change during a morph: every overlay cell's
// size R2(t) is a quadratic in t (eq. 18, docs/math.md section 4), and where
// it changes sign inside (0,1) a neck pinches or opens, a void closes, or a
// component appears or vanishes in that cell. Known before the first frame.
#pragma once

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"

#include <vector>

namespace skinmesh {

// R2(t) = a t^2 + b t + c, Angstrom^2. Exact for an overlay cell: a simplex
// of B(t) whose dimension is (|X|-1) + (|Y|-1), X and Y the source and target
// balls of its pairs, so that its affine hull is that of the Minkowski cell
// (1-t) delta_X + t delta_Y and its centre z_XY(t) (eq. 17). A simplex of
// lower dimension inside such a cell (the diagonal of a parallelogram) has a
// mixed cell of no volume, holds no skin, and its size is not quadratic.
struct CellSize {
  double a = 0, b = 0, c = 0;
  bool overlay_cell = false;
  // The cell's centre, affine in t (eq. 17): z(t) = center_half + (t - 1/2) center_slope.
  Eigen::Vector3d center_half = Eigen::Vector3d::Zero(), center_slope = Eigen::Vector3d::Zero();
  double at(double t) const { return (a * t + b) * t + c; }
  Eigen::Vector3d center(double t) const { return center_half + (t - 0.5) * center_slope; }
};

// The size curve of every cell of `middle` (the complex of B(1/2) of the
// live pairs `pairs`), from the cell's size at t = 1/4, 1/2 and 3/4 (a
// quadratic is fixed by three values), each frame moved by with_balls.
std::vector<CellSize> cell_sizes(const SkinComplex& middle, const std::vector<Ball>& source,
                                 const std::vector<Ball>& target, const std::vector<BallPair>& pairs);

struct TopologyEvent {
  double t = 0;   // in (0,1)
  int cell = -1;  // the cell of `middle` whose size changes sign
  // Filled by critical_events: the cell's dimension (the index of the
  // critical point) and the change of the skin's Euler characteristic as
  // the morph passes t (+-2; 0 where the size only touches zero).
  int dim = 0;
  int euler_change = 0;
};

// Every sign change of an overlay cell's size curve inside (0,1), by time. A
// double root (the size touches zero) counts as an event too.
std::vector<TopologyEvent> topology_events(const std::vector<CellSize>& sizes);

// The events at which the skin's topology does change: where the size of a
// cell vanishes its quadric is a cone with apex z(t), and the skin changes
// there only if the apex lies in the cell's own mixed cell (a critical point
// of the skin, Edelsbrunner 1999), i.e. if the morph oracle's minimiser at
// (z(t), t) is supported by exactly the cell's source balls X and target
// balls Y. An overlay cell (X, Y) that is not a simplex (a prism, a
// parallelogram) is triangulated into simplices with one centre and one
// size curve: it is one critical point, reported once. `middle` and `pairs`
// as for cell_sizes.
std::vector<TopologyEvent> critical_events(const std::vector<TopologyEvent>& events,
                                           const std::vector<CellSize>& sizes, const SkinComplex& middle,
                                           const std::vector<BallPair>& pairs, const MorphOracle& oracle);

// Per critical event, the event it cancels within the step (from, to], or
// -1: a void sealed (dimension 2, Euler characteristic +2) and filled
// (dimension 3, -2), or a piece pinched off a component (dimension 1, +2)
// that then vanishes (dimension 0, -2), the vanishing second and its apex
// within `same_place` of the first's (Angstrom, each at its own time). The
// void or piece lives inside the step only: no frame holds it, and the two
// change no topology. Vanishing events marked in `skip` (accounted for
// otherwise) are not paired.
std::vector<int> cancelling_partners(const std::vector<TopologyEvent>& events, const std::vector<CellSize>& sizes,
                                     double from, double to, const std::vector<char>& skip,
                                     double same_place = 0.5);

}  // namespace skinmesh
