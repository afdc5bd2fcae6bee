#include "skinmesh/morph/matched_motion.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/morph/alignment.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace skinmesh {
namespace {

double radius_of(const Ball& b) { return std::sqrt(std::max(b.weight, 0.0)); }

// Of the matched tracks, the one whose atom on `side` (0 source, 1 target)
// lies nearest to `x`.
int nearest_matched(const MatchedMotion& m, const std::vector<int>& matched_tracks, int side, const Eigen::Vector3d& x) {
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int k : matched_tracks) {
    const MatchedMotion::Track& t = m.tracks[static_cast<size_t>(k)];
    const Ball& b = side == 0 ? m.source_balls[static_cast<size_t>(t.source)] : m.target_balls[static_cast<size_t>(t.target)];
    const double d = (b.center - x).squaredNorm();
    if (d < best_distance) {
      best_distance = d;
      best = k;
    }
  }
  return best;
}

}  // namespace

MatchedMotion match_motion(const Molecule& source, const std::vector<Ball>& source_balls, const Molecule& target,
                           const std::vector<Ball>& target_balls) {
  if (source_balls.size() != source.atoms.size() || target_balls.size() != target.atoms.size())
    contract_error("match_motion: one ball per atom on each side");
  MatchedMotion m;
  m.source_balls = source_balls;
  m.target_balls = target_balls;
  std::vector<char> source_matched(source.atoms.size(), 0), target_matched(target.atoms.size(), 0);
  std::vector<int> matched_tracks;
  for (const auto& [i, j] : matched_atoms(source, target)) {
    matched_tracks.push_back(static_cast<int>(m.tracks.size()));
    m.tracks.push_back({static_cast<int>(i), static_cast<int>(j), -1});
    source_matched[i] = target_matched[j] = 1;
  }
  if (matched_tracks.empty()) contract_error("match_motion: no atom of the source matches one of the target");
  m.matched = static_cast<long>(matched_tracks.size());
  for (size_t i = 0; i < source.atoms.size(); ++i)
    if (!source_matched[i]) {
      m.tracks.push_back({static_cast<int>(i), -1, nearest_matched(m, matched_tracks, 0, source_balls[i].center)});
      ++m.source_only;
    }
  for (size_t j = 0; j < target.atoms.size(); ++j)
    if (!target_matched[j]) {
      m.tracks.push_back({-1, static_cast<int>(j), nearest_matched(m, matched_tracks, 1, target_balls[j].center)});
      ++m.target_only;
    }
  return m;
}

std::vector<Ball> MatchedMotion::balls_at(double t) const {
  if (!(t >= 0 && t <= 1)) contract_error("MatchedMotion::balls_at: t must lie in [0,1]");
  std::vector<Ball> out(tracks.size());
  // a + t (b - a), not (1 - t) a + t b: an atom that does not move stays
  // where it is bit for bit, so that the engine finds the skin around it
  // unchanged (moving_balls.hpp).
  const auto centre_at = [&](const Track& k) {
    const Eigen::Vector3d& a = source_balls[static_cast<size_t>(k.source)].center;
    return (a + t * (target_balls[static_cast<size_t>(k.target)].center - a)).eval();
  };
  for (size_t i = 0; i < tracks.size(); ++i) {
    const Track& k = tracks[i];
    double r = 0;
    if (k.anchor < 0) {  // matched: ends exact, whatever rounding the line has
      out[i].center = t == 0 ? source_balls[static_cast<size_t>(k.source)].center
                             : t == 1 ? target_balls[static_cast<size_t>(k.target)].center : centre_at(k);
      if (t == 0 || t == 1) {
        out[i].weight = (t == 0 ? source_balls[static_cast<size_t>(k.source)] : target_balls[static_cast<size_t>(k.target)]).weight;
        continue;
      }
      const Ball& from = source_balls[static_cast<size_t>(k.source)];
      const Ball& to = target_balls[static_cast<size_t>(k.target)];
      if (from.weight == to.weight) {  // its radius kept exactly (sqrt and square would round it)
        out[i].weight = from.weight;
        continue;
      }
      r = (1 - t) * radius_of(from) + t * radius_of(to);
    } else if ((t == 0 && k.source >= 0) || (t == 1 && k.target >= 0)) {  // present at this end: as given
      out[i] = t == 0 ? source_balls[static_cast<size_t>(k.source)] : target_balls[static_cast<size_t>(k.target)];
      continue;
    } else {
      const Track& a = tracks[static_cast<size_t>(k.anchor)];
      const Eigen::Vector3d anchor = t == 0 ? source_balls[static_cast<size_t>(a.source)].center
                                     : t == 1 ? target_balls[static_cast<size_t>(a.target)].center : centre_at(a);
      if (k.target < 0) {  // source only: shrinks into its anchor
        out[i].center = anchor + (1 - t) * (source_balls[static_cast<size_t>(k.source)].center - source_balls[static_cast<size_t>(a.source)].center);
        r = (1 - t) * radius_of(source_balls[static_cast<size_t>(k.source)]);
      } else {  // target only: grows out of its anchor
        out[i].center = anchor + t * (target_balls[static_cast<size_t>(k.target)].center - target_balls[static_cast<size_t>(a.target)].center);
        r = t * radius_of(target_balls[static_cast<size_t>(k.target)]);
      }
    }
    out[i].weight = r * r;
  }
  return out;
}

}  // namespace skinmesh
