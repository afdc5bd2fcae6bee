#include "skinmesh/morph/moving_balls.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/quality/mesh_quality.hpp"  // mesh_topology

#include "judge.hpp"
#include "local_repair.hpp"
#include "mesh_part.hpp"
#include "births.hpp"
#include "surgery.hpp"
#include "unchanged_skin.hpp"
#include "vanishing.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <optional>

namespace skinmesh {
namespace {

double radius_of(const Ball& b) { return std::sqrt(std::max(b.weight, 0.0)); }

// How far a ball moved: its centre's way plus the change of its radius.
double ball_move(const Ball& a, const Ball& b) {
  return (b.center - a.center).norm() + std::abs(radius_of(b) - radius_of(a));
}

// The balls a share `a` of the way from `from` to `to`: centres on the
// straight line; radii linear where both weights are >= 0 (an atom growing
// from nothing), weights linear otherwise. A centre that does not move and
// a weight that does not change stay as they are, bit for bit: the engine
// then finds the skin around such balls unchanged.
std::vector<Ball> balls_between(const std::vector<Ball>& from, const std::vector<Ball>& to, double a) {
  std::vector<Ball> out(from.size());
  for (size_t i = 0; i < out.size(); ++i) {
    out[i].center = from[i].center + a * (to[i].center - from[i].center);
    if (from[i].weight == to[i].weight) {
      out[i].weight = from[i].weight;
    } else if (from[i].weight >= 0 && to[i].weight >= 0) {
      const double r = (1 - a) * radius_of(from[i]) + a * radius_of(to[i]);
      out[i].weight = r * r;
    } else {
      out[i].weight = (1 - a) * from[i].weight + a * to[i].weight;
    }
  }
  return out;
}

// Per ball, the rotation of least squares (Kabsch 1976, reflection
// excluded) taking the old centres of the ball and its neighbours in the
// regular triangulation of `from` onto their new centres: how the
// neighbourhood turned. Identity for a hidden ball or fewer than three
// centres. A rigid motion of the whole set gives every ball its rotation.
std::vector<Eigen::Matrix3d> neighbourhood_rotations(const SkinComplex& from, const std::vector<Ball>& to) {
  const std::vector<Ball>& old = from.balls();
  std::vector<Eigen::Matrix3d> rotations(old.size(), Eigen::Matrix3d::Identity());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, old.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<int> near;
    for (size_t b = r.begin(); b != r.end(); ++b) {
      const int cell = from.vertex_cell(static_cast<int>(b));
      if (cell < 0) continue;
      near.assign(1, static_cast<int>(b));
      for (auto c = from.cofaces_begin(cell); c != from.cofaces_end(cell); ++c)
        if (!c->beyond) near.push_back(c->ball);
      if (near.size() < 3) continue;
      Eigen::Vector3d p_mean = Eigen::Vector3d::Zero(), q_mean = Eigen::Vector3d::Zero();
      for (int i : near) {
        p_mean += old[static_cast<size_t>(i)].center;
        q_mean += to[static_cast<size_t>(i)].center;
      }
      p_mean /= static_cast<double>(near.size());
      q_mean /= static_cast<double>(near.size());
      Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
      for (int i : near)
        h += (old[static_cast<size_t>(i)].center - p_mean) * (to[static_cast<size_t>(i)].center - q_mean).transpose();
      const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
      Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
      d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
      rotations[b] = svd.matrixV() * d * svd.matrixU().transpose();
    }
  });
  return rotations;
}

// The rotation a cell's patch turns by (docs/math.md section 6): `r` (its
// first ball's neighbourhood rotation, or the rigid motion that carried all
// its balls), corrected by the least rotation that puts the direction space
// of delta_X exactly onto its new place (the edge's direction, the
// triangle's plane), so that the quadric maps onto the new one exactly. A
// vertex's and a tetrahedron's quadric is isotropic in its direction space:
// any rotation maps it.
Eigen::Matrix3d cell_rotation(const MixedCell& cell, const std::vector<Ball>& old, const std::vector<Ball>& now,
                              const Eigen::Matrix3d& r) {
  const auto at = [](const std::vector<Ball>& balls, int i) { return balls[static_cast<size_t>(i)].center; };
  const std::array<int, 4>& x = cell.balls;
  Eigen::Vector3d before, after;
  if (cell.dim == 1) {
    before = (at(old, x[1]) - at(old, x[0])).normalized();
    after = (at(now, x[1]) - at(now, x[0])).normalized();
  } else if (cell.dim == 2) {
    before = (at(old, x[1]) - at(old, x[0])).cross(at(old, x[2]) - at(old, x[0])).normalized();
    after = (at(now, x[1]) - at(now, x[0])).cross(at(now, x[2]) - at(now, x[0])).normalized();
  } else {
    return r;
  }
  const Eigen::Vector3d turned = r * before;
  if (cell.dim == 2 && turned.dot(after) < 0) after = -after;  // a plane's normal has no sign
  return Eigen::Quaterniond::FromTwoVectors(turned, after).toRotationMatrix() * r;
}

// kept: in a cell the step left as it was (quiet_balls), where it stays.
enum class VertexFate : char { kept, moved, relocated, lost };

// Whether the vertex stayed on its cell's closed-form path (not placed again, not lost).
bool stayed_put(VertexFate f) { return f == VertexFate::kept || f == VertexFate::moved; }

// Per ball, 1 where `flags` marks it and every neighbour it has in the
// regular triangulation of `from` or of `to` (hidden: none).
std::vector<char> with_all_neighbours(const SkinComplex& from, const SkinComplex& to, const std::vector<char>& flags) {
  const auto neighbours_flagged = [&flags](const SkinComplex& c, size_t ball) {
    const int cell = c.vertex_cell(static_cast<int>(ball));
    if (cell < 0) return true;
    for (auto it = c.cofaces_begin(cell); it != c.cofaces_end(cell); ++it)
      if (!flags[static_cast<size_t>(it->ball)]) return false;
    return true;
  };
  std::vector<char> out(flags.size(), 0);
  for (size_t b = 0; b < out.size(); ++b) out[b] = flags[b] && neighbours_flagged(from, b) && neighbours_flagged(to, b);
  return out;
}

// Per ball, whether the step left its mixed cells as they were: it and
// every neighbour it has before or after the step kept centre and weight
// exactly. The Voronoi face nu_X of a simplex X of such balls is the
// intersection of the power halfspaces of X's neighbours against X, all of
// them balls that stayed, so it is the same set before and after (and X a
// simplex of both); so are its mixed cell (1-s) delta_X + s nu_X and the
// skin's patch in it (docs/math.md section 3).
std::vector<char> quiet_balls(const SkinComplex& from, const SkinComplex& to) {
  const std::vector<Ball>& before = from.balls();
  const std::vector<Ball>& after = to.balls();
  std::vector<char> stayed(before.size(), 0);
  for (size_t b = 0; b < stayed.size(); ++b)
    stayed[b] = before[b].center == after[b].center && before[b].weight == after[b].weight;
  return with_all_neighbours(from, to, stayed);
}

// Per ball, whether it and its neighbours in the regular triangulation of
// `from` moved in the step as one rigid body (to kRigid Angstrom), radii
// kept: by the ball's neighbourhood rotation and its own translation. A
// ball that stayed moved rigidly. Hidden balls: no.
std::vector<char> rigidly_moved_balls(const SkinComplex& from, const std::vector<Ball>& to,
                                      const std::vector<Eigen::Matrix3d>& rotations) {
  constexpr double kRigid = 1e-9;
  const std::vector<Ball>& old = from.balls();
  std::vector<char> rigid(old.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, old.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t b = r.begin(); b != r.end(); ++b) {
      const int cell = from.vertex_cell(static_cast<int>(b));
      if (cell < 0 || old[b].weight != to[b].weight) continue;
      const auto carried = [&](int i) {
        const size_t k = static_cast<size_t>(i);
        const Eigen::Vector3d expected = to[b].center + rotations[b] * (old[k].center - old[b].center);
        return old[k].weight == to[k].weight && (to[k].center - expected).norm() <= kRigid;
      };
      bool all = true;
      for (auto c = from.cofaces_begin(cell); all && c != from.cofaces_end(cell); ++c)
        if (!c->beyond) all = carried(c->ball);
      rigid[b] = all;
    }
  });
  return rigid;
}

