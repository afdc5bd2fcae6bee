#include "necks.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <utility>

namespace skinmesh::detail {
namespace {

constexpr double kTwoPi = 6.283185307179586;
// Angstrom: the triangles a neck's cut and spacing read lie within this of its apex.
constexpr double kNearby = 4.0;

// Cylindrical coordinates about a neck's axis through its apex, and the
// skin's radius there: r^2 = alpha h^2 + beta in the neck's cell.
struct NeckFrame {
  Eigen::Vector3d apex = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d u = Eigen::Vector3d::UnitX(), v = Eigen::Vector3d::UnitY();  // across the axis
  double alpha = 0, beta = 0;
  int cell = -1;
  bool opens = false;

  double height(const Eigen::Vector3d& x) const { return axis.dot(x - apex); }
  double radius(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d d = x - apex;
    return (d - axis * axis.dot(d)).norm();
  }
  double angle(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d d = x - apex;
    return std::atan2(v.dot(d), u.dot(d));
  }
  Eigen::Vector3d at(double h, double r, double theta) const {
    return apex + h * axis + r * (std::cos(theta) * u + std::sin(theta) * v);
  }
};

// The quadric of a cell X of dimension k (skin_complex.hpp),
// Q = (1-s)|(I-P)(x-z)|^2 - s|P(x-z)|^2 + s(1-s)R2, about its axis: for an
// edge (k = 1) the axis is the edge's direction P and r^2 = s/(1-s) h^2 - s R2;
// for a triangle (k = 2) the axis is its normal I-P and
// r^2 = (1-s)/s h^2 + (1-s) R2. A neck that opens needs a tube there
// (beta > 0), one that pinches two caps (beta < 0).
std::optional<NeckFrame> neck_frame(const SkinComplex& complex, const TopologyChange& change) {
  if ((change.dim != 1 && change.dim != 2) || change.neck_cell < 0 || std::abs(change.euler_change) != 2)
    return std::nullopt;
  const MixedCell& cell = complex.cell(change.neck_cell);
  if (cell.degenerate || cell.dim != change.dim) return std::nullopt;
  const double s = complex.shrink();
  const Eigen::Matrix3d along = change.dim == 1 ? cell.P : Eigen::Matrix3d::Identity() - cell.P;
  Eigen::Index k = 0;
  along.colwise().norm().maxCoeff(&k);
  NeckFrame f;
  f.apex = cell.center;
  f.axis = along.col(k).normalized();
  f.u = f.axis.unitOrthogonal();
  f.v = f.axis.cross(f.u);
  f.alpha = change.dim == 1 ? s / (1 - s) : (1 - s) / s;
  f.beta = change.dim == 1 ? -s * cell.R2 : (1 - s) * cell.R2;
  f.cell = change.neck_cell;
  f.opens = change.euler_change < 0;
  if (f.opens != (f.beta > 0)) return std::nullopt;
  return f;
}

// A closed loop of vertices ordered by increasing angle about the axis, and
// on which side of the apex it lies.
struct Loop {
  std::vector<int> vertices;
  std::vector<double> angles;  // unwrapped, increasing, less than 2 pi from first to last
  double height = 0;           // mean
};

// The boundary half-edges (u -> v, as the cut triangles had them) followed
// into loops; each must wind once around the axis with its angle strictly
// monotonic. Empty when the cut's boundary is not two such loops.
std::vector<Loop> loops_around(const SurfaceMesh& mesh, const std::vector<std::pair<int, int>>& boundary,
                               const NeckFrame& f) {
  std::map<int, int> next;
  for (const auto& [a, b] : boundary)
    if (!next.emplace(a, b).second) return {};  // a vertex twice on the boundary
  std::vector<Loop> loops;
  while (!next.empty()) {
    Loop loop;
    int at = next.begin()->first;
    while (true) {
      const auto it = next.find(at);
      if (it == next.end()) break;
      loop.vertices.push_back(at);
      at = it->second;
      next.erase(it);
    }
    if (at != loop.vertices.front() || loop.vertices.size() < 3) return {};
    double turn = 0, h = 0;
    std::vector<double> steps;
    for (size_t i = 0; i < loop.vertices.size(); ++i) {
      const Eigen::Vector3d& p = mesh.vertices[static_cast<size_t>(loop.vertices[i])];
      const Eigen::Vector3d& q = mesh.vertices[static_cast<size_t>(loop.vertices[(i + 1) % loop.vertices.size()])];
      double d = f.angle(q) - f.angle(p);
      d -= kTwoPi * std::round(d / kTwoPi);
      steps.push_back(d);
      turn += d;
      h += f.height(p);
    }
    if (std::abs(std::abs(turn) - kTwoPi) > 1e-6) return {};
    const double sign = turn > 0 ? 1 : -1;
    if (std::any_of(steps.begin(), steps.end(), [&](double d) { return d * sign <= 0; })) return {};
    if (sign < 0) std::reverse(loop.vertices.begin(), loop.vertices.end());
    double a = f.angle(mesh.vertices[static_cast<size_t>(loop.vertices[0])]);
    for (size_t i = 0; i < loop.vertices.size(); ++i) {
      if (i > 0) {
        double d = f.angle(mesh.vertices[static_cast<size_t>(loop.vertices[i])]) -
                   f.angle(mesh.vertices[static_cast<size_t>(loop.vertices[i - 1])]);
        d -= kTwoPi * std::floor(d / kTwoPi);
        a += d;
      }
      loop.angles.push_back(a);
    }
    loop.height = h / static_cast<double>(loop.vertices.size());
    loops.push_back(std::move(loop));
  }
  if (loops.size() != 2 || (loops[0].height > 0) == (loops[1].height > 0)) return {};
  if (loops[0].height > loops[1].height) std::swap(loops[0], loops[1]);
  return loops;
}

// Triangles joining ring `lower` to ring `upper` (both by increasing
// angle), each advancing along the ring whose next vertex comes first
// around the axis: (p_i, p_i+1, q_j) or (p_i, q_j+1, q_j).
void zip(const Loop& lower, const Loop& upper, std::vector<std::array<int, 3>>& out) {
  const size_t np = lower.vertices.size(), nq = upper.vertices.size();
  // Start the upper ring at its vertex nearest in angle to the lower's first.
  size_t j0 = 0;
  double offset = kTwoPi;
  for (size_t j = 0; j < nq; ++j) {
    double d = upper.angles[j] - lower.angles[0];
    d -= kTwoPi * std::round(d / kTwoPi);
    if (std::abs(d) < std::abs(offset)) offset = d, j0 = j;
  }
  const auto p_angle = [&](size_t i) { return lower.angles[i % np] + kTwoPi * static_cast<double>(i / np); };
  const auto q_angle = [&](size_t j) {
    const size_t k = j0 + j;
    return lower.angles[0] + offset + upper.angles[k % nq] + kTwoPi * static_cast<double>(k / nq) - upper.angles[j0];
  };
  const auto p = [&](size_t i) { return lower.vertices[i % np]; };
  const auto q = [&](size_t j) { return upper.vertices[(j0 + j) % nq]; };
  size_t i = 0, j = 0;
  while (i < np || j < nq) {
    if (j == nq || (i < np && p_angle(i + 1) <= q_angle(j + 1))) {
      out.push_back({p(i), p(i + 1), q(j)});
      ++i;
    } else {
      out.push_back({p(i), q(j + 1), q(j)});
      ++j;
    }
  }
}

// Skin points the surgery adds, numbered after the mesh's vertices.
struct Added {
  size_t base = 0;  // the mesh's vertex count
  std::vector<Eigen::Vector3d> points;
  std::vector<int> cells;
  int add(const Projection& p) {
    points.push_back(p.point);
    cells.push_back(p.cell);
    return static_cast<int>(base + points.size() - 1);
  }
  void truncate(size_t n) {
    points.resize(n);
    cells.resize(n);
  }
};

// A ring of skin points at height h about the axis, about `guess` from it,
// spaced about `spacing`: each projected onto the skin from its place on
// the circle. False when it would take more than 1,000 points, or a
// projection does not converge, strays farther than `spacing` from where it
// started, or leaves the ring out of order.
bool ring_at(const SkinComplex& complex, const NeckFrame& f, double h, double guess, double spacing, Added& added,
             Loop& ring) {
  const double count = std::ceil(kTwoPi * guess / spacing);
  if (!(count <= 1000)) return false;
  const int n = std::max(6, static_cast<int>(count));
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < n; ++k) {
    const double theta = kTwoPi * k / n;
    const Eigen::Vector3d from = f.at(h, guess, theta);
    const Projection p = complex.project(from, f.cell, 1e-14);
    if (!p.converged || (p.point - from).norm() > spacing) return false;
    ring.vertices.push_back(added.add(p));
    points.push_back(p.point);
  }
  double a = f.angle(points[0]);
  ring.angles.push_back(a);
  for (size_t k = 1; k < points.size(); ++k) {
    double d = f.angle(points[k]) - f.angle(points[k - 1]);
    d -= kTwoPi * std::floor(d / kTwoPi);
    if (d <= 0 || d >= kTwoPi / 2) return false;
    a += d;
    ring.angles.push_back(a);
  }
  ring.height = h;
  return true;
}

// Whether the new triangles close the cut: each boundary half-edge of the
// cut once, in the cut triangles' direction, and every other half-edge once
// with its twin. Each group (the tube, or one cap) is reversed first when
// it runs against the boundary.
bool closes_cut(std::vector<std::vector<std::array<int, 3>>>& groups, const std::vector<std::pair<int, int>>& boundary,
                std::vector<std::array<int, 3>>& made) {
  const std::set<std::pair<int, int>> outer(boundary.begin(), boundary.end());
  made.clear();
  for (auto& group : groups) {
    const bool reversed = std::any_of(group.begin(), group.end(), [&](const std::array<int, 3>& t) {
      for (int e = 0; e < 3; ++e)
        if (outer.count({t[static_cast<size_t>((e + 1) % 3)], t[static_cast<size_t>(e)]})) return true;
      return false;
    });
    for (auto t : group) {
      if (reversed) std::swap(t[1], t[2]);
      made.push_back(t);
    }
  }
  std::map<std::pair<int, int>, int> half;
  for (const auto& t : made)
    for (int e = 0; e < 3; ++e) ++half[{t[static_cast<size_t>(e)], t[static_cast<size_t>((e + 1) % 3)]}];
  for (const auto& [e, n] : half) {
    if (n != 1) return false;
    const bool on_boundary = outer.count(e) > 0;
    const bool twinned = half.count({e.second, e.first}) > 0;
    if (on_boundary == twinned) return false;
  }
  return std::all_of(boundary.begin(), boundary.end(), [&](const auto& e) { return half.count(e) > 0; });
}

// The triangles of `near` with a corner in the cylinder of radius `reach`
// and height 2 `half_height` about the axis, and the loops their boundary
// makes (loops_around; none when they are not two loops around the axis).
struct Cut {
  std::vector<int> triangles;
  std::vector<std::pair<int, int>> boundary;
  std::vector<Loop> loops;
};

Cut cut_in_cylinder(const SurfaceMesh& mesh, const std::vector<int>& near, const NeckFrame& f, double reach,
                    double half_height) {
  Cut c;
  std::set<std::pair<int, int>> half;
  for (int t : near) {
    const auto& tri = mesh.triangles[static_cast<size_t>(t)];
    const bool in = std::any_of(tri.begin(), tri.end(), [&](int v) {
      const Eigen::Vector3d& x = mesh.vertices[static_cast<size_t>(v)];
      return std::abs(f.height(x)) <= half_height && f.radius(x) <= reach;
    });
    if (!in) continue;
    c.triangles.push_back(t);
    for (int e = 0; e < 3; ++e) half.insert({tri[static_cast<size_t>(e)], tri[static_cast<size_t>((e + 1) % 3)]});
  }
  for (const auto& e : half)
    if (!half.count({e.second, e.first})) c.boundary.push_back(e);
  if (!c.boundary.empty()) c.loops = loops_around(mesh, c.boundary, f);
  return c;
}

// The mean edge length of the triangles of `near` with a corner within
// 2 A of the apex: the spacing of the cut. 0 when there are none.
double spacing_near(const SurfaceMesh& mesh, const std::vector<int>& near, const Eigen::Vector3d& apex) {
  double length = 0;
  long edges = 0;
  for (int t : near) {
    const auto& tri = mesh.triangles[static_cast<size_t>(t)];
    if (std::none_of(tri.begin(), tri.end(),
                     [&](int v) { return (mesh.vertices[static_cast<size_t>(v)] - apex).squaredNorm() < 4.0; }))
      continue;
    for (int e = 0; e < 3; ++e)
      length += (mesh.vertices[static_cast<size_t>(tri[static_cast<size_t>(e)])] -
                 mesh.vertices[static_cast<size_t>(tri[static_cast<size_t>((e + 1) % 3)])])
                    .norm();
    edges += 3;
  }
  return edges ? length / static_cast<double>(edges) : 0;
}

// A tube of rings between the loops, each at the skin's radius in the
// neck's cell, projected onto the skin: rings and their points spaced by
// the target edge length there (`criteria`), which the waist's curvature
// makes small. False past 200 rings.
bool tube(const SkinComplex& complex, const NeckFrame& f, const std::vector<Loop>& loops,
          const MeshingOptions& criteria, Added& added, std::vector<std::array<int, 3>>& made) {
  const auto profile = [&](double h) { return std::sqrt(f.alpha * h * h + f.beta); };
  const auto target_at = [&](double h) {
    const Projection p = complex.project(f.at(h, profile(h), 0), f.cell, 1e-12);
    return p.converged ? target_edge_length(complex, p.point, p.cell, criteria) : 0.0;
  };
  Loop below = loops[0];
  double h = loops[0].height;
  for (int rings = 0;; ++rings) {
    const double slope = f.alpha * h / profile(h);  // dr/dh
    const double step = target_at(h) / std::sqrt(1 + slope * slope);
    if (!(step > 0) || rings > 200) return false;
    if (h + 1.5 * step >= loops[1].height) break;
    h += step;
    Loop ring;
    if (!ring_at(complex, f, h, profile(h), target_at(h), added, ring)) return false;
    zip(below, ring, made);
    below = std::move(ring);
  }
  zip(below, loops[1], made);
  return true;
}

// A fan closing `loop` at the skin's point on the axis on its side.
bool cap(const SkinComplex& complex, const NeckFrame& f, const Loop& loop, double length, Added& added,
         std::vector<std::array<int, 3>>& made) {
  const double side = loop.height > 0 ? 1 : -1;
  const Eigen::Vector3d from = f.apex + side * std::sqrt(-f.beta / f.alpha) * f.axis;
  const Projection p = complex.project(from, f.cell, 1e-14);
  if (!p.converged || (p.point - from).norm() > length) return false;
  const int apex = added.add(p);
  const size_t n = loop.vertices.size();
  for (size_t i = 0; i < n; ++i) made.push_back({loop.vertices[i], loop.vertices[(i + 1) % n], apex});
  return true;
}

// One neck's surgery: the triangles it cuts (among `near`, none of them in
// `taken`) and the triangles and points that replace them. The cylinder
// grows from 0.75 to 4 edge lengths past the skin's waist (and its caps)
// until its cut leaves two loops around the axis. The change of the Euler
// characteristic is checked here: the points added less the vertices cut
// out (those of cut triangles off the boundary), less half the triangles
// added over those cut (V - E + F with E = 3F/2). False, `added` as it was, when no cut does, a new
// point cannot be put on the skin, or the change is not `euler_change`.
bool cut_and_mend(const SkinComplex& complex, const NeckFrame& f, int euler_change, const MeshingOptions& criteria,
                  const SurfaceMesh& mesh, const std::vector<int>& near, const std::vector<char>& taken,
                  Added& added, std::vector<int>& cut, std::vector<std::array<int, 3>>& made) {
  const double length = spacing_near(mesh, near, f.apex);
  if (length <= 0) return false;
  const double waist = std::sqrt(std::abs(f.beta));
  const double cap_height = f.opens ? 0 : std::sqrt(-f.beta / f.alpha);
  Cut c;
  for (double k : {0.75, 1.0, 1.5, 2.5, 4.0}) {
    const double reach = waist + k * length, half_height = cap_height + k * length;
    if (reach * reach + half_height * half_height > kNearby * kNearby) break;  // past the triangles `near` holds
    c = cut_in_cylinder(mesh, near, f, reach, half_height);
    if (!c.loops.empty()) break;
  }
  if (c.loops.empty()) return false;
  if (std::any_of(c.triangles.begin(), c.triangles.end(), [&](int t) { return taken[static_cast<size_t>(t)]; }))
    return false;
  const size_t had = added.points.size();
  std::vector<std::vector<std::array<int, 3>>> groups(f.opens ? 1 : 2);
  bool built = f.opens ? tube(complex, f, c.loops, criteria, added, groups[0]) : true;
  for (size_t k = 0; !f.opens && built && k < 2; ++k) built = cap(complex, f, c.loops[k], length, added, groups[k]);
  std::vector<std::array<int, 3>> triangles;
  if (!built || !closes_cut(groups, c.boundary, triangles)) {
    added.truncate(had);
    return false;
  }
  std::set<int> inner;
  for (int t : c.triangles)
    for (int v : mesh.triangles[static_cast<size_t>(t)]) inner.insert(v);
  for (const auto& e : c.boundary) inner.erase(e.first);
  const long twice = 2 * (static_cast<long>(added.points.size() - had) - static_cast<long>(inner.size())) -
                     (static_cast<long>(triangles.size()) - static_cast<long>(c.triangles.size()));
  if (twice != 2L * euler_change) {
    added.truncate(had);
    return false;
  }
  cut = std::move(c.triangles);
  made = std::move(triangles);
  return true;
}

// Per change, the triangles with a corner within `radius` of its apex: one
// pass over the vertices, then over the triangles.
std::vector<std::vector<int>> triangles_near(const SurfaceMesh& mesh, const std::vector<Eigen::Vector3d>& apexes,
                                             double radius) {
  std::vector<std::vector<int>> near(apexes.size());
  std::vector<char> close(mesh.vertices.size(), 0);
  for (size_t v = 0; v < close.size(); ++v)
    for (const Eigen::Vector3d& a : apexes) close[v] = close[v] || (mesh.vertices[v] - a).squaredNorm() <= radius * radius;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    if (!close[static_cast<size_t>(tri[0])] && !close[static_cast<size_t>(tri[1])] && !close[static_cast<size_t>(tri[2])])
      continue;
    for (size_t k = 0; k < apexes.size(); ++k)
      if (std::any_of(tri.begin(), tri.end(), [&](int v) {
            return (mesh.vertices[static_cast<size_t>(v)] - apexes[k]).squaredNorm() <= radius * radius;
          }))
        near[k].push_back(static_cast<int>(t));
  }
  return near;
}

}  // namespace

