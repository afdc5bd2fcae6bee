// Bringing the tetrahedra TetGen leaves outside the radius-edge and dihedral
// bounds within them (see tet_improvement.hpp).
//
// TetGen may not split the surface (-Y), and near it a few tetrahedra keep
// a radius-edge ratio or a dihedral angle just outside what was asked: the
// refinement point it would insert lies too close to the surface. Two local
// operations fix them, neither touching the marked faces or their points:
//  - moving a point TetGen added (a Steiner point) inside its star, by a
//    pattern search that maximises the star's worst tetrahedron;
//  - removing an edge that lies on no marked face (Shewchuk's edge removal:
//    the ring of tetrahedra around it replaced by the best triangulation of
//    its link polygon, each triangle joined to both ends), which is what
//    undoes a flat tetrahedron spanned by four surface points.
// Every change keeps all tetrahedra it makes positively oriented and fills
// exactly the space it empties, so every region's volume is unchanged.
#include "skinmesh/volume/tet_improvement.hpp"

#include "skinmesh/quality/tet_quality.hpp"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <functional>
#include <optional>
#include <set>

namespace skinmesh {
namespace {

using Tet = std::array<int, 4>;

// An edge removal that mends a tetrahedron of fixed points may leave one
// with a free point this far outside the bounds, for the smoothing to mend.
constexpr double kFlatEnough = 0.2;

// 1 or more when the tetrahedron meets both bounds; below 1 by the factor
// it misses the worse one; -1 when flat or inverted.
double shape_quality(const std::vector<Eigen::Vector3d>& points, const Tet& t, const TetBounds& bounds) {
  const TetShape s =
      tet_shape(points[static_cast<size_t>(t[0])], points[static_cast<size_t>(t[1])],
                        points[static_cast<size_t>(t[2])], points[static_cast<size_t>(t[3])]);
  if (!(s.volume > 0)) return -1;
  double q = bounds.max_radius_edge / s.radius_edge;
  if (bounds.min_dihedral > 0) q = std::min(q, s.min_dihedral / bounds.min_dihedral);
  return q;
}

// Which free points a smoothing round moves: those of the bad tetrahedra, or
// also those in their vertices' stars (the stars constrain each other).
enum class SmoothingReach { bad_tets, their_stars };

class Improver {
 public:
  Improver(TetMesh& mesh, const TetBounds& bounds) : mesh_(mesh), bounds_(bounds), star_(mesh.points.size()) {
    fixed_.assign(mesh.points.size(), 0);
    for (const auto& f : mesh.faces)
      for (int k = 0; k < 3; ++k) {
        fixed_[static_cast<size_t>(f[static_cast<size_t>(k)])] = 1;
        const int a = f[static_cast<size_t>(k)], b = f[static_cast<size_t>((k + 1) % 3)];
        marked_edges_.insert({std::min(a, b), std::max(a, b)});
      }
    for (size_t t = 0; t < mesh.tets.size(); ++t)
      for (int v : mesh.tets[t]) star_[static_cast<size_t>(v)].push_back(static_cast<int>(t));
  }

  std::vector<int> all_bad_tets() const {
    std::vector<int> bad;
    for (size_t t = 0; t < mesh_.tets.size(); ++t)
      if (mesh_.tets[t][0] >= 0 && quality(mesh_.tets[t]) < 1) bad.push_back(static_cast<int>(t));
    return bad;
  }

  // The bad tetrahedra among the previous ones and those changed since.
  std::vector<int> bad_tets(const std::vector<int>& previous) {
    std::set<int> candidates(previous.begin(), previous.end());
    candidates.insert(changed_.begin(), changed_.end());
    changed_.clear();
    std::vector<int> bad;
    for (int t : candidates)
      if (mesh_.tets[static_cast<size_t>(t)][0] >= 0 && quality(mesh_.tets[static_cast<size_t>(t)]) < 1)
        bad.push_back(t);
    return bad;
  }

  // The free points of the bad tetrahedra (and, with their_stars, those of
  // their vertices' stars) optimised once each. Returns how many moved.
  // The time bound: past `deadline` (steady clock) every pass stops.
  void set_deadline(double max_seconds) {
    if (max_seconds > 0)
      deadline_ = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                          std::chrono::duration<double>(max_seconds));
  }
  bool late() const { return deadline_ && std::chrono::steady_clock::now() > *deadline_; }

