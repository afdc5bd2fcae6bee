// The skin function as one convex minimisation (docs/math.md section 2):
//     F_B(x) = min over l in the simplex of (1-s)|x - Z l|^2 + s sum_i l_i pi_i(x).
// A second implementation of the skin, independent of the mixed complex: it
// never builds a triangulation. Each answer is certified by the optimality
// (KKT) conditions checked against every ball, so tests can trust it.
#pragma once

#include "skinmesh/core/balls.hpp"

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace skinmesh {

struct OracleResult {
  double value = 0.0;                                   // F_B(x), Angstrom^2
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();   // 2 (x - Z l*)
  std::vector<std::pair<int, double>> support;          // (ball, l_i > 0)
  double kkt_violation = 0.0;  // worst optimality violation over all balls, relative; ~1e-15 when certified
  bool certified = false;      // kkt_violation below 1e-9

  // First-order distance to the skin |F| / |grad F| (Angstrom).
  double distance() const;
};

class SkinOracle {
 public:
  SkinOracle(std::vector<Ball> balls, double shrink);
  OracleResult evaluate(const Eigen::Vector3d& x) const;
  double shrink() const { return shrink_; }
  const std::vector<Ball>& balls() const { return balls_; }

 private:
  std::vector<Ball> balls_;
  double shrink_;
};

}  // namespace skinmesh