// The rigid motion that carried the most balls that moved in the step (to
// 1e-9 A, radii kept), from the neighbourhood rotation of each of the first
// few balls of `rigid` that moved and no motion tried before carried; none
// when no ball that moved did so rigidly.
std::optional<detail::RigidMotion> largest_rigid_motion(const std::vector<Ball>& old, const std::vector<Ball>& now,
                                                        const std::vector<char>& rigid,
                                                        const std::vector<Eigen::Matrix3d>& rotations) {
  constexpr int kMotionsTried = 4;
  std::optional<detail::RigidMotion> best;
  long most = 0;
  std::vector<char> carried(old.size(), 0);  // by a motion tried
  int tried = 0;
  for (size_t b = 0; b < old.size() && tried < kMotionsTried; ++b) {
    if (!rigid[b] || carried[b] || old[b].center == now[b].center) continue;
    ++tried;
    const detail::RigidMotion motion{rotations[b], now[b].center - rotations[b] * old[b].center};
    long count = 0;
    for (size_t k = 0; k < old.size(); ++k)
      if (motion.carries(old[k], now[k])) {
        ++count;
        carried[k] = 1;
      }
    if (count > most) {
      best = motion;
      most = count;
    }
  }
  return best;
}

bool cell_of_flagged_balls(const MixedCell& cell, const std::vector<char>& flags) {
  for (int i = 0; i <= cell.dim; ++i)
    if (!flags[static_cast<size_t>(cell.balls[static_cast<size_t>(i)])]) return false;
  return true;
}

// Per vertex of `moved` (the transported `before`), whether it stayed on its
// cell's path and moved by `motion` (to 1e-9 A), in a cell not all of whose
// balls are `carried_balls` (those vertices are carried by their rings).
std::vector<char> moved_by(const detail::RigidMotion& motion, const SkinComplex& next, const SurfaceMesh& before,
                           const SurfaceMesh& moved, const std::vector<VertexFate>& fates,
                           const std::vector<char>& carried_balls) {
  std::vector<char> out(moved.vertices.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      out[v] = stayed_put(fates[v]) && !cell_of_flagged_balls(next.cell(moved.cells[v]), carried_balls) &&
               (motion(before.vertices[v]) - moved.vertices[v]).norm() <= 1e-9;
  });
  return out;
}

// Per vertex of a transported step, what the step before settled there:
// `verdict` what the judge may take from the step before (the skin around
// the vertex as it was, or moved as one rigid body: judge.hpp), `thinning`
// where thinning would decide as it did (its cell's balls and their
// neighbours moved as one rigid body: mend_by_edits' `still`).
struct Settled {
  detail::KnownVerdicts verdict;
  std::vector<char> thinning;
};

// Where a vertex was before a step, and the largest move of its cell's
// balls in the step (Angstrom). It may move that far plus `continuity`
// times its longest mesh edge before the step and keep its id.
struct Continuity {
  Eigen::Vector3d from;
  double balls_moved = 0;
};

// Per vertex id below `next_id` (ids are handed out in order), its index in
// `ids`, or -1: a look-up without a hash map of every vertex.
std::vector<int> vertex_of_id(const std::vector<long>& ids, long next_id) {
  std::vector<int> index(static_cast<size_t>(next_id), -1);
  for (size_t v = 0; v < ids.size(); ++v) index[static_cast<size_t>(ids[v])] = static_cast<int>(v);
  return index;
}

int vertex_with_id(const std::vector<int>& index, long id) {
  return id >= 0 && id < static_cast<long>(index.size()) ? index[static_cast<size_t>(id)] : -1;
}

std::vector<Continuity> continuity_starts(const SkinComplex& from, const SkinComplex& to, const SurfaceMesh& mesh) {
  std::vector<double> ball_moved(from.balls().size());
  for (size_t b = 0; b < ball_moved.size(); ++b) ball_moved[b] = ball_move(from.balls()[b], to.balls()[b]);
  std::vector<Continuity> out(mesh.vertices.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const MixedCell& cell = from.cell(mesh.cells[v]);
      double balls_moved = 0;
      for (int i = 0; i <= cell.dim; ++i)
        balls_moved = std::max(balls_moved, ball_moved[static_cast<size_t>(cell.balls[static_cast<size_t>(i)])]);
      out[v] = {mesh.vertices[v], balls_moved};
    }
  });
  return out;
}

// Per vertex of the mesh before the step marked in `wanted`, its longest
// edge among `triangles` (Angstrom; 0 for the others): only the few
// vertices that moved farther than their balls need it, so it is not
// worked out for every vertex.
std::vector<double> longest_edges_of(const std::vector<Continuity>& before,
                                     const std::vector<std::array<int, 3>>& triangles, const std::vector<char>& wanted) {
  std::vector<double> longest(before.size(), 0.0);
  for (const auto& t : triangles)
    for (size_t k = 0; k < 3; ++k) {
      const auto a = static_cast<size_t>(t[k]), b = static_cast<size_t>(t[(k + 1) % 3]);
      if (!wanted[a] && !wanted[b]) continue;
      const double length = (before[a].from - before[b].from).norm();
      longest[a] = std::max(longest[a], length);
      longest[b] = std::max(longest[b], length);
    }
  return longest;
}

// Per vertex of `mesh` (ids `ids`), whether it moved in the step farther
// than its bound (Continuity) from where its id was before: first against
// its balls' move alone (in parallel), then, for the few past that, with
// `continuity` times its longest edge before the step added.
std::vector<char> jumped_vertices(const SurfaceMesh& mesh, const std::vector<long>& ids,
                                  const std::vector<Continuity>& before,
                                  const std::vector<std::array<int, 3>>& triangles_before,
                                  const std::vector<int>& index_before, double continuity) {
  std::vector<char> jumped(ids.size(), 0), wanted(before.size(), 0);
  std::vector<double> moved(ids.size(), 0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, ids.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const int found = vertex_with_id(index_before, ids[v]);
      if (found < 0) continue;
      const Continuity& c = before[static_cast<size_t>(found)];
      moved[v] = (mesh.vertices[v] - c.from).norm();
      wanted[static_cast<size_t>(found)] = moved[v] > c.balls_moved;  // ids are unique: one writer each
    }
  });
  if (std::find(wanted.begin(), wanted.end(), 1) == wanted.end()) return jumped;
  const std::vector<double> longest = longest_edges_of(before, triangles_before, wanted);
  for (size_t v = 0; v < ids.size(); ++v) {
    const int found = vertex_with_id(index_before, ids[v]);
    if (found < 0 || !wanted[static_cast<size_t>(found)]) continue;
    const Continuity& c = before[static_cast<size_t>(found)];
    jumped[v] = moved[v] > c.balls_moved + continuity * longest[static_cast<size_t>(found)];
  }
  return jumped;
}

// How the vertices of one cell of the step before move (docs/math.md
// section 6), worked out once per cell, not once per vertex: the cell it
// persists as (-1: gone); whether its balls are all quiet (its vertices
// stay); else, where it persists with a size of the same sign and is not
// flat, its exact map x -> to_center + scale turn (x - from_center).
struct CellMap {
  int persisting = -1;
  bool quiet = false;
  bool mapped = false;
  bool still = false;  // mapped, and none of its balls moved: its vertices stay where they are
  Eigen::Vector3d from_center = Eigen::Vector3d::Zero(), to_center = Eigen::Vector3d::Zero();
  Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
  double scale = 1;
};

// The maps of the cells of `from` that vertices lie in, one per such cell:
// a frame's vertices lie in a fraction of the cells, and a map for every
// cell of the complex is megabytes to fill every step on 3,000 atoms.
struct CellMaps {
  std::vector<int> slot;  // per cell of `from`: its map in `maps`, or -1
  std::vector<CellMap> maps;
  const CellMap& of(int cell) const { return maps[static_cast<size_t>(slot[static_cast<size_t>(cell)])]; }
};

