// The skin topology of B(t), frame after frame, for the certificate of the
// m x n blend's frames: counted from scratch (skin_topology, the exact
// alpha complex of B(t)'s balls) at one frame and carried unchanged to a
// later frame when no time between them can change it.
//
// Why that can be known ahead: the skin of B(t) is the zero set of F_t
// (docs/math.md section 4). It changes its topology only where F_t has a
// critical point on it, and every critical point of F_t is the centre z of
// a mixed cell lying in that cell, where F_t = s R2 (H. Edelsbrunner,
// "Deformable smooth surface design", 1999). For t in (0,1) the cells are
// those of the overlay complex of B(1/2); a simplex that spans its overlay
// cell has that cell's centre and size, and its size is a quadratic in t
// (eq. 18). So the topology can change only at a root of such a size
// curve, and only if the gradient of F_t (the morph oracle's, certified
// against every pair) vanishes at the cell's centre there. A window of
// time is kept around every root where the gradient is not clearly away
// from zero, widened by the curve's measured error; any two frames in
// (0,1) with no such window between them have the same topology.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/morph/events.hpp"

#include <optional>
#include <utility>
#include <vector>

namespace skinmesh {

struct TopologyWindowOptions {
  // A root is a possible change when the gradient of F_t at the cell's
  // centre is at most this (Angstrom), plus what the centre can move
  // within the root's window.
  double gradient_below = 1e-4;
  // A size curve of a cell that is not an overlay cell by its pairs
  // (CellSize::overlay_cell) whose values at t = 0.4 and 0.6 differ from
  // the cell's own size there by more than this (Angstrom^2) is not a
  // quadratic: a simplex inside its overlay cell that does not span it (a
  // diagonal), whose centre is no critical point of its own. Every other
  // curve is kept, and its measured error widens its windows.
  double not_quadratic_above = 1e-4;
};

// The times at which the skin's topology may change, decided on demand:
// every root of every size curve is a candidate, and whether it is a
// possible change (the oracle's gradient at the cell's centre there) is
// decided the first time an interval holding it is asked about, in any
// order, until one is. Steps of a fine morph hold a few candidates; a
// coarse step holds thousands, and a possible change is found among its
// first hundred or so.
class TopologyWindows {
 public:
  // No candidate: no change anywhere.
  TopologyWindows() = default;
  // Windows known to be possible changes, [from, to] each (tests).
  explicit TopologyWindows(const std::vector<std::pair<double, double>>& windows);
  // `middle`, `sizes` and `pairs` as for critical_events (the complex of
  // B(1/2) of the live pairs, its cells' size curves); `source` and
  // `target` the morph's balls, `oracle` their morph oracle (copied).
  TopologyWindows(const SkinComplex& middle, const std::vector<CellSize>& sizes, const std::vector<Ball>& source,
                  const std::vector<Ball>& target, const std::vector<BallPair>& pairs, const MorphOracle& oracle,
                  const TopologyWindowOptions& options = {});
  // Whether the skin's topology may differ between t = a and t = b (in any order).
  bool meets(double a, double b);
  long curves() const { return curves_; }                                      // size curves looked at
  long candidates() const { return static_cast<long>(candidates_.size()); }  // their roots and near-roots
  long decided() const;   // candidates asked about so far
  long possible() const;  // of them, possible changes

 private:
  struct Candidate {
    double from = 0, to = 0;    // the window around the root
    double t = 0;               // the root
    double gradient_below = 0;  // a possible change below this gradient (Angstrom): the option and the centre's move
    int cell = -1;              // into cells_
    signed char possible = -1;  // -1 not decided yet, 0 no change, 1 a possible change
  };
  bool decide(Candidate& c);  // asks the oracle once, keeps the answer in c
  std::vector<Candidate> candidates_;  // ascending by from
  std::vector<double> reach_;          // per candidate: the largest `to` of it and all before it
  // Per cell with a candidate: its centre's line and its pairs (the solve's start).
  struct Cell {
    Eigen::Vector3d center_half = Eigen::Vector3d::Zero(), center_slope = Eigen::Vector3d::Zero();
    std::vector<BallPair> start;
  };
  std::vector<Cell> cells_;
  std::optional<MorphOracle> oracle_;
  long curves_ = 0;
};

// A frame's count: the topology, and the t of the frame whose balls were counted.
struct CountedTopology {
  SkinTopology topology;
  double counted_at = -1;
};

class CarriedTopology {
 public:
  explicit CarriedTopology(TopologyWindows windows) : windows_(std::move(windows)) {}
  // The topology of the skin of `balls`, B(t)'s balls: the count of an
  // earlier call when both t are in (0,1) and no window lies between,
  // otherwise skin_topology(balls), kept for later calls.
  CountedTopology at(double t, const std::vector<Ball>& balls);
  long counted() const { return counted_; }
  long carried() const { return carried_; }
  const TopologyWindows& windows() const { return windows_; }

 private:
  TopologyWindows windows_;
  CountedTopology last_;
  long counted_ = 0, carried_ = 0;
};

}  // namespace skinmesh