  long smooth(const std::vector<int>& bad, SmoothingReach reach) {
    const bool wide = reach == SmoothingReach::their_stars;
    std::set<int> work;
    for (int t : bad)
      for (int v : mesh_.tets[static_cast<size_t>(t)]) {
        if (!fixed_[static_cast<size_t>(v)]) work.insert(v);
        if (wide)
          for (int s : star_[static_cast<size_t>(v)])
            for (int u : mesh_.tets[static_cast<size_t>(s)])
              if (!fixed_[static_cast<size_t>(u)]) work.insert(u);
      }
    long moved = 0;
    for (int v : work) {
      if (late()) break;
      if (optimise_point(v)) {
        ++moved;
        changed_.insert(changed_.end(), star_[static_cast<size_t>(v)].begin(), star_[static_cast<size_t>(v)].end());
      }
    }
    return moved;
  }

  // Tries to remove each edge of tetrahedron t that lies on no marked face;
  // returns whether one was removed.
  bool remove_an_edge(int t) {
    if (mesh_.tets[static_cast<size_t>(t)][0] < 0) return false;
    const Tet tet = mesh_.tets[static_cast<size_t>(t)];
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        if (remove_edge(tet[static_cast<size_t>(i)], tet[static_cast<size_t>(j)])) return true;
    return false;
  }

  // Drops the tetrahedra edge removal emptied.
  void compact() {
    size_t kept = 0;
    for (size_t t = 0; t < mesh_.tets.size(); ++t)
      if (mesh_.tets[t][0] >= 0) {
        mesh_.tets[kept] = mesh_.tets[t];
        mesh_.tet_region[kept] = mesh_.tet_region[t];
        ++kept;
      }
    mesh_.tets.resize(kept);
    mesh_.tet_region.resize(kept);
  }

 private:
  double quality(const Tet& t) const { return shape_quality(mesh_.points, t, bounds_); }

  struct StarQuality {
    double worst = INFINITY;
    long bad = 0;
  };
  StarQuality star_quality(int v) const {
    StarQuality s;
    for (int t : star_[static_cast<size_t>(v)]) {
      const double q = quality(mesh_.tets[static_cast<size_t>(t)]);
      s.worst = std::min(s.worst, q);
      if (q < 1) ++s.bad;
    }
    return s;
  }

  // Pattern search for the position of v that maximises the worst quality
  // of its star. Returns whether v moved.
  bool optimise_point(int v) {
    Eigen::Vector3d& x = mesh_.points[static_cast<size_t>(v)];
    const Eigen::Vector3d start = x;
    const StarQuality before = star_quality(v);
    double shortest = INFINITY;
    for (int t : star_[static_cast<size_t>(v)])
      for (int u : mesh_.tets[static_cast<size_t>(t)])
        if (u != v) shortest = std::min(shortest, (mesh_.points[static_cast<size_t>(u)] - x).norm());
    static const Eigen::Vector3d kDirections[] = {
        {1, 0, 0},  {-1, 0, 0}, {0, 1, 0},   {0, -1, 0},  {0, 0, 1},   {0, 0, -1},  {1, 1, 1},
        {1, 1, -1}, {1, -1, 1}, {1, -1, -1}, {-1, 1, 1},  {-1, 1, -1}, {-1, -1, 1}, {-1, -1, -1}};
    double step = 0.25 * shortest;
    double best = before.worst;
    for (int iteration = 0; iteration < 200 && step > 1e-4 * shortest && best < 1.5; ++iteration) {
      const Eigen::Vector3d here = x;
      Eigen::Vector3d best_point = here;
      for (const Eigen::Vector3d& d : kDirections) {
        x = here + step * d.normalized();
        const double q = star_quality(v).worst;
        if (q > best + 1e-12) {
          best = q;
          best_point = x;
        }
      }
      x = best_point;
      if (best_point == here) step *= 0.5;
    }
    // Keep the move only if it leaves fewer tetrahedra out of bounds (a
    // max-min search can pull good neighbours down to the worst one).
    const StarQuality after = star_quality(v);
    if (after.bad < before.bad || (after.bad == before.bad && after.worst > before.worst)) return x != start;
    x = start;
    return false;
  }