CellMaps cell_maps(const SkinComplex& from, const SkinComplex& to, const std::vector<Eigen::Matrix3d>& rotations,
                   const std::vector<char>& quiet, const std::optional<detail::RigidMotion>& motion,
                   const std::vector<int>& cells) {
  CellMaps out;
  out.slot.assign(from.cells().size(), -1);
  std::vector<int> used;  // the cells with a vertex, ascending
  for (int c : cells) out.slot[static_cast<size_t>(c)] = 0;
  for (size_t c = 0; c < out.slot.size(); ++c)
    if (out.slot[c] == 0) {
      out.slot[c] = static_cast<int>(used.size());
      used.push_back(static_cast<int>(c));
    }
  out.maps.resize(used.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, used.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const auto c = static_cast<size_t>(used[k]);
      CellMap& m = out.maps[k];
      const MixedCell& c0 = from.cell(static_cast<int>(c));
      m.persisting = to.find_cell(c0.balls);
      if (m.persisting < 0) continue;
      m.quiet = cell_of_flagged_balls(c0, quiet);
      if (m.quiet) continue;  // its vertices stay where they are (move_vertex)
      const MixedCell& c1 = to.cell(m.persisting);
      const double ratio = c1.R2 / c0.R2;
      m.mapped = !c0.degenerate && !c1.degenerate && c0.dim == c1.dim && c0.R2 != 0 && ratio > 0;
      if (!m.mapped) continue;
      m.from_center = c0.center;
      m.to_center = c1.center;
      m.scale = std::sqrt(ratio);
      // A cell whose balls all stayed keeps its patch: its vertices stay put
      // rather than turn with their neighbourhood, so that the judge can find
      // their triangles settled (skin_unchanged_near). One whose balls the
      // step's largest rigid motion carried turns with that motion, so that
      // its vertices move by it and their triangles can be carried.
      const auto all_balls = [&](auto&& test) {
        for (int i = 0; i <= c0.dim; ++i)
          if (!test(static_cast<size_t>(c0.balls[static_cast<size_t>(i)]))) return false;
        return true;
      };
      m.still = all_balls([&](size_t b) {
        return from.balls()[b].center == to.balls()[b].center && from.balls()[b].weight == to.balls()[b].weight;
      });
      if (m.still) continue;
      const bool carried =
          motion && all_balls([&](size_t b) { return motion->carries(from.balls()[b], to.balls()[b]); });
      const Eigen::Matrix3d& start = carried ? motion->rotation : rotations[static_cast<size_t>(c0.balls[0])];
      m.turn = cell_rotation(c0, from.balls(), to.balls(), start);
    }
  });
  return out;
}

// One vertex from the skin of `from` onto the skin of `to`: by its cell's
// map where the cell persists with a size of the same sign, else projected
// from where its owning ball took it.
VertexFate move_vertex(const SkinComplex& from, const SkinComplex& to, const CellMap& map, Eigen::Vector3d& p,
                       int& cell) {
  if (map.persisting >= 0 && map.quiet) {
    cell = map.persisting;
    return VertexFate::kept;
  }
  if (map.mapped) {
    const Eigen::Vector3d q =
        map.still ? p : Eigen::Vector3d(map.to_center + map.scale * (map.turn * (p - map.from_center)));
    constexpr double kOnBoundary = 1e-9;  // Angstrom-scaled membership slack (rounding on a cell face)
    if (to.membership_violation(map.persisting, q) <= kOnBoundary) {
      p = q;
      cell = map.persisting;
      return VertexFate::moved;
    }
    const Projection projected = to.project(q, map.persisting, 1e-14);
    if (!projected.converged) return VertexFate::lost;
    p = projected.point;
    cell = projected.cell;
    return VertexFate::relocated;
  }
  const int owner = from.owning_ball(p, cell);
  const Eigen::Vector3d start =
      p + (to.balls()[static_cast<size_t>(owner)].center - from.balls()[static_cast<size_t>(owner)].center);
  const int hint = map.persisting >= 0 ? map.persisting : to.vertex_cell(owner);
  const Projection projected = to.project(start, hint, 1e-14);
  if (!projected.converged) {
    cell = to.locate(p, hint);  // a valid cell of the new complex for a vertex the remesh drops
    return VertexFate::lost;
  }
  p = projected.point;
  cell = projected.cell;
  return VertexFate::relocated;
}

// The critical cells inside the body: z_X lies in its own mixed cell and
// R2_X < 0. By discrete Morse theory on the alpha filtration they alone
// make the body's homotopy type, each adding (-1)^dim to its Euler
// characteristic (Edelsbrunner 1999; docs/math.md section 6). Keyed by
// ball tuple.
std::vector<int> inside_critical_cells(const SkinComplex& complex) {
  std::vector<char> critical(complex.cells().size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, critical.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t c = r.begin(); c != r.end(); ++c) {
      const MixedCell& cell = complex.cells()[c];
      critical[c] = !cell.degenerate && cell.R2 < 0 &&
                    complex.membership_violation(static_cast<int>(c), cell.center) <= 0;
    }
  });
  std::vector<int> out;
  for (size_t c = 0; c < critical.size(); ++c)
    if (critical[c]) out.push_back(static_cast<int>(c));
  return out;
}

// What a step's two complexes, `from` before it and `to` after, say of its
// balls before any vertex moves (step): computed beside the step before
// when `to` is built ahead (build_ahead), so that the step starts with them.
struct StepBalls {
  // The places of the step's topology changes (topology_changes,
  // keep_events), when found beside the step before: none where the two
  // complexes' topologies are the same.
  struct Events {
    std::vector<detail::TopologyChange> changes;
    std::vector<detail::VanishingSphere> vanished;
  };
  std::optional<Events> events;
  std::vector<int> critical;                   // inside_critical_cells(to)
  std::vector<Eigen::Matrix3d> rotations;      // neighbourhood_rotations
  std::vector<char> quiet, rigid;              // quiet_balls, rigidly_moved_balls
  std::optional<detail::RigidMotion> largest;  // largest_rigid_motion
  std::vector<char> settled, carried;          // with_all_neighbours of `quiet` and of `rigid`
};

StepBalls step_balls(const SkinComplex& from, const SkinComplex& to) {
  StepBalls b;
  b.critical = inside_critical_cells(to);
  b.rotations = neighbourhood_rotations(from, to.balls());
  b.quiet = quiet_balls(from, to);
  b.rigid = rigidly_moved_balls(from, to.balls(), b.rotations);
  b.largest = largest_rigid_motion(from.balls(), to.balls(), b.rigid, b.rotations);
  b.settled = with_all_neighbours(from, to, b.quiet);
  b.carried = with_all_neighbours(from, to, b.rigid);
  return b;
}

// The cells of `cells` (inside critical cells of `of`) whose ball tuple is
// not an inside critical cell of `other`: each looked up by its tuple in
// `other`'s table (SkinComplex::find_cell).
std::vector<int> critical_only_in(const SkinComplex& of, const std::vector<int>& cells, const SkinComplex& other,
                                  const std::vector<int>& other_cells) {
  std::vector<char> critical(other.cells().size(), 0);
  for (int c : other_cells) critical[static_cast<size_t>(c)] = 1;
  std::vector<int> out;
  for (int c : cells) {
    const int there = other.find_cell(of.cell(c).balls);
    if (there < 0 || !critical[static_cast<size_t>(there)]) out.push_back(c);
  }
  return out;
}

