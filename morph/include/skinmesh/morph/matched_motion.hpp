// The balls of one molecule moving from one conformation to another
// (docs/math.md section 6; `skinmesh morph --pairs matched`): every atom the
// two sides share (alignment.hpp's matched_atoms) is one ball that travels
// on a straight line from its source to its target centre, its radius going
// linearly from its source radius to its target radius (the same when both
// sides use one radius table).
//
// An atom on one side only grows out of, or shrinks into, its anchor: the
// matched atom nearest to it on its own side. A target-only atom k with
// anchor a is at z_a(t) + t (b_k - b_a) with radius t r_k; a source-only
// atom at z_a(t) + (1-t) (a_k - a_a) with radius (1-t) r_k. At the end
// where it is absent it is a ball of radius 0 at its anchor's centre,
// which a ball of larger weight at the same centre dominates in every
// convex combination: it changes no skin there, and it changes
// continuously in between.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/molecule.hpp"

#include <vector>

namespace skinmesh {

struct MatchedMotion {
  // Per ball: its atom's index on each side (-1 where the side lacks it)
  // and its anchor ball (-1 for a matched atom).
  struct Track {
    int source = -1, target = -1, anchor = -1;
  };
  std::vector<Track> tracks;
  std::vector<Ball> source_balls, target_balls;  // per side, as given
  long matched = 0, source_only = 0, target_only = 0;

  // The balls at t in [0,1], one per track in their order. At t = 0 the
  // skin is the source's, at t = 1 the target's.
  std::vector<Ball> balls_at(double t) const;
};

// `source_balls` and `target_balls` are the sides' balls (balls_from_molecule),
// one per atom. Throws ContractError when no atom matches or a ball list's
// size is not its molecule's.
MatchedMotion match_motion(const Molecule& source, const std::vector<Ball>& source_balls, const Molecule& target,
                           const std::vector<Ball>& target_balls);

}  // namespace skinmesh