RepairResult neck_surgery(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                          const std::vector<TopologyChange>& changes, const MeshingOptions& criteria,
                          std::vector<char>& done) {
  RepairResult r;
  done.assign(changes.size(), 0);
  std::vector<NeckFrame> frames;
  std::vector<size_t> which;
  for (size_t k = 0; k < changes.size(); ++k)
    if (const std::optional<NeckFrame> f = neck_frame(complex, changes[k])) frames.push_back(*f), which.push_back(k);
  if (frames.empty()) return r;
  std::vector<Eigen::Vector3d> apexes;
  for (const NeckFrame& f : frames) apexes.push_back(f.apex);
  const std::vector<std::vector<int>> near = triangles_near(mesh, apexes, kNearby);
  Added added;
  added.base = mesh.vertices.size();
  std::vector<char> taken(mesh.triangles.size(), 0);
  std::vector<std::array<int, 3>> made;
  for (size_t i = 0; i < frames.size(); ++i) {
    std::vector<int> cut;
    std::vector<std::array<int, 3>> mended;
    if (!cut_and_mend(complex, frames[i], changes[which[i]].euler_change, criteria, mesh, near[i], taken, added, cut,
                      mended))
      continue;
    for (int t : cut) taken[static_cast<size_t>(t)] = 1;
    made.insert(made.end(), mended.begin(), mended.end());
    done[which[i]] = 1;
  }
  if (made.empty()) return r;
  // The mesh without the cut triangles, with the new ones, renumbered over
  // the vertices still used (those cut out go), in one pass.
  const size_t had = mesh.vertices.size();
  std::vector<int> index(had + added.points.size(), -1);
  std::vector<char> verdicts;
  verdicts.reserve(mesh.triangles.size() + made.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    if (!taken[t]) {
      for (int v : mesh.triangles[t]) index[static_cast<size_t>(v)] = 0;
      verdicts.push_back(failing[t]);
    }
  for (const auto& t : made)
    for (int v : t) index[static_cast<size_t>(v)] = 0;
  verdicts.resize(verdicts.size() + made.size(), 1);
  SurfaceMesh& out = r.mesh;
  for (size_t v = 0; v < index.size(); ++v) {
    if (index[v] < 0) continue;
    index[v] = static_cast<int>(out.vertices.size());
    const bool old = v < had;
    out.vertices.push_back(old ? mesh.vertices[v] : added.points[v - had]);
    if (!mesh.cells.empty()) out.cells.push_back(old ? mesh.cells[v] : added.cells[v - had]);
    if (!mesh.normals.empty())
      out.normals.push_back(old ? mesh.normals[v]
                                : complex.evaluate(added.points[v - had], added.cells[v - had]).gradient.normalized());
    r.origin.push_back(old ? static_cast<long>(v) : -1);
  }
  const auto renumbered = [&](const std::array<int, 3>& t) {
    return std::array<int, 3>{index[static_cast<size_t>(t[0])], index[static_cast<size_t>(t[1])],
                              index[static_cast<size_t>(t[2])]};
  };
  out.triangles.reserve(verdicts.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    if (!taken[t]) out.triangles.push_back(renumbered(mesh.triangles[t]));
  for (const auto& t : made) out.triangles.push_back(renumbered(t));
  r.failing = std::move(verdicts);
  r.left = std::count(r.failing.begin(), r.failing.end(), 1);
  r.ok = true;
  return r;
}

long take_done_changes(const std::vector<char>& done, LocalRepairOptions& local) {
  std::vector<TopologyChange> rest;
  long taken = 0;
  for (size_t k = 0; k < local.changes.size(); ++k) {
    if (k < done.size() && done[k]) {
      local.euler_change -= local.changes[k].euler_change;
      ++taken;
    } else {
      rest.push_back(local.changes[k]);
    }
  }
  local.changes = std::move(rest);
  return taken;
}

}  // namespace skinmesh::detail