// Where the skin's topology changed in the step, as places the local
// repair must remesh (local_repair.hpp): the inside critical cells of one
// side that the other lacks, less the pairs a flip only renamed (same
// dimension, centres within 0.05 A). A vertex cell that became one is a
// component born, a tetrahedron that stopped being one a void born: both
// seeded. A tetrahedron that became one (a void filled) or a vertex cell
// that stopped (a component gone) is listed in `vanished`, at its place
// in the step before: its component is dropped before the repair
// (vanishing.hpp). When the counts did not change (`same_topology`), the
// places are pairs of critical points that cancel: no birth, nothing vanished.
void topology_changes(const SkinComplex& from, const std::vector<int>& from_critical, const SkinComplex& to,
                      const std::vector<int>& to_critical, bool same_topology, detail::LocalRepairOptions& local,
                      std::vector<detail::VanishingSphere>& vanished) {
  std::vector<const MixedCell*> gone, came;
  const std::vector<int> came_index = critical_only_in(to, to_critical, from, from_critical);
  for (int c : critical_only_in(from, from_critical, to, to_critical)) gone.push_back(&from.cell(c));
  for (int c : came_index) came.push_back(&to.cell(c));
  // A k-cell and a (k+1)-cell having it as a face that appear (or go)
  // together are a cancelling pair of critical points: no change.
  const auto is_face = [](const MixedCell& f, const MixedCell& c) {
    if (c.dim != f.dim + 1) return false;
    for (int i = 0; i <= f.dim; ++i)
      if (std::find(c.balls.begin(), c.balls.begin() + c.dim + 1, f.balls[static_cast<size_t>(i)]) ==
          c.balls.begin() + c.dim + 1)
        return false;
    return true;
  };
  const auto cancel_pairs = [&](std::vector<const MixedCell*>& cells, std::vector<char>& out) {
    for (size_t i = 0; i < cells.size(); ++i)
      for (size_t j = 0; j < cells.size() && !out[i]; ++j)
        if (!out[j] && i != j && (is_face(*cells[i], *cells[j]) || is_face(*cells[j], *cells[i]))) out[i] = out[j] = 1;
  };
  std::vector<char> renamed(came.size(), 0), gone_out(gone.size(), 0);
  cancel_pairs(came, renamed);
  cancel_pairs(gone, gone_out);
  std::vector<const MixedCell*> really_gone;
  for (size_t i = 0; i < gone.size(); ++i) {
    const MixedCell* g = gone[i];
    bool paired = gone_out[i];
    for (size_t k = 0; k < came.size() && !paired; ++k)
      if (!renamed[k] && came[k]->dim == g->dim && (came[k]->center - g->center).norm() < 0.05) {
        renamed[k] = 1;
        paired = true;
      }
    if (!paired) really_gone.push_back(g);
  }
  // euler: the change of the skin's Euler characteristic, +-2 (-1)^dim for
  // a critical cell that came or went; neck: the cell in `to` (dimension 1 or 2).
  const auto place = [&](const MixedCell& cell, int index, bool birth, int euler, int neck) {
    detail::TopologyChange change;
    change.point = cell.center;
    change.size = std::sqrt(std::abs(cell.R2));
    change.radius = 1.0 + 2 * change.size;
    change.birth = birth;
    change.cell = index;
    change.dim = cell.dim;
    change.euler_change = same_topology ? 0 : euler;
    change.neck_cell = cell.dim == 1 || cell.dim == 2 ? neck : -1;
    local.changes.push_back(change);
  };
  for (size_t k = 0; k < came.size(); ++k) {
    if (renamed[k]) continue;
    const MixedCell& cell = *came[k];
    const int euler = cell.dim % 2 ? -2 : 2;
    if (same_topology) place(cell, came_index[k], false, 0, -1);  // a pair of critical points that cancel
    else if (cell.dim == 3) vanished.push_back({cell.center, 1.0 + 2 * std::sqrt(std::abs(cell.R2))});
    else place(cell, came_index[k], cell.dim == 0, euler, came_index[k]);
  }
  for (const MixedCell* g : really_gone) {
    if (same_topology) {
      place(*g, -1, false, 0, -1);
      continue;
    }
    if (g->dim == 0) {
      vanished.push_back({g->center, 1.0 + 2 * std::sqrt(std::abs(g->R2))});
      continue;
    }
    const int now = g->dim == 3 ? to.find_cell(g->balls) : -1;
    place(now >= 0 ? to.cell(now) : *g, now, now >= 0, g->dim % 2 ? 2 : -2, to.find_cell(g->balls));
  }
}

// Of the places topology_changes found, those where a size can have
// crossed zero in the step: |R2| at most 4 r dz + dz^2, dz the largest ball
// move of the step and r the largest ball radius (R2 = |z - z_i|^2 - w_i
// moves by no more). A critical cell that came or went with a larger size
// did so by a flip or a cancelling pair, which changes no topology. When
// none is that small, all are kept.
void keep_events(const SkinComplex& from, const SkinComplex& to, detail::LocalRepairOptions& local,
                 std::vector<detail::VanishingSphere>& vanished) {
  double dz = 0, r = 0;
  for (size_t i = 0; i < to.balls().size(); ++i) {
    dz = std::max(dz, ball_move(from.balls()[i], to.balls()[i]));
    r = std::max(r, radius_of(to.balls()[i]));
  }
  const double bound = 4 * r * dz + dz * dz;
  std::vector<detail::TopologyChange> changes;
  std::vector<detail::VanishingSphere> spheres;
  for (const auto& c : local.changes)
    if (c.size * c.size <= bound) changes.push_back(c);
  for (const auto& v : vanished)
    if ((v.reach - 1) * (v.reach - 1) / 4 <= bound) spheres.push_back(v);
  if (changes.empty() && spheres.empty()) return;
  local.changes = std::move(changes);
  vanished = std::move(spheres);
}

MeshingOptions with_size_margin(MeshingOptions o, double margin) {
  o.sizing.epsilon *= margin;
  o.edge_length *= margin;
  o.tolerance *= margin;
  return o;
}

// The complex builds with the skin's topology counted on its own regular
// triangulation (the certificate's count: exact predicates, independent of
// the mixed cells and their geometry, which the mesh follows).
SkinComplexOptions counting_topology(double shrink) {
  SkinComplexOptions options;
  options.shrink = shrink;
  options.count_topology = true;
  return options;
}

// The certificate's count for a complex's balls: the one counted at its
// build, else skin_topology's.
SkinTopology topology_of(const SkinComplex& complex) {
  return complex.topology() ? *complex.topology() : skin_topology(complex.balls());
}

void check_balls(const std::vector<Ball>& balls, const char* what) {
  for (const Ball& b : balls)
    if (!b.center.allFinite() || !std::isfinite(b.weight)) contract_error(std::string(what) + ": a ball is not finite");
}

}  // namespace

// The first internal step advance_to takes from `from` towards `to`: at
// most max_step for any ball (as advance_to divides the move).
std::vector<Ball> first_step(const std::vector<Ball>& from, const std::vector<Ball>& to, double max_step) {
  double farthest = 0;
  for (size_t i = 0; i < from.size(); ++i) farthest = std::max(farthest, ball_move(from[i], to[i]));
  const long steps = std::max(1L, static_cast<long>(std::ceil(farthest / max_step)));
  return steps == 1 ? to : balls_between(from, to, 1.0 / static_cast<double>(steps));
}

bool same_balls(const std::vector<Ball>& a, const std::vector<Ball>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](const Ball& x, const Ball& y) { return x.center == y.center && x.weight == y.weight; });
}

// The engine's state and its steps: MovingBalls' public calls forward here.
struct MovingBalls::Impl {
  Impl(std::vector<Ball> balls, const MovingOptions& options, double t);
  ~Impl() { forget_ahead(); }
  const MorphFrame& advance_to(std::vector<Ball> balls, double t, const std::vector<Ball>& next);
  void step(std::vector<Ball> balls, const std::vector<Ball>* after);
  void build_ahead(const SkinComplex& now, const SkinTopology& now_topology, const std::vector<int>& now_critical);
  bool take_ahead(const std::vector<Ball>& balls, std::optional<SkinComplex>& complex, SkinTopology& topology,
                  std::optional<StepBalls>& step_balls);
  void finish_ahead();
  void forget_ahead();
  void repair(const SkinComplex& next, const SkinTopology& topology, const std::vector<int>& critical,
              SurfaceMesh& moved, std::vector<char>& lost, const std::vector<char>& stayed, Settled settled);
  std::vector<char> judge_and_relax(const SkinComplex& next, SurfaceMesh& moved, Settled& settled);
  std::string mend_locally(const SkinComplex& next, const SkinTopology& topology, const std::vector<int>& critical,
                           SurfaceMesh& moved, std::vector<char>& lost, const std::vector<char>& stayed,
                           Settled settled, detail::LocalRepairOptions& local);
  bool drop_vanished(const std::vector<detail::VanishingSphere>& vanished, const std::vector<char>& stayed,
                     SurfaceMesh& moved, std::vector<char>& lost, Settled& settled, long& euler_change);
  bool merge_lost(SurfaceMesh& moved, std::vector<char>& lost, Settled& settled);
  struct Unmended;
  bool mend_by_surgery(const SkinComplex& next, SurfaceMesh& moved, std::vector<char>& failing, Settled& settled,
                       detail::LocalRepairOptions& local, Unmended& before);
  std::string edit_and_patch(const SkinComplex& next, const SkinTopology& topology, SurfaceMesh& moved,
                             std::vector<char>& lost, std::vector<char>& failing, Settled& settled,
                             detail::LocalRepairOptions& local);
  // What mend_locally had before a surgery, to mend the frame again without it.
  struct Unmended {
    SurfaceMesh mesh;
    std::vector<char> failing;
    std::vector<long> ids;
    long next_id = 0;
    std::vector<char> thinning;
    detail::LocalRepairOptions local;
  };
  void keep_vertices(const std::vector<int>& kept_from, std::vector<char>& lost, Settled& settled);
  bool remesh(const SkinComplex& next, const SurfaceMesh& moved, std::vector<char>& drop, const MeshingOptions& criteria,
              const std::vector<SkinSample>& seeds);
  MeshingOptions repair_criteria() const { return options_.frames; }

