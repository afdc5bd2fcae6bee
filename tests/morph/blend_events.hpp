// The m x n blend's topology events computed as the morph computes them
// (morph.cpp): the live pairs, every cell's size curve from B(1/2)'s
// complex, and the critical events among the sign changes.
#pragma once

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/morph/events.hpp"

#include <vector>

namespace skinmesh::test {

struct BlendEvents {
  std::vector<BallPair> live;
  SkinComplex middle;
  std::vector<CellSize> sizes;
  std::vector<TopologyEvent> critical;  // empty until with_critical()

  BlendEvents(const std::vector<Ball>& source, const std::vector<Ball>& target)
      : live(live_pairs(source, target)),
        middle(build_skin_complex(interpolated_balls(source, target, live, 0.5), {0.5})),
        sizes(cell_sizes(middle, source, target, live)) {}

  BlendEvents& with_critical(const std::vector<Ball>& source, const std::vector<Ball>& target) {
    critical = critical_events(topology_events(sizes), sizes, middle, live, MorphOracle(source, target, 0.5));
    return *this;
  }
};

}  // namespace skinmesh::test
