// A morph of two equal balls whose skins are apart at the source and joined
// by a neck at the target (one ball moves towards the other), and the
// oracle's verdict on whether they are joined at t.
#pragma once

#include "skinmesh/core/skin_oracle.hpp"

#include <cmath>
#include <vector>

namespace skinmesh::test {

struct TwoBallMorph {
  std::vector<Ball> source, target;
  TwoBallMorph() {
    const double w = 1.5 * 1.5 / 0.5;  // lone skin radius 1.5 A
    const double touch = 2 * std::sqrt(w);
    source = {{Eigen::Vector3d(0, 0, 0), w}, {Eigen::Vector3d(1.3 * touch, 0, 0), w}};
    target = {{Eigen::Vector3d(0, 0, 0), w}, {Eigen::Vector3d(0.7 * touch, 0, 0), w}};
  }
  // By the morph oracle, blind to cells: F_t < 0 at `samples` points along
  // the axis between the two centres.
  bool joined(const MorphOracle& oracle, double t, int samples) const {
    const Eigen::Vector3d far = (1 - t) * source[1].center + t * target[1].center;
    for (int k = 1; k < samples; ++k)
      if (oracle.evaluate(far * (k / static_cast<double>(samples)), t).value > 0) return false;
    return true;
  }
};

}  // namespace skinmesh::test