  MovingOptions options_;
  SkinComplex complex_;
  long generation_ = 0;  // how many times complex_ was replaced
  std::optional<StepBalls::Events> events_;  // of the step being made, when found with its complex built ahead
  SkinTopology topology_;
  std::vector<int> critical_;  // cells of complex_ that are critical points inside the body (moving_balls.cpp)
  MorphFrame frame_;
  long next_id_ = 0;
  detail::RefusedEdges refused_thinning_;
  std::function<void(SurfaceMesh&, std::vector<long>&)> certificate_fault_;  // tests only: none
  // The last step ended with every triangle of the frame judged passing
  // (mended locally, or nothing to mend), not remeshed: the settled
  // triangles of the next step keep that verdict (step).
  bool all_passed_ = false;
  // The complex and topology of the next internal step, built beside this
  // step's repair when its balls are known (build_ahead).
  struct Ahead {
    std::vector<Ball> balls;
    std::optional<SkinComplex> complex;
    SkinTopology topology;
    std::optional<StepBalls> step;  // from the complex of complex_'s generation `from`
    long from = -1;
  };
  Ahead ahead_;
  tbb::task_group building_ahead_;
  // The balls of the step after this one, when known, until build_ahead starts on them.
  std::optional<std::vector<Ball>> after_;
};

// Starts building the next step's complex (after_), if known and not
// started: once the step's judging is done, whose parallel passes it would
// slow, so that it runs beside the mostly serial edits and patch. With it
// what it and `now`, the complex the step ends with, say of the balls
// (StepBalls) and, when the topologies differ, where it changes between
// them; `now` is read until finish_ahead, `now_critical` (its inside
// critical cells) is copied: the step's own list can go first when an
// exception unwinds the step.
void MovingBalls::Impl::build_ahead(const SkinComplex& now, const SkinTopology& now_topology,
                                    const std::vector<int>& now_critical) {
  if (!after_) return;
  forget_ahead();
  ahead_.balls = std::move(*after_);
  after_.reset();
  ahead_.from = generation_ + 1;  // the step ends with complex_ = now
  building_ahead_.run([this, &now, now_topology, now_critical] {
    ahead_.complex.emplace(build_skin_complex(ahead_.balls, counting_topology(options_.shrink)));
    ahead_.topology = topology_of(*ahead_.complex);
    StepBalls& step = ahead_.step.emplace(step_balls(now, *ahead_.complex));
    StepBalls::Events& events = step.events.emplace();
    if (ahead_.topology == now_topology) return;
    detail::LocalRepairOptions found;
    topology_changes(now, now_critical, *ahead_.complex, step.critical, false, found, events.vanished);
    keep_events(now, *ahead_.complex, found, events.vanished);
    events.changes = std::move(found.changes);
  });
}

// The complex built ahead, when it was built for exactly `balls`; false
// (and none kept) otherwise, or when its building failed.
bool MovingBalls::Impl::take_ahead(const std::vector<Ball>& balls, std::optional<SkinComplex>& complex,
                                   SkinTopology& topology, std::optional<StepBalls>& step_balls) {
  finish_ahead();
  const bool same = ahead_.complex.has_value() && same_balls(ahead_.balls, balls);
  if (same) {
    complex = std::move(ahead_.complex);
    topology = ahead_.topology;
    if (ahead_.from == generation_) step_balls = std::move(ahead_.step);
  }
  ahead_ = Ahead{};
  return same;
}

// Waits for the building ahead; when it failed, nothing built ahead is
// kept (the step builds its own complex and reports what fails there).
void MovingBalls::Impl::finish_ahead() {
  try {
    building_ahead_.wait();
  } catch (...) {
    ahead_.complex.reset();
  }
}

void MovingBalls::Impl::forget_ahead() {
  finish_ahead();
  ahead_ = Ahead{};
}

MovingBalls::Impl::Impl(std::vector<Ball> balls, const MovingOptions& options, double t) : options_(options) {
  if (balls.empty()) contract_error("MovingBalls: the ball set is empty");
  check_balls(balls, "MovingBalls");
  if (!(options.max_step > 0) || !(options.continuity >= 0))
    contract_error("MovingBalls: max_step must be positive and continuity non-negative");
  const auto start = Clock::now();
  complex_ = build_skin_complex(std::move(balls), counting_topology(options.shrink));
  topology_ = topology_of(complex_);
  critical_ = inside_critical_cells(complex_);
  frame_.stats.seconds_complex = seconds_since(start);
  const auto mesh_start = Clock::now();
  SkinMeshResult made = mesh_skin(complex_, with_size_margin(options.first, options.first_size_margin));
  if (made.status != MeshingStatus::ok) throw MeshingFailed(made.status, "moving balls, first frame: " + made.message);
  frame_.mesh = std::move(made.mesh);
  frame_.ids.resize(frame_.mesh.vertices.size());
  std::iota(frame_.ids.begin(), frame_.ids.end(), 0L);
  next_id_ = static_cast<long>(frame_.ids.size());
  FrameStats& s = frame_.stats;
  s.t = t;
  s.full_rebuild = true;
  s.inserted = static_cast<long>(frame_.mesh.vertices.size());
  s.vertices = s.inserted;
  s.triangles = static_cast<long>(frame_.mesh.triangles.size());
  s.seconds_repair = seconds_since(mesh_start);
  s.topology_certified = mesh_topology(frame_.mesh) == topology_;
  if (!s.topology_certified)
    throw Error("moving balls, first frame: the mesh has " + mesh_topology(frame_.mesh).text() + ", the skin " +
                topology_.text());
  s.seconds = seconds_since(start);
}

MovingBalls::MovingBalls(std::vector<Ball> balls, const MovingOptions& options, double t)
    : impl_(std::make_unique<Impl>(std::move(balls), options, t)) {}
MovingBalls::MovingBalls(MovingBalls&&) noexcept = default;
MovingBalls& MovingBalls::operator=(MovingBalls&&) noexcept = default;
MovingBalls::~MovingBalls() = default;

const MorphFrame& MovingBalls::advance_to(std::vector<Ball> balls, double t) {
  return impl_->advance_to(std::move(balls), t, {});
}
const MorphFrame& MovingBalls::advance_to(std::vector<Ball> balls, double t, std::vector<Ball> next) {
  return impl_->advance_to(std::move(balls), t, next);
}
const MorphFrame& MovingBalls::frame() const { return impl_->frame_; }
const SkinComplex& MovingBalls::complex() const { return impl_->complex_; }
const std::vector<Ball>& MovingBalls::balls() const { return impl_->complex_.balls(); }
const SkinTopology& MovingBalls::topology() const { return impl_->topology_; }

const MorphFrame& MovingBalls::advance_to(const std::vector<Eigen::Vector3d>& centres, double t) {
  std::vector<Ball> balls = impl_->complex_.balls();
  if (centres.size() != balls.size()) contract_error("MovingBalls::advance_to: the number of centres differs");
  for (size_t i = 0; i < balls.size(); ++i) balls[i].center = centres[i];
  return impl_->advance_to(std::move(balls), t, {});
}