  // Edge removal of c-d, done when the best triangulation of its link makes
  // the ring's worst tetrahedron better.
  bool remove_edge(int c, int d) {
    if (marked_edges_.count({std::min(c, d), std::max(c, d)})) return false;
    std::vector<int> ring;
    for (int t : star_[static_cast<size_t>(c)]) {
      const Tet& tet = mesh_.tets[static_cast<size_t>(t)];
      if (std::find(tet.begin(), tet.end(), d) != tet.end()) ring.push_back(t);
    }
    if (ring.size() < 3 || ring.size() > 7) return false;
    const std::vector<int> polygon = link_polygon(ring, c, d);
    if (polygon.empty()) return false;
    const int region = mesh_.tet_region[static_cast<size_t>(ring[0])];
    std::vector<Tet> old_tets;
    for (int t : ring) {
      if (mesh_.tet_region[static_cast<size_t>(t)] != region) return false;
      old_tets.push_back(mesh_.tets[static_cast<size_t>(t)]);
    }
    const std::vector<Tet> best_tets = best_link_triangulation(polygon, c, d, score(old_tets));
    if (best_tets.empty()) return false;
    replace_ring(ring, best_tets, region);
    return true;
  }

  // The link of edge c-d as a polygon, counter-clockwise seen from d; empty
  // when the ring of tetrahedra is not one closed ring (the edge is on the
  // domain's boundary).
  std::vector<int> link_polygon(const std::vector<int>& ring, int c, int d) const {
    // Each ring tetrahedron, written (c, d, x, y) positively, gives the link
    // edge x -> y; they chain into the link polygon around c-d.
    std::vector<std::pair<int, int>> link;
    for (int t : ring) {
      const Tet& tet = mesh_.tets[static_cast<size_t>(t)];
      int other[2], n = 0;
      for (int v : tet)
        if (v != c && v != d) other[n++] = v;
      Tet oriented{c, d, other[0], other[1]};
      if (!(signed_tet_volume(mesh_.points[static_cast<size_t>(c)], mesh_.points[static_cast<size_t>(d)],
                              mesh_.points[static_cast<size_t>(other[0])],
                              mesh_.points[static_cast<size_t>(other[1])]) > 0))
        std::swap(oriented[2], oriented[3]);
      link.push_back({oriented[2], oriented[3]});
    }
    std::vector<int> polygon{link[0].first};
    for (size_t k = 0; k + 1 < link.size(); ++k) {
      const auto next = std::find_if(link.begin(), link.end(), [&](auto& e) { return e.first == polygon.back(); });
      if (next == link.end()) return {};
      polygon.push_back(next->second);
    }
    const auto last = std::find_if(link.begin(), link.end(), [&](auto& e) { return e.first == polygon.back(); });
    if (last == link.end() || last->second != polygon.front()) return {};
    return polygon;
  }

  // A triangulation is judged first by its worst tetrahedron of four fixed
  // points (nothing but another flip can change it), capped at 1, then by
  // its worst tetrahedron overall (moving a free point may mend it later).
  std::pair<double, double> score(const std::vector<Tet>& tets) const {
    double fixed_worst = 1, worst = INFINITY;
    for (const Tet& t : tets) {
      const double q = quality(t);
      worst = std::min(worst, q);
      if (fixed_[static_cast<size_t>(t[0])] && fixed_[static_cast<size_t>(t[1])] &&
          fixed_[static_cast<size_t>(t[2])] && fixed_[static_cast<size_t>(t[3])])
        fixed_worst = std::min(fixed_worst, q);
    }
    return std::make_pair(worst > 0 ? fixed_worst : -1.0, worst);
  }

