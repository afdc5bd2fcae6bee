// The skin function as one convex minimisation (docs/math.md section 2):
//     F_B(x) = min over l in the simplex of (1-s)|x - Z l|^2 + s sum_i l_i pi_i(x).
// A second implementation of the skin, independent of the mixed complex: it
// never builds a triangulation. Each answer is certified by the optimality
// (KKT) conditions checked against every ball (those too far from the point
// to violate them by a bound on their distance and the largest weight, the
// rest one by one), so tests can trust it.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/interpolation.hpp"

#include <Eigen/Core>

#include <array>
#include <cmath>

#include <memory>
#include <utility>
#include <vector>

namespace skinmesh {

class BallGrid;  // balls bucketed by centre (skin_oracle.cpp)

struct OracleResult {
  double value = 0.0;                                   // F_B(x), Angstrom^2
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();   // 2 (x - Z l*)
  std::vector<std::pair<int, double>> support;          // (ball, l_i > 0)
  double kkt_violation = 0.0;  // worst optimality violation over all balls, relative; ~1e-15 when certified
  bool certified = false;      // kkt_violation below 1e-9
  // Every ball whose centre lies farther than this from x (Angstrom) meets
  // the optimality conditions by a bound that holds for any ball of weight
  // at most the largest weight of the balls; the answer stands, unchanged,
  // for another ball set that agrees with this one within `reach` of x and
  // has no larger weight (the check of morph frames relies on this).
  double reach = INFINITY;

  // First-order distance to the skin |F| / |grad F| (Angstrom).
  double distance() const;
};

class SkinOracle {
 public:
  SkinOracle(std::vector<Ball> balls, double shrink);
  OracleResult evaluate(const Eigen::Vector3d& x) const;
  // The same, with the solve started from `start`'s balls (indices into
  // balls(), -1 for none; e.g. the balls of the mixed cell a mesh vertex
  // lies in) instead of the balls of least power at x. The answer is
  // certified against every ball either way, so it does not depend on the
  // start; a start that holds the minimiser's support spares the search for
  // candidates and most steps of the solve. No valid ball: as evaluate(x).
  // Throws ContractError for an index past the last ball.
  OracleResult evaluate(const Eigen::Vector3d& x, const std::array<int, 4>& start) const;
  double shrink() const { return shrink_; }
  const std::vector<Ball>& balls() const { return balls_; }

 private:
  std::vector<Ball> balls_;
  double shrink_;
  // Balls far from x are certified by a bound instead of one by one
  // (evaluate); the grid finds the near ones.
  std::shared_ptr<const BallGrid> grid_;
  // warm: the first solve starts from all the candidates (a start's balls).
  OracleResult solve_from(const Eigen::Vector3d& x, std::vector<int> candidates, bool warm = false) const;
  friend class MorphOracle;  // certifies each side's balls with its grid the same way
};

// The skin function of every frame of a morph (docs/math.md section 4):
//     F_t(x) = min over l, u in the simplices of
//              (1-s)|x - (1-t) Z_A l - t Z_B u|^2 + s [(1-t) l.pi_A(x) + t u.pi_B(x)],
// which equals the skin function of all m*n interpolated balls b_ij(t). It is
// solved over a few candidate pairs and certified against every pair: a pair's
// optimality multiplier is (1-t) g_i + t g_j with g_i, g_j the source's and
// target's own, so the check over all m*n pairs needs only each side's least
// multiplier: found among each side's balls near x (its grid) and certified
// for the rest by the bound SkinOracle uses, so a point costs what its
// neighbourhood holds, not m + n. Like SkinOracle it never builds a
// triangulation, and it never asks which pairs are live: an independent
// reference for every frame of a morph.
struct MorphOracleResult {
  double value = 0.0;                                  // F_t(x), Angstrom^2
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  // 2 (x - (1-t) Z_A l* - t Z_B u*)
  // Pairs with their weight in the minimiser. At t = 0 (1) only the source's
  // (target's) balls count, and the other index is -1.
  std::vector<std::pair<BallPair, double>> support;
  double kkt_violation = 0.0;  // relative, over every pair; ~1e-15 when certified
  bool certified = false;      // kkt_violation below 1e-9
  double distance() const;     // |F_t| / |grad F_t|, Angstrom
};

class MorphOracle {
 public:
  // Throws ContractError on an empty ball set or a shrink factor outside (0,1).
  MorphOracle(std::vector<Ball> source, std::vector<Ball> target, double shrink);
  // t in [0, 1]; throws ContractError outside.
  MorphOracleResult evaluate(const Eigen::Vector3d& x, double t) const;
  // The same, with the pair solve started from `start` (e.g. the pairs of
  // the overlay cell a frame's vertex lies in) instead of the pairs of a few
  // balls of least power on each side; certified against every pair either
  // way. Up to four pairs (a cell's) all start in the working set: when they
  // hold the minimiser's support, one step of the solve instead of a pair
  // added per step. At t = 0 or 1, and with no pair, as evaluate(x, t). Throws
  // ContractError for a ball index past a side's last ball.
  MorphOracleResult evaluate(const Eigen::Vector3d& x, double t, const std::vector<BallPair>& start) const;

 private:
  SkinOracle source_, target_;
  // warm: the first solve starts from all the pairs (a start's).
  MorphOracleResult solve_from(const Eigen::Vector3d& x, double t, std::vector<BallPair> pairs, bool warm = false) const;
};

}  // namespace skinmesh