const MorphFrame& MovingBalls::Impl::advance_to(std::vector<Ball> balls, double t, const std::vector<Ball>& next) {
  const std::vector<Ball> from = complex_.balls();
  if (balls.size() != from.size()) contract_error("MovingBalls::advance_to: the number of balls differs");
  check_balls(balls, "MovingBalls::advance_to");
  const auto start = Clock::now();
  const std::vector<Eigen::Vector3d> before = frame_.mesh.vertices;  // the frame before
  const std::vector<int> was = vertex_of_id(frame_.ids, next_id_);
  double farthest = 0;
  for (size_t i = 0; i < from.size(); ++i) farthest = std::max(farthest, ball_move(from[i], balls[i]));
  const long steps = std::max(1L, static_cast<long>(std::ceil(farthest / options_.max_step)));
  frame_.stats = FrameStats{};
  frame_.stats.t = t;
  // Each step is told the balls of the step after it, when they are known.
  const auto at = [&](long k) {
    return k == steps ? balls : balls_between(from, balls, static_cast<double>(k) / static_cast<double>(steps));
  };
  bool next_usable = next.size() == balls.size();
  for (const Ball& b : next) next_usable = next_usable && b.center.allFinite() && std::isfinite(b.weight);
  for (long k = 1; k <= steps; ++k) {
    std::vector<Ball> after;
    if (k < steps) after = at(k + 1);
    else if (next_usable) after = first_step(balls, next, options_.max_step);
    step(at(k), after.empty() ? nullptr : &after);
  }
  finish_ahead();  // inside the call, so that the frame's seconds hold all its work
  FrameStats& s = frame_.stats;
  s.steps = steps;
  // Each kept vertex's move (-1: a new id), in parallel; then counted.
  std::vector<double> kept_move(frame_.ids.size(), -1.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, kept_move.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const int found = vertex_with_id(was, frame_.ids[v]);
      if (found >= 0) kept_move[v] = (frame_.mesh.vertices[v] - before[static_cast<size_t>(found)]).norm();
    }
  });
  long kept = 0;
  for (double move : kept_move)
    if (move >= 0) {
      ++kept;
      s.max_kept_move = std::max(s.max_kept_move, move);
    }
  s.vertices = static_cast<long>(frame_.mesh.vertices.size());
  s.triangles = static_cast<long>(frame_.mesh.triangles.size());
  s.ids_kept = s.vertices > 0 ? static_cast<double>(kept) / static_cast<double>(s.vertices) : 0.0;
  s.inserted = s.vertices - kept;
  s.removed = static_cast<long>(before.size()) - kept;
  s.seconds = seconds_since(start);
  return frame_;
}

std::vector<int> MovingBalls::vertex_balls() const {
  const MorphFrame& f = impl_->frame_;
  std::vector<int> owner(f.mesh.vertices.size());
  for (size_t v = 0; v < owner.size(); ++v) owner[v] = impl_->complex_.owning_ball(f.mesh.vertices[v], f.mesh.cells[v]);
  return owner;
}

// One internal step: the new complex, every vertex moved onto its skin,
// judged, mended and certified (moving_balls.hpp).
void MovingBalls::Impl::step(std::vector<Ball> balls, const std::vector<Ball>* after) {
  FrameStats& s = frame_.stats;
  auto stage = Clock::now();
  std::optional<SkinComplex> built;
  SkinTopology topology;
  std::optional<StepBalls> known;
  const bool counted = take_ahead(balls, built, topology, known);
  s.built_ahead += counted;
  if (!built) built.emplace(build_skin_complex(std::move(balls), counting_topology(options_.shrink)));
  SkinComplex next = std::move(*built);
  // The complex built ahead reads `next` (build_ahead): done before `next` goes.
  struct Finish {
    Impl& impl;
    ~Finish() { impl.finish_ahead(); }
  } finish{*this};
  // The certificate's count comes with the complex; where the complex could
  // not count it (a flat triangulation), skin_topology runs beside the rest
  // of the step and is waited for before the repair.
  tbb::task_group counting;
  if (!counted && next.topology()) topology = *next.topology();
  else if (!counted) counting.run([&] { topology = skin_topology(next.balls()); });
  if (!known) known = step_balls(complex_, next);
  events_ = std::move(known->events);
  std::vector<int> critical = std::move(known->critical);
  const std::vector<Eigen::Matrix3d>& rotations = known->rotations;
  const std::vector<char>& quiet = known->quiet;
  s.seconds_complex += seconds_since(stage);
  stage = Clock::now();
  SurfaceMesh moved = frame_.mesh;
  const std::vector<Continuity> reach = continuity_starts(complex_, next, moved);
  const std::vector<std::array<int, 3>> triangles_before = moved.triangles;  // as they were: the repair changes them
  const size_t n = moved.vertices.size();
  std::vector<VertexFate> fates(n);
  // Balls whose neighbourhood moved as one rigid body. The largest such
  // motion turns the cells it carried whole (cell_maps); thinning decides as
  // it did where the cells around a vertex moved so: the same edge lengths,
  // targets and fans.
  const std::vector<char>& rigid_balls = known->rigid;
  const std::optional<detail::RigidMotion>& largest = known->largest;
  const CellMaps maps = cell_maps(complex_, next, rotations, quiet, largest, moved.cells);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      fates[v] = move_vertex(complex_, next, maps.of(moved.cells[v]), moved.vertices[v], moved.cells[v]);
      // The vertex lies in its cell now (its membership was tested, or the
      // projection ended there): its normal without locating it again.
      if (fates[v] == VertexFate::moved || fates[v] == VertexFate::relocated)
        moved.normals[v] = next.gradient(moved.cells[v], moved.vertices[v]).normalized();
    }
  });
  // A triangle whose corners all stayed in cells two rings of stillness
  // deep (with_all_neighbours of the quiet balls) sees the same skin around
  // it as before, so it keeps the verdict it had: it passed, when the step
  // before ended with every triangle judged passing.
  const std::vector<char>& settled_balls = known->settled;
  // The judge's counterpart: a triangle whose corners moved with cells two
  // rings of rigid motion deep sees a congruent skin (judge.hpp).
  const std::vector<char>& carried_balls = known->carried;
  std::vector<char> lost(n, 0), stayed(n, 0);
  // A vertex that stayed where the skin within the judge's reach of it is
  // proven the same function (skin_unchanged_near) is settled as well:
  // atoms that moved nearby but stay inactive there do not unsettle it.
  std::vector<char> unproven(n, 0);  // stayed exactly where it was, not settled by its rings
  if (all_passed_)
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t v = r.begin(); v != r.end(); ++v)
        unproven[v] = stayed_put(fates[v]) && moved.vertices[v] == frame_.mesh.vertices[v] &&
                      !(fates[v] == VertexFate::kept && cell_of_flagged_balls(next.cell(moved.cells[v]), settled_balls));
    });
  // A vertex the step's largest rigid motion carried, not carried by its
  // rings, whose skin within the judge's reach that motion carried as well
  // (balls_moving_with) is carried though atoms nearby moved otherwise.
  const std::optional<detail::RigidMotion> motion = all_passed_ ? largest : std::nullopt;
  const std::vector<char> unproven_carried =
      motion ? moved_by(*motion, next, frame_.mesh, moved, fates, carried_balls) : std::vector<char>(n, 0);
  const bool any_unproven = std::find(unproven.begin(), unproven.end(), 1) != unproven.end();
  const bool any_carried = std::find(unproven_carried.begin(), unproven_carried.end(), 1) != unproven_carried.end();
  std::vector<char> either(n, 0);
  for (size_t v = 0; v < n; ++v) either[v] = unproven[v] || unproven_carried[v];
  const std::vector<double> reach_judged =
      any_unproven || any_carried ? detail::judged_reach(frame_.mesh, options_.frames.tolerance, either)
                                  : std::vector<double>(n, 0.0);
  const std::vector<char> unchanged =
      any_unproven ? detail::skin_unchanged_near(complex_, next.balls(), frame_.mesh, reach_judged, unproven) : unproven;
  const std::vector<char> carried_along =
      any_carried ? detail::skin_unchanged_near(complex_, detail::balls_moving_with(*motion, complex_.balls(), next.balls()),
                                                frame_.mesh, reach_judged, unproven_carried)
                  : unproven_carried;
  Settled settled;
  settled.verdict.settled.assign(n, 0);
  settled.verdict.carried.assign(n, 0);
  settled.thinning.assign(n, 0);
  std::vector<char> by_motion(n, 0);  // carried, not settled by rings of still atoms
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      lost[v] = fates[v] == VertexFate::lost;
      stayed[v] = stayed_put(fates[v]);
      const MixedCell& cell = next.cell(moved.cells[v]);
      const bool ring_settled =
          all_passed_ && fates[v] == VertexFate::kept && cell_of_flagged_balls(cell, settled_balls);
      settled.verdict.settled[v] = ring_settled || unchanged[v];
      // A vertex settled by its rings of still atoms is carried (by no motion) too.
      const bool carried = all_passed_ && stayed[v] && cell_of_flagged_balls(cell, carried_balls);
      settled.verdict.carried[v] = ring_settled || carried || carried_along[v];
      by_motion[v] = (carried || carried_along[v]) && !ring_settled;
      settled.thinning[v] = all_passed_ && stayed[v] && cell_of_flagged_balls(cell, rigid_balls);
    }
  });
  const bool carried_by_motion = std::find(by_motion.begin(), by_motion.end(), 1) != by_motion.end();
  s.moved += std::count(stayed.begin(), stayed.end(), 1);
  s.relocated += std::count(fates.begin(), fates.end(), VertexFate::relocated);
  s.lost += std::count(lost.begin(), lost.end(), 1);
  // The places before the step only where a vertex is carried by a motion
  // (KnownVerdicts::before): a triangle of ring-settled corners alone is settled.
  if (carried_by_motion) settled.verdict.before = frame_.mesh.vertices;
  const std::vector<int> index_before = vertex_of_id(frame_.ids, next_id_);  // a vertex id -> its index in `reach`
  s.seconds_transport += seconds_since(stage);
  stage = Clock::now();
  counting.wait();
  s.seconds_complex += seconds_since(stage);
  if (after && options_.build_ahead) after_ = *after;
  repair(next, topology, critical, moved, lost, stayed, std::move(settled));
  build_ahead(next, topology, critical);  // when the repair did not start it
  // Ids mean continuous motion (moving_balls.hpp): a vertex that
  // moved farther in the step than its bound, by transport, relaxation,
  // an edit or a remesh, is another point of the skin and takes a new id
  // (found in parallel, handed out in vertex order).
  const std::vector<char> jumped =
      jumped_vertices(frame_.mesh, frame_.ids, reach, triangles_before, index_before, options_.continuity);
  for (size_t v = 0; v < jumped.size(); ++v)
    if (jumped[v]) {
      frame_.ids[v] = next_id_++;
      ++s.reidentified;
    }
  finish_ahead();
  complex_ = std::move(next);
  ++generation_;
  topology_ = topology;
  critical_ = std::move(critical);
}