  // The tetrahedra joining the best triangulation of the link polygon to c
  // and d (every choice of apex for side (i, j), recursively: at most 42
  // triangulations for 7 sides), or none when none beats `old_score`.
  std::vector<Tet> best_link_triangulation(const std::vector<int>& polygon, int c, int d,
                                           std::pair<double, double> old_score) const {
    const int n = static_cast<int>(polygon.size());
    std::vector<Tet> best_tets;
    std::pair<double, double> best = old_score;
    std::vector<std::array<int, 3>> triangles;
    std::function<void(std::vector<std::pair<int, int>>)> enumerate = [&](std::vector<std::pair<int, int>> open) {
      if (open.empty()) {
        std::vector<Tet> made;
        for (const auto& tr : triangles) {
          // The link runs counter-clockwise seen from d ((c, d, x, y) is
          // positive), so (x, y, z) in polygon order faces d: (x, y, z, d)
          // and (z, y, x, c) are positive when the removal is valid.
          const int x = polygon[static_cast<size_t>(tr[0])], y = polygon[static_cast<size_t>(tr[1])],
                    z = polygon[static_cast<size_t>(tr[2])];
          made.push_back({x, y, z, d});
          made.push_back({z, y, x, c});
        }
        const std::pair<double, double> candidate = score(made);
        // Better among the fixed tetrahedra, not flat anywhere; or as good
        // there and better overall.
        const bool better = candidate.first > best.first + 1e-12
                                ? candidate.second >= std::min(best.second, kFlatEnough)
                                : candidate.first >= best.first && candidate.second > best.second + 1e-12;
        if (better) {
          best = candidate;
          best_tets = made;
        }
        return;
      }
      const auto [i, j] = open.back();
      open.pop_back();
      for (int k = i + 1; k < j; ++k) {
        triangles.push_back({i, k, j});
        auto next = open;
        if (k - i > 1) next.push_back({i, k});
        if (j - k > 1) next.push_back({k, j});
        enumerate(next);
        triangles.pop_back();
      }
    };
    enumerate({{0, n - 1}});
    return best_tets;
  }

  // Puts `made` in place of the ring's tetrahedra (reusing their slots),
  // keeping the vertex stars current. Orientation decides validity: each new
  // tetrahedron must be positive, which quality() > 0 already required.
  void replace_ring(const std::vector<int>& ring, const std::vector<Tet>& made, int region) {
    for (int t : ring)
      for (int v : mesh_.tets[static_cast<size_t>(t)]) {
        auto& s = star_[static_cast<size_t>(v)];
        s.erase(std::remove(s.begin(), s.end(), t), s.end());
      }
    for (size_t k = 0; k < made.size(); ++k) {
      int slot;
      if (k < ring.size()) {
        slot = ring[k];
        mesh_.tets[static_cast<size_t>(slot)] = made[k];
      } else {
        slot = static_cast<int>(mesh_.tets.size());
        mesh_.tets.push_back(made[k]);
        mesh_.tet_region.push_back(region);
      }
      for (int v : made[k]) star_[static_cast<size_t>(v)].push_back(slot);
      changed_.push_back(slot);
    }
    for (size_t k = made.size(); k < ring.size(); ++k)
      mesh_.tets[static_cast<size_t>(ring[k])] = {-1, -1, -1, -1};
  }

  TetMesh& mesh_;
  TetBounds bounds_;
  std::vector<std::vector<int>> star_;
  std::vector<char> fixed_;
  std::set<std::pair<int, int>> marked_edges_;
  std::optional<std::chrono::steady_clock::time_point> deadline_;
  std::vector<int> changed_;  // tetrahedra changed since bad_tets() last looked
};

}  // namespace

TetImprovement improve_tet_mesh(TetMesh& mesh, const TetBounds& bounds, double max_seconds) {
  Improver improver(mesh, bounds);
  improver.set_deadline(max_seconds);
  TetImprovement result;
  std::vector<int> bad = improver.all_bad_tets();
  result.bad_before = static_cast<long>(bad.size());
  // Moving the bad tetrahedra's own free points first, then those around
  // them too (their stars constrain each other), and removing edges where
  // moving points cannot help (a tetrahedron of four surface points).
  for (int round = 0; round < 8 && !bad.empty(); ++round) {
    const size_t before = bad.size();
    result.moved += improver.smooth(bad, round >= 2 ? SmoothingReach::their_stars : SmoothingReach::bad_tets);
    bad = improver.bad_tets(bad);
    if (round >= 1) {
      for (int t : bad) {
        if (improver.late()) break;
        result.flips += improver.remove_an_edge(t);
      }
      bad = improver.bad_tets(bad);
    }
    if (round >= 3 && bad.size() >= before) break;
    if (improver.late()) break;
  }
  result.timed_out = improver.late();
  improver.compact();
  result.bad_after = static_cast<long>(improver.all_bad_tets().size());
  return result;
}

}  // namespace skinmesh
