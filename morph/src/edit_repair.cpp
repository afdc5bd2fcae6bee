#include "edit_repair.hpp"

#include "local_repair.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <deque>

namespace skinmesh::detail {
namespace {

using Triangle = std::array<int, 3>;

Eigen::Vector3d area_normal(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return (b - a).cross(c - a);
}

// The angle at `at` of the triangle (at, p, q), radians.
double angle_at(const Eigen::Vector3d& at, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d u = p - at, w = q - at;
  return std::atan2(u.cross(w).norm(), u.dot(w));
}

// Triangle t rotated so that it starts at vertex v (which it contains).
Triangle starting_at(const Triangle& t, int v) {
  if (t[1] == v) return {t[1], t[2], t[0]};
  if (t[2] == v) return {t[2], t[0], t[1]};
  return t;
}

// A closed triangle mesh under edits: triangles are removed by a flag, and
// every vertex knows the live triangles around it.
class EditableMesh {
 public:
  explicit EditableMesh(const SurfaceMesh& m)
      : vertices(m.vertices), normals(m.normals), cells(m.cells), star(m.vertices.size()) {
    for (const Triangle& t : m.triangles) add(t);
  }

  int add(const Triangle& t) {
    const int f = static_cast<int>(triangles.size());
    triangles.push_back(t);
    alive.push_back(1);
    for (int v : t) star[static_cast<size_t>(v)].push_back(f);
    return f;
  }
  void remove(int f) {
    alive[static_cast<size_t>(f)] = 0;
    for (int v : triangles[static_cast<size_t>(f)]) {
      std::vector<int>& around = star[static_cast<size_t>(v)];
      around.erase(std::find(around.begin(), around.end(), f));
    }
  }
  int add_vertex(const Eigen::Vector3d& x, const Eigen::Vector3d& normal, int cell) {
    vertices.push_back(x);
    normals.push_back(normal);
    cells.push_back(cell);
    star.emplace_back();
    return static_cast<int>(vertices.size()) - 1;
  }
  // The live triangle with the directed edge a -> b, or -1.
  int with_edge(int a, int b) const {
    for (int f : star[static_cast<size_t>(a)]) {
      const Triangle r = starting_at(triangles[static_cast<size_t>(f)], a);
      if (r[1] == b) return f;
    }
    return -1;
  }
  bool joined(int a, int b) const { return with_edge(a, b) >= 0 || with_edge(b, a) >= 0; }
  std::vector<int> neighbours(int v) const {
    std::vector<int> out;
    for (int f : star[static_cast<size_t>(v)])
      for (int w : triangles[static_cast<size_t>(f)])
        if (w != v && std::find(out.begin(), out.end(), w) == out.end()) out.push_back(w);
    return out;
  }
  const Eigen::Vector3d& at(int v) const { return vertices[static_cast<size_t>(v)]; }

  std::vector<Eigen::Vector3d> vertices, normals;
  std::vector<int> cells;
  std::vector<Triangle> triangles;
  std::vector<char> alive;
  std::vector<std::vector<int>> star;
};

class Editor {
 public:
  Editor(const SkinComplex& complex, const SurfaceMesh& mesh, const MeshingOptions& accept,
         const EditRepairOptions& options)
      : complex_(complex), m_(mesh), accept_(accept), options_(options) {}

  bool run(const std::vector<char>& failing, long budget, EditRepair& out);
  const EditableMesh& mesh() const { return m_; }
  const std::vector<int>& stuck() const { return stuck_; }

 private:
  bool passes(const Triangle& t);
  bool mend(int f);
  bool turned_over(const Triangle& t) const;
  bool try_relocate(int v);
  // Turned-over triangles, kept out of every edit.
  bool frozen(int f) const { return static_cast<size_t>(f) < frozen_.size() && frozen_[static_cast<size_t>(f)]; }
  enum class FlipRule { both_pass, delaunay };
  bool flip(int a, int b, FlipRule rule);
  void flip_around(int n);
  bool try_contract(int keep, int gone);
  bool split(int a, int b);
  // Replaces triangles; added ones not judged yet are queued.
  void commit(const std::vector<int>& removed, const std::vector<Triangle>& added, bool judged);
  double target_length(int v) const {
    return target_edge_length(complex_, m_.at(v), m_.cells[static_cast<size_t>(v)], accept_);
  }