// The moved step made the frame: kept as it is, or mended, cheapest first
// (moving_balls.hpp); throws Error when no mesh of the step can be certified.
void MovingBalls::Impl::repair(const SkinComplex& next, const SkinTopology& topology, const std::vector<int>& critical,
                         SurfaceMesh& moved, std::vector<char>& lost, const std::vector<char>& stayed,
                         Settled settled) {
  detail::LocalRepairOptions local;  // the step's topology changes, among them
  const std::string because = mend_locally(next, topology, critical, moved, lost, stayed, std::move(settled), local);
  all_passed_ = because.empty();
  if (because.empty()) return;
  FrameStats& s = frame_.stats;
  s.remeshed_because = because;
  const auto stage = Clock::now();
  s.crowded += detail::mark_crowded(next, moved, options_.frames, options_.repair.crowded_below, lost);
  const std::vector<long> ids = frame_.ids;  // of `moved`'s vertices, for a second remesh
  bool remeshed = remesh(next, moved, lost, repair_criteria(), {});
  // A neck that opened in the step can be too thin for any vertex to lie
  // on: the remesh then closes it. Seeded at the step's topology changes,
  // it resolves them (seeding every remesh made larger meshes where it was
  // not needed).
  if ((!remeshed || mesh_topology(frame_.mesh) != topology) && !local.changes.empty()) {
    frame_.ids = ids;
    remeshed = remesh(next, moved, lost, repair_criteria(), detail::seeds_at_changes(next, local.changes));
    s.remeshed_because += "; remeshed again with seeds at the topology changes";
  }
  if (!remeshed || mesh_topology(frame_.mesh) != topology) {
    SkinMeshResult made = mesh_skin(next, repair_criteria());
    if (made.status != MeshingStatus::ok)
      throw MeshingFailed(made.status, "moving balls: a step the mesher cannot mesh: " + made.message);
    frame_.mesh = std::move(made.mesh);
    frame_.ids.resize(frame_.mesh.vertices.size());
    for (long& id : frame_.ids) id = next_id_++;
    s.full_rebuild = true;
  }
  s.repaired = true;
  s.remeshed = true;
  s.seconds_repair += seconds_since(stage);
  if (certificate_fault_) certificate_fault_(frame_.mesh, frame_.ids);
  const SkinTopology made = mesh_topology(frame_.mesh);
  if (made != topology)
    throw Error("moving balls: a step's mesh has " + made.text() + " where the skin has " + topology.text() +
                "; the frame is refused");
  s.topology_certified = true;
}

// Per triangle of `moved`, whether it fails the frame criteria, after the
// corners of those that failed were relaxed along the skin once; the
// relaxed vertices are no longer `settled`.
std::vector<char> MovingBalls::Impl::judge_and_relax(const SkinComplex& next, SurfaceMesh& moved, Settled& settled) {
  detail::Judged j = detail::judge_and_relax(next, moved, options_.relaxation, options_.frames, &settled.verdict);
  for (size_t v = 0; v < j.relaxed.size() && v < settled.thinning.size(); ++v)
    if (j.relaxed[v]) settled.verdict.settled[v] = settled.verdict.carried[v] = settled.thinning[v] = 0;
  FrameStats& s = frame_.stats;
  s.settled += j.settled;
  s.carried += j.carried;
  s.bad_triangles += j.failing_before_relax;
  s.seconds_judge += j.seconds_judge;
  s.seconds_relax += j.seconds_relax;
  return std::move(j.failing);
}

// Judging, relaxation, edits and a local patch (moving_balls.hpp). Returns
// "" when they made a certified frame, else why the step must be remeshed
// whole; `moved` and `lost` are then the mesh to remesh from and its lost
// vertices, and `local` holds the step's topology changes.
std::string MovingBalls::Impl::mend_locally(const SkinComplex& next, const SkinTopology& topology,
                                      const std::vector<int>& critical, SurfaceMesh& moved, std::vector<char>& lost,
                                      const std::vector<char>& stayed, Settled settled,
                                      detail::LocalRepairOptions& local) {
  FrameStats& s = frame_.stats;
  // Where the topology changed; a component or void that vanished is
  // dropped first (its sphere of triangles has no skin left to go to); one
  // that is not a component of its own in the step before becomes a place
  // of the local patch, whose Euler characteristic is checked.
  local.crowded_below = options_.repair.crowded_below;
  local.policy = options_.repair.patch;
  local.components_certified_after = true;  // mesh_topology below
  std::vector<detail::VanishingSphere> vanished;
  if (topology != topology_) {
    if (events_) {  // found beside the step before
      local.changes = std::move(events_->changes);
      vanished = std::move(events_->vanished);
    } else {
      topology_changes(complex_, critical_, next, critical, false, local, vanished);
      keep_events(complex_, next, local, vanished);
    }
    s.events += static_cast<long>(local.changes.size() + vanished.size());
  }  // otherwise the critical cells that came or went are flips and cancelling pairs: no place to remesh
  local.euler_change = topology.euler - topology_.euler;
  if (!vanished.empty() && !drop_vanished(vanished, stayed, moved, lost, settled, local.euler_change))
    for (const detail::VanishingSphere& v : vanished) {  // not a component of its own: the patch takes it
      detail::TopologyChange change;
      change.point = v.center;
      change.radius = v.reach;
      local.changes.push_back(change);
    }
  const long lost_count = std::count(lost.begin(), lost.end(), 1);
  if (lost_count > 0 && !merge_lost(moved, lost, settled))
    return std::to_string(lost_count) + " vertices could not be put on the new skin nor merged into a neighbour";
  std::vector<char> failing = judge_and_relax(next, moved, settled);
  build_ahead(next, topology, critical);
  const RepairPolicy& policy = options_.repair;
  if (local.changes.empty() || !(policy.neck_surgery || policy.birth_surgery) || !policy.edits.enabled)
    return edit_and_patch(next, topology, moved, lost, failing, settled, local);
  // Necks and births mended by surgery first; when the edits and the patch
  // cannot finish the frame after it, the frame is mended again from before
  // it, the patch remeshing around every change, before it is remeshed whole.
  Unmended before;
  const long necks_before = s.necks, births_before = s.births;  // of the frame's earlier steps
  if (!mend_by_surgery(next, moved, failing, settled, local, before))
    return edit_and_patch(next, topology, moved, lost, failing, settled, local);
  const std::string because = edit_and_patch(next, topology, moved, lost, failing, settled, local);
  if (because.empty()) return because;
  s.surgeries_undone += s.necks - necks_before + s.births - births_before;
  s.necks = necks_before;
  s.births = births_before;
  moved = std::move(before.mesh);
  failing = std::move(before.failing);
  frame_.ids = std::move(before.ids);
  next_id_ = before.next_id;
  settled.thinning = std::move(before.thinning);
  local = std::move(before.local);
  lost.assign(moved.vertices.size(), 0);
  return edit_and_patch(next, topology, moved, lost, failing, settled, local);
}

// Edits, then a local patch around what still fails and the topology
// changes left in `local`, then the certificate (mend_locally). Returns ""
// with the frame made, else why not.
std::string MovingBalls::Impl::edit_and_patch(const SkinComplex& next, const SkinTopology& topology,
                                              SurfaceMesh& moved, std::vector<char>& lost, std::vector<char>& failing,
                                              Settled& settled, detail::LocalRepairOptions& local) {
  FrameStats& s = frame_.stats;
  long left = std::count(failing.begin(), failing.end(), 1);
  const auto stage = Clock::now();
  if (left > 0 && options_.repair.edits.enabled) {
    detail::RepairResult edited =
        detail::mend_by_edits(next, std::move(moved), failing, options_.frames, options_.repair.edits, &frame_.ids,
                              &refused_thinning_, &settled.thinning);
    detail::take_ids_and_counts(edited, frame_.ids, next_id_, s);
    moved = std::move(edited.mesh);
    failing = std::move(edited.failing);
    left = edited.left;
    s.seconds_edits += seconds_since(stage);
  }
  lost.assign(moved.vertices.size(), 0);  // the edits renumbered the vertices; none is lost
  std::string because;
  const double share = std::max(options_.repair.patch.max_failing_share * static_cast<double>(failing.size()),
                                 static_cast<double>(options_.repair.patch.always_patch_up_to));
  if (left > share) {
    because = std::to_string(left) + " triangles still failing after the edits (" +
              detail::failing_kinds(next, moved, failing, options_.frames).text() + "), more than the local share (" +
              std::to_string(static_cast<long>(share)) + ")";
  } else if (left > 0 || !local.changes.empty()) {
    const auto patch_start = Clock::now();
    detail::RepairResult patched =
        detail::repair_locally(next, moved, failing, repair_criteria(), options_.frames, local);
    s.seconds_patch += seconds_since(patch_start);
    s.patch_attempts += patched.attempts;
    if (patched.ok) {
      detail::take_ids_and_counts(patched, frame_.ids, next_id_, s);
      moved = std::move(patched.mesh);
      lost.assign(moved.vertices.size(), 0);
    } else {
      because = "the local patch failed: " + patched.failed_because;
    }
  }
  s.seconds_repair += seconds_since(stage);
  if (!because.empty()) return because;
  if (certificate_fault_) certificate_fault_(moved, frame_.ids);
  const SkinTopology made = mesh_topology(moved);
  if (made != topology) return "the mended mesh has " + made.text() + ", the skin " + topology.text();
  frame_.mesh = std::move(moved);
  s.topology_certified = true;
  return "";
}

// The components of the step before that `vanished` took (vanishing.hpp),
// dropped from `moved` with their ids and their entries in `lost`;
// `euler_change` gains 2 for each, since the repair counts from the mesh
// without them. False when one is not found as a component of its own.
bool MovingBalls::Impl::drop_vanished(const std::vector<detail::VanishingSphere>& vanished, const std::vector<char>& stayed,
                                SurfaceMesh& moved, std::vector<char>& lost, Settled& settled,
                                long& euler_change) {
  std::vector<char> found;
  const std::vector<char> gone =
      detail::vanishing_components(frame_.mesh, std::vector<char>(stayed.size(), 0), vanished, found);
  if (std::find(found.begin(), found.end(), 0) != found.end()) return false;
  std::vector<char> keep(moved.triangles.size());
  for (size_t f = 0; f < keep.size(); ++f) keep[f] = !gone[static_cast<size_t>(moved.triangles[f][0])];
  std::vector<int> kept_from;
  moved = detail::used_part(moved, keep, kept_from);
  keep_vertices(kept_from, lost, settled);
  euler_change += 2 * static_cast<long>(vanished.size());
  return true;
}

// The necks that opened or pinched in the step cut and joined or capped
// (necks.hpp), their new triangles left failing for the edits, and the
// components and voids born meshed as spheres (births.hpp); the changes
// made leave the patch's places and the Euler characteristic it must make.
// False, nothing changed, when none was made; else `before` holds the frame
// as it was.
bool MovingBalls::Impl::mend_by_surgery(const SkinComplex& next, SurfaceMesh& moved, std::vector<char>& failing,
                                        Settled& settled, detail::LocalRepairOptions& local, Unmended& before) {
  const auto start = Clock::now();
  const detail::LocalRepairOptions unmended = local;
  detail::EventSurgery surgery =
      detail::surgery_at_events(next, moved, failing, options_.frames, options_.repair, local);
  detail::RepairResult& cut = surgery.result;
  const double seconds = seconds_since(start);
  frame_.stats.seconds_edits += seconds;
  frame_.stats.seconds_repair += seconds;
  if (!cut.ok) return false;
  std::vector<char> thinning(cut.origin.size(), 0);
  if (!settled.thinning.empty())
    for (size_t v = 0; v < thinning.size(); ++v)
      if (cut.origin[v] >= 0) thinning[v] = settled.thinning[static_cast<size_t>(cut.origin[v])];
  before = {std::move(moved), std::move(failing), frame_.ids, next_id_, std::move(settled.thinning), unmended};
  settled.thinning = std::move(thinning);
  detail::take_ids_and_counts(cut, frame_.ids, next_id_, frame_.stats);
  moved = std::move(cut.mesh);
  failing = std::move(cut.failing);
  frame_.stats.necks += surgery.necks;
  frame_.stats.births += surgery.births;
  return true;
}

// The vertices transport lost merged into neighbours it placed
// (merge_lost_vertices), with their ids; the corners of the triangles the
// merges changed are no longer settled or carried (their triangles are
// judged). False, nothing changed, when one cannot be merged.
bool MovingBalls::Impl::merge_lost(SurfaceMesh& moved, std::vector<char>& lost, Settled& settled) {
  std::vector<int> kept_from;
  std::vector<char> touched;
  std::vector<char> merged = lost;
  if (!detail::merge_lost_vertices(moved, merged, kept_from, touched)) return false;
  keep_vertices(kept_from, lost, settled);
  for (size_t v = 0; v < touched.size(); ++v)
    if (touched[v]) settled.verdict.settled[v] = settled.verdict.carried[v] = settled.thinning[v] = 0;
  return true;
}

// The ids and per-vertex marks of the vertices `kept_from` names, in its order.
void MovingBalls::Impl::keep_vertices(const std::vector<int>& kept_from, std::vector<char>& lost, Settled& settled) {
  std::vector<long> ids;
  for (int v : kept_from) ids.push_back(frame_.ids[static_cast<size_t>(v)]);
  frame_.ids = std::move(ids);
  for (std::vector<char>* marks : {&lost, &settled.verdict.settled, &settled.verdict.carried, &settled.thinning}) {
    std::vector<char> kept;
    for (int v : kept_from) kept.push_back(marks->empty() ? 0 : (*marks)[static_cast<size_t>(v)]);
    *marks = std::move(kept);
  }
  if (!settled.verdict.before.empty()) {
    std::vector<Eigen::Vector3d> before;
    for (int v : kept_from) before.push_back(settled.verdict.before[static_cast<size_t>(v)]);
    settled.verdict.before = std::move(before);
  }
}

namespace detail {

void inject_certificate_fault(MovingBalls& engine, std::function<void(SurfaceMesh&, std::vector<long>&)> fault) {
  engine.impl_->certificate_fault_ = std::move(fault);
}

}  // namespace detail

// The whole step remeshed from the moved vertices not dropped and `seeds`
// (remesh_skin); false when the mesher cannot.
bool MovingBalls::Impl::remesh(const SkinComplex& next, const SurfaceMesh& moved, std::vector<char>& drop,
                               const MeshingOptions& criteria, const std::vector<SkinSample>& seeds) {
  detail::RepairResult r = detail::remesh_from_vertices(next, moved, drop, criteria, seeds);
  if (!r.ok) return false;
  detail::take_ids_and_counts(r, frame_.ids, next_id_, frame_.stats);
  frame_.mesh = std::move(r.mesh);
  return true;
}

}  // namespace skinmesh