  const SkinComplex& complex_;
  EditableMesh m_;
  const MeshingOptions& accept_;
  EditRepairOptions options_;
  std::deque<int> queue_;
  std::vector<int> stuck_;
  std::vector<char> frozen_;
  long flips_ = 0, splits_ = 0, contractions_ = 0, relocations_ = 0, judged_ = 0;
};

bool Editor::passes(const Triangle& t) {
  ++judged_;
  return triangle_passes(complex_, {m_.at(t[0]), m_.at(t[1]), m_.at(t[2])}, m_.cells[static_cast<size_t>(t[0])],
                         accept_);
}

void Editor::commit(const std::vector<int>& removed, const std::vector<Triangle>& added, bool judged) {
  for (int f : removed) m_.remove(f);
  for (const Triangle& t : added) {
    const int f = m_.add(t);
    if (!judged) queue_.push_back(f);
  }
}

// Flips edge a-b of triangles (a, b, c) and (b, a, d) to c-d. Rule
// both_pass: when both new triangles pass (they are not queued). Rule
// delaunay: when the angles opposite a-b sum past pi (Lawson's test: d lies
// in the circle of a, b, c); the new triangles are queued.
bool Editor::flip(int a, int b, FlipRule rule) {
  const int f1 = m_.with_edge(a, b), f2 = m_.with_edge(b, a);
  if (f1 < 0 || f2 < 0) return false;
  const int c = starting_at(m_.triangles[static_cast<size_t>(f1)], a)[2];
  const int d = starting_at(m_.triangles[static_cast<size_t>(f2)], b)[2];
  if (frozen(f1) || frozen(f2) || c == d || m_.joined(c, d)) return false;  // c-d would be doubled
  if (rule == FlipRule::delaunay &&
      angle_at(m_.at(c), m_.at(a), m_.at(b)) + angle_at(m_.at(d), m_.at(a), m_.at(b)) <= M_PI)
    return false;
  const Triangle t1{a, d, c}, t2{d, b, c};
  const Eigen::Vector3d n1 = area_normal(m_.at(a), m_.at(d), m_.at(c)), n2 = area_normal(m_.at(d), m_.at(b), m_.at(c));
  if (!(n1.dot(n2) > 0) || turned_over(t1) || turned_over(t2)) return false;  // folded over
  if (rule == FlipRule::both_pass && !(passes(t1) && passes(t2))) return false;
  commit({f1, f2}, {t1, t2}, rule == FlipRule::both_pass);
  ++flips_;
  return true;
}

// Lawson's flips around a new vertex n: each edge opposite n is flipped
// while it fails the test, and the two edges it brings opposite n are
// checked in turn (bounded: a surface is not a plane).
void Editor::flip_around(int n) {
  std::vector<std::pair<int, int>> edges;
  for (int f : m_.star[static_cast<size_t>(n)]) {
    const Triangle r = starting_at(m_.triangles[static_cast<size_t>(f)], n);
    edges.emplace_back(r[1], r[2]);
  }
  for (int guard = 0; !edges.empty() && guard < 64; ++guard) {
    const auto [u, v] = edges.back();
    edges.pop_back();
    const int f = m_.with_edge(u, v), g = m_.with_edge(v, u);
    if (f < 0 || g < 0 || starting_at(m_.triangles[static_cast<size_t>(f)], u)[2] != n) continue;
    const int d = starting_at(m_.triangles[static_cast<size_t>(g)], v)[2];
    if (!flip(u, v, FlipRule::delaunay)) continue;
    edges.emplace_back(u, d);
    edges.emplace_back(d, v);
  }
}

// Contracts edge keep-gone into `keep` when the link condition holds (the
// two vertices share exactly the two neighbours across the edge, so the
// topology stays; T. K. Dey et al., "Topology preserving edge contraction",
// 1999) and every triangle that then uses `keep` instead passes (which
// includes facing outward).
bool Editor::try_contract(int keep, int gone) {
  const int f1 = m_.with_edge(keep, gone), f2 = m_.with_edge(gone, keep);
  if (f1 < 0 || f2 < 0) return false;
  const int c = starting_at(m_.triangles[static_cast<size_t>(f1)], keep)[2];
  const int d = starting_at(m_.triangles[static_cast<size_t>(f2)], gone)[2];
  if (m_.star[static_cast<size_t>(c)].size() <= 3 || m_.star[static_cast<size_t>(d)].size() <= 3) return false;
  const std::vector<int> around_keep = m_.neighbours(keep);
  int shared = 0;
  for (int w : m_.neighbours(gone))
    if (std::find(around_keep.begin(), around_keep.end(), w) != around_keep.end()) {
      if (w != c && w != d) return false;
      ++shared;
    }
  if (shared != 2) return false;
  const std::vector<int> removed = m_.star[static_cast<size_t>(gone)];
  if (std::any_of(removed.begin(), removed.end(), [&](int f) { return frozen(f); })) return false;
  std::vector<Triangle> added;
  for (int f : removed) {
    if (f == f1 || f == f2) continue;
    const Triangle& old = m_.triangles[static_cast<size_t>(f)];
    Triangle t = old;
    std::replace(t.begin(), t.end(), gone, keep);
    if (!passes(t)) return false;
    added.push_back(t);
  }
  commit(removed, added, true);
  ++contractions_;
  return true;
}

// Splits edge a-b at the skin point nearest its midpoint, then flips the
// edges around the new vertex where Lawson's test asks for it (longest-edge
// bisection with Delaunay flips). The new triangles are queued to be judged.
bool Editor::split(int a, int b) {
  const int f1 = m_.with_edge(a, b), f2 = m_.with_edge(b, a);
  if (f1 < 0 || f2 < 0) return false;
  const int c = starting_at(m_.triangles[static_cast<size_t>(f1)], a)[2];
  const int d = starting_at(m_.triangles[static_cast<size_t>(f2)], b)[2];
  if (frozen(f1) || frozen(f2)) return false;
  const Eigen::Vector3d mid = 0.5 * (m_.at(a) + m_.at(b));
  const double length = (m_.at(a) - m_.at(b)).norm();
  const Projection p = complex_.project(mid, m_.cells[static_cast<size_t>(a)], 1e-14);
  // A projection far from the midpoint (the edge spans a neck or a void) or
  // near a corner of the two triangles is no split of this edge.
  if (!p.converged || (p.point - mid).norm() > 0.25 * length) return false;
  for (int w : {a, b, c, d})
    if ((p.point - m_.at(w)).norm() < 0.3 * length) return false;
  const Eigen::Vector3d normal = complex_.evaluate(p.point, p.cell).gradient.normalized();
  const int n = m_.add_vertex(p.point, normal, p.cell);
  commit({f1, f2}, {{a, n, c}, {n, b, c}, {b, n, d}, {n, a, d}}, false);
  ++splits_;
  flip_around(n);
  return true;
}

// Moves vertex v to the skin point nearest the centroid of its neighbours
// (one step of tangential smoothing, which unfolds a vertex transport moved
// across its neighbours) when every triangle around it then passes.
bool Editor::try_relocate(int v) {
  const std::vector<int>& around = m_.star[static_cast<size_t>(v)];
  if (std::any_of(around.begin(), around.end(), [&](int f) { return frozen(f); })) return false;
  const std::vector<int> ring = m_.neighbours(v);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int w : ring) centroid += m_.at(w);
  centroid /= static_cast<double>(ring.size());
  const Projection p = complex_.project(centroid, m_.cells[static_cast<size_t>(v)], 1e-14);
  if (!p.converged) return false;
  const Eigen::Vector3d old_point = m_.at(v), old_normal = m_.normals[static_cast<size_t>(v)];
  const int old_cell = m_.cells[static_cast<size_t>(v)];
  m_.vertices[static_cast<size_t>(v)] = p.point;
  m_.cells[static_cast<size_t>(v)] = p.cell;
  m_.normals[static_cast<size_t>(v)] = complex_.evaluate(p.point, p.cell).gradient.normalized();
  const bool all_pass = std::all_of(around.begin(), around.end(), [&](int f) {
    return passes(m_.triangles[static_cast<size_t>(f)]);
  });
  if (all_pass) {
    ++relocations_;
    return true;
  }
  m_.vertices[static_cast<size_t>(v)] = old_point;
  m_.cells[static_cast<size_t>(v)] = old_cell;
  m_.normals[static_cast<size_t>(v)] = old_normal;
  return false;
}

// Whether a triangle faces against the skin's normals at its corners
// (transport moved a vertex across its neighbours).
bool Editor::turned_over(const Triangle& t) const {
  const Eigen::Vector3d n = area_normal(m_.at(t[0]), m_.at(t[1]), m_.at(t[2]));
  return !(n.dot(m_.normals[static_cast<size_t>(t[0])] + m_.normals[static_cast<size_t>(t[1])] +
                 m_.normals[static_cast<size_t>(t[2])]) > 0);
}

// One failing triangle mended (false: it is left as it is): a turned-over
// one by moving a corner back among its neighbours, or else frozen, since
// edits around a fold spread it; else a flip of one of its edges (longest first),
// else the contraction of its shortest edge when that is crowded, else the
// split of its longest edge.
bool Editor::mend(int f) {
  const Triangle t = m_.triangles[static_cast<size_t>(f)];
  std::array<std::pair<double, std::pair<int, int>>, 3> edges;
  for (size_t k = 0; k < 3; ++k) {
    const int u = t[k], v = t[(k + 1) % 3];
    edges[k] = {(m_.at(u) - m_.at(v)).squaredNorm(), {u, v}};
  }
  std::sort(edges.begin(), edges.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  if (turned_over(t)) {  // a vertex moved across its neighbours: move one back, else leave it to the patch repair
    for (int v : t)
      if (try_relocate(v)) return true;
    frozen_.resize(m_.triangles.size(), 0);
    frozen_[static_cast<size_t>(f)] = 1;
    return false;
  }
  for (const auto& e : edges)
    if (flip(e.second.first, e.second.second, FlipRule::both_pass)) return true;
  // A crowded or needle-short edge goes: splitting a needle makes needles.
  const auto [u, v] = edges[2].second;
  const double limit = options_.crowded_below * std::min(target_length(u), target_length(v));
  const bool needle = edges[2].first < 0.1 * edges[1].first;  // shortest edge under a third of the middle one
  if ((needle || edges[2].first < limit * limit) && (try_contract(u, v) || try_contract(v, u))) return true;
  return split(edges[0].second.first, edges[0].second.second);
}

// Mends the queue; a triangle no edit mends is set aside in `stuck`.
// False when the edits pass the budget (they chase each other).
bool Editor::run(const std::vector<char>& failing, long budget, EditRepair& out) {
  const size_t known_bad = failing.size();  // triangles below this index were judged failing already
  // Folds first: a turned-over triangle whose corners cannot be moved back
  // is frozen before any other edit can spread the fold.
  frozen_.assign(failing.size(), 0);
  for (size_t f = 0; f < failing.size(); ++f) {
    if (!failing[f] || !m_.alive[f] || !turned_over(m_.triangles[f])) continue;
    const Triangle t = m_.triangles[f];
    frozen_[f] = !std::any_of(t.begin(), t.end(), [&](int v) { return try_relocate(v); });
  }
  for (size_t f = 0; f < failing.size(); ++f)
    if (failing[f]) queue_.push_back(static_cast<int>(f));
  long edits = 0;
  bool ok = true;
  while (!queue_.empty() && ok) {
    const int f = queue_.front();
    queue_.pop_front();
    if (!m_.alive[static_cast<size_t>(f)]) continue;
    if (static_cast<size_t>(f) >= known_bad && passes(m_.triangles[static_cast<size_t>(f)])) continue;
    ok = ++edits <= budget;
    if (ok && !mend(f)) stuck_.push_back(f);
  }
  out.flips = flips_;
  out.splits = splits_;
  out.contractions = contractions_;
  out.relocations = relocations_;
  out.judged = judged_;
  return ok;
}

// The live triangles and the vertices they use, renumbered, with the
// stuck ones (still live) flagged.
void extract(const EditableMesh& m, size_t old_vertices, const std::vector<int>& stuck, EditRepair& out) {
  std::vector<char> is_stuck(m.triangles.size(), 0);
  for (int f : stuck) is_stuck[static_cast<size_t>(f)] = m.alive[static_cast<size_t>(f)];
  std::vector<int> renumber(m.vertices.size(), -1);
  for (size_t v = 0; v < renumber.size(); ++v) {
    if (m.star[v].empty()) continue;
    renumber[v] = static_cast<int>(out.mesh.vertices.size());
    out.mesh.vertices.push_back(m.vertices[v]);
    out.mesh.normals.push_back(m.normals[v]);
    out.mesh.cells.push_back(m.cells[v]);
    out.origin.push_back(v < old_vertices ? static_cast<long>(v) : -1);
  }
  for (size_t f = 0; f < m.triangles.size(); ++f) {
    if (!m.alive[f]) continue;
    const Triangle& t = m.triangles[f];
    out.mesh.triangles.push_back({renumber[static_cast<size_t>(t[0])], renumber[static_cast<size_t>(t[1])],
                                  renumber[static_cast<size_t>(t[2])]});
    out.failing.push_back(is_stuck[f]);
    out.stuck += is_stuck[f];
  }
}

}  // namespace

EditRepair repair_by_edits(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                           const MeshingOptions& accept, const EditRepairOptions& options) {
  EditRepair out;
  Editor editor(complex, mesh, accept, options);
  const long count = std::count(failing.begin(), failing.end(), 1);
  if (!editor.run(failing, options.edits_per_failing * count + 64, out)) return out;
  extract(editor.mesh(), mesh.vertices.size(), editor.stuck(), out);
  out.ok = true;
  return out;
}

}  // namespace skinmesh::detail
