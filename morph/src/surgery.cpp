#include "surgery.hpp"

#include "judge.hpp"
#include "mesh_part.hpp"

#include <Eigen/Geometry>
#include <boost/container/static_vector.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <optional>
#include <unordered_map>
#include <utility>

namespace skinmesh::detail {

size_t RefusedEdges::slot_of(const Key& key) const {
  // MurmurHash3's 64-bit finaliser of the two ids mixed: ids that follow
  // one another land in slots far apart.
  uint64_t h = static_cast<uint64_t>(key.first) * 0x9e3779b97f4a7c15ULL ^ static_cast<uint64_t>(key.second);
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  const size_t mask = slots_.size() - 1;
  size_t s = static_cast<size_t>(h) & mask;
  while (slots_[s] >= 0 && entries_[static_cast<size_t>(slots_[s])].first != key) s = (s + 1) & mask;
  return s;
}

std::vector<RefusedEdges::Entry>::const_iterator RefusedEdges::find(const Key& key) const {
  if (slots_.empty()) return entries_.end();
  const int at = slots_[slot_of(key)];
  return at < 0 ? entries_.end() : entries_.begin() + at;
}

void RefusedEdges::add(const Key& key, double length, int frames) {
  if (2 * (entries_.size() + 1) > slots_.size()) grow();
  const size_t s = slot_of(key);
  if (slots_[s] >= 0) return;
  slots_[s] = static_cast<int>(entries_.size());
  entries_.push_back({key, {length, frames}});
}

void RefusedEdges::reserve(size_t n) {
  entries_.reserve(n);
  while (slots_.size() < 2 * n) grow();
}

void RefusedEdges::grow() {
  slots_.assign(std::max<size_t>(64, 2 * slots_.size()), -1);
  for (size_t k = 0; k < entries_.size(); ++k) slots_[slot_of(entries_[k].first)] = static_cast<int>(k);
}

namespace {

using Triangle = std::array<int, 3>;

// The directed edges of the mesh: per vertex, the edges out of it with the
// triangle each lies in, in a block of `slots`. Built by counting (two
// passes over the triangles), it costs a fraction of a hash map of every
// directed edge (50-70 ms a frame for 3mht's 900,000, most of the edits'
// time when few triangles fail); a vertex has few edges, so a lookup scans
// a handful. A block that fills moves to the end of `slots` with twice the
// room.
class EdgeIndex {
 public:
  EdgeIndex(size_t vertices, const std::vector<std::array<int, 3>>& triangles)
      : start_(vertices + 1, 0), count_(vertices, 0), room_(vertices, 0) {
    for (const auto& t : triangles)
      for (int v : t) ++room_[static_cast<size_t>(v)];
    for (size_t v = 0; v < vertices; ++v) {
      room_[v] += kSpare;
      start_[v + 1] = start_[v] + room_[v];
    }
    start_.pop_back();
    // Room to grow without moving every slot: the first vertex an edit adds
    // or the first block that fills would otherwise copy the whole index.
    const size_t slots = static_cast<size_t>(start_.empty() ? 0 : start_.back() + room_.back());
    slots_.reserve(slots + slots / 8 + 1024);
    for (std::vector<int>* per_vertex : {&start_, &count_, &room_}) per_vertex->reserve(vertices + vertices / 16 + 64);
    slots_.resize(slots);
    // Each directed edge of a closed oriented manifold once: no lookup.
    for (size_t f = 0; f < triangles.size(); ++f) {
      const auto& t = triangles[f];
      for (size_t k = 0; k < 3; ++k) {
        const size_t v = static_cast<size_t>(t[k]);
        slots_[static_cast<size_t>(start_[v] + count_[v]++)] = {t[(k + 1) % 3], static_cast<int>(f)};
      }
    }
  }
  // The triangle holding edge from -> to, or -1.
  int face(int from, int to) const {
    const int k = slot(from, to);
    return k < 0 ? -1 : slots_[static_cast<size_t>(k)].second;
  }
  void set(int from, int to, int f) {
    const int k = slot(from, to);
    if (k >= 0) {
      slots_[static_cast<size_t>(k)].second = f;
      return;
    }
    const size_t v = static_cast<size_t>(from);
    if (count_[v] == room_[v]) grow(v);
    slots_[static_cast<size_t>(start_[v] + count_[v]++)] = {to, f};
  }
  void erase(int from, int to) {
    const int k = slot(from, to);
    if (k < 0) return;
    const size_t v = static_cast<size_t>(from);
    slots_[static_cast<size_t>(k)] = slots_[static_cast<size_t>(start_[v] + --count_[v])];
  }
  void add_vertex() {
    start_.push_back(static_cast<int>(slots_.size()));
    count_.push_back(0);
    room_.push_back(2 * kSpare);
    slots_.resize(slots_.size() + 2 * kSpare);
  }
  void remove_last_vertex() {  // one add_vertex undone, before any edge of it was set
    slots_.resize(static_cast<size_t>(start_.back()));
    start_.pop_back();
    count_.pop_back();
    room_.pop_back();
  }

 private:
  static constexpr int kSpare = 4;  // room for edges an edit adds to a vertex
  // Where edge from -> to is in `slots`, or -1.
  int slot(int from, int to) const {
    const size_t v = static_cast<size_t>(from);
    for (int k = start_[v], end = start_[v] + count_[v]; k < end; ++k)
      if (slots_[static_cast<size_t>(k)].first == to) return k;
    return -1;
  }
  void grow(size_t v) {
    const int at = static_cast<int>(slots_.size());
    slots_.resize(slots_.size() + static_cast<size_t>(2 * room_[v]));
    std::copy(slots_.begin() + start_[v], slots_.begin() + start_[v] + count_[v], slots_.begin() + at);
    start_[v] = at;
    room_[v] *= 2;
  }
  std::vector<int> start_, count_, room_;
  std::vector<std::pair<int, int>> slots_;  // (to, triangle)
};

// The triangles or vertices around one vertex, kept on the stack (Boost's
// fixed-capacity vector): the thinning asks for four such lists for each
// edge it tries, hundreds of edges a frame, and heap lists cost about a
// tenth of a small molecule's frame. A vertex with more triangles than
// this is left alone by the edits.
constexpr size_t kMostFan = 64;
template <class T>
using Fan = boost::container::static_vector<T, kMostFan>;

// Of the triangle a b c; infinite when its corners are collinear.
double circumradius_squared(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d u = b - a, w = c - a, uxw = u.cross(w);
  const double cross2 = uxw.squaredNorm();
  if (!(cross2 > 0)) return INFINITY;
  return (u.squaredNorm() * w.cross(uxw) + w.squaredNorm() * uxw.cross(u)).squaredNorm() / (4.0 * cross2 * cross2);
}

double angle_at(const Eigen::Vector3d& apex, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d u = (a - apex).normalized(), w = (b - apex).normalized();
  return std::acos(std::clamp(u.dot(w), -1.0, 1.0));
}

// The mesh with its directed edges indexed (each directed edge lies in one
// triangle of a closed oriented manifold), edited in place.
class Editor {
 public:
  Editor(const SkinComplex& complex, SurfaceMesh mesh, const MeshingOptions& accept, const EditPolicy& options,
         const std::vector<char>* still)
      : complex_(complex),
        mesh_(std::move(mesh)),
        accept_(accept),
        options_(options),
        edges_(mesh_.vertices.size(), mesh_.triangles),
        vertices_before_(mesh_.vertices.size()) {  // mesh_ is declared (so initialised) first
    if (mesh_.normals.size() != mesh_.vertices.size()) {
      mesh_.normals.resize(mesh_.vertices.size());
      for (size_t v = 0; v < mesh_.vertices.size(); ++v)
        mesh_.normals[v] = complex_.evaluate(mesh_.vertices[v], mesh_.cells[v]).gradient.normalized();
    }
    alive_.assign(mesh_.triangles.size(), 1);
    if (still != nullptr && still->size() == mesh_.vertices.size()) still_ = *still;
    corner_face_.assign(mesh_.vertices.size(), -1);
    for (int f = 0; f < static_cast<int>(mesh_.triangles.size()); ++f)
      for (int v : tri(f)) corner_face_[static_cast<size_t>(v)] = f;
  }

  RepairResult run(const std::vector<char>& failing, const std::vector<long>* ids, RefusedEdges* refused);

 private:
  const Triangle& tri(int f) const { return mesh_.triangles[static_cast<size_t>(f)]; }
  const Eigen::Vector3d& at(int v) const { return mesh_.vertices[static_cast<size_t>(v)]; }
  int face_of(int from, int to) const {
    return edges_.face(from, to);
  }
  int third(int f, int a, int b) const {
    for (int v : tri(f))
      if (v != a && v != b) return v;
    return -1;
  }
  void attach(int f) {
    const Triangle& t = tri(f);
    for (size_t k = 0; k < 3; ++k) {
      edges_.set(t[k], t[(k + 1) % 3], f);
      corner_face_[static_cast<size_t>(t[k])] = f;
    }
  }
  void detach(int f) {
    const Triangle& t = tri(f);
    for (size_t k = 0; k < 3; ++k) edges_.erase(t[k], t[(k + 1) % 3]);
  }
  int add_face(const Triangle& t) {
    mesh_.triangles.push_back(t);
    alive_.push_back(1);
    return static_cast<int>(mesh_.triangles.size()) - 1;
  }
  // Whether triangle (a, b, c) turns the way the skin's normals at its corners point.
  bool faces_out(const Triangle& t) const {
    const Eigen::Vector3d n = (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0]));
    for (int v : t)
      if (!(n.dot(mesh_.normals[static_cast<size_t>(v)]) > 0)) return false;
    return true;
  }
  // The triangles around v, in order across the edges into v (none where
  // they are not one closed fan of at most kMostFan).
  Fan<int> star(int v) const;
  // The vertices around v, in the same order (the corner after v in each triangle).
  Fan<int> ring(int v) const;
  // The ring of v from its star (`around`, star(v)): each triangle's corner after v.
  Fan<int> ring_of(int v, const Fan<int>& around) const;

  Verdict judge(int f) const;
  bool should_flip(int a, int b) const;
  bool flip(int a, int b, std::vector<int>& touched);
  void legalize(int apex, std::vector<std::pair<int, int>> link, std::vector<int>& touched);
  bool try_flip(int f, std::vector<int>& touched);
  bool try_split(int f, std::vector<int>& touched);
  bool try_contract(int f, std::vector<int>& touched);
  bool contract(int gone, int kept, std::vector<int>& touched);
  void thin_crowded(std::unordered_map<int, int>& seen, const std::vector<long>* ids, RefusedEdges* refused);
  struct Thinning {
    std::vector<char> near;             // per vertex
    std::vector<double> target;         // per vertex, Angstrom; -1: not worked out yet
    std::vector<unsigned char> to_try;  // per triangle, bit k: its edge k is to be tried
  };
  Thinning thinning_marks() const;
  void mark_after_contraction(const std::vector<int>& touched, Thinning& th) const;
  // Bit k set where edge k of triangle f (lower end first) has an end near
  // a change and is shorter than thin_below times the target at its ends.
  template <class TargetOf>
  unsigned char edges_to_try(size_t f, const std::vector<char>& near, TargetOf&& target_of) const {
    unsigned char bits = 0;
    const Triangle& t = mesh_.triangles[f];
    for (size_t k = 0; k < 3; ++k) {
      int a = t[k], b = t[(k + 1) % 3];
      if (a > b || !(near[static_cast<size_t>(a)] || near[static_cast<size_t>(b)])) continue;
      // The end near a change first: its target is known, and most edges
      // are too long for it, so the other end's is rarely needed.
      if (!near[static_cast<size_t>(a)]) std::swap(a, b);
      const double length = (at(a) - at(b)).norm();
      if (length < options_.thin_below * target_of(a) && length < options_.thin_below * target_of(b))
        bits = static_cast<unsigned char>(bits | (1u << k));
    }
    return bits;
  }
  void unsettle(const std::vector<int>& touched);
  std::vector<char> near_change() const;

  const SkinComplex& complex_;
  SurfaceMesh mesh_;
  const MeshingOptions& accept_;
  EditPolicy options_;
  std::vector<char> alive_;
  std::vector<int> corner_face_;  // per vertex: a triangle it is a corner of (-1: gone)
  std::vector<char> still_;       // per vertex of the mesh given (mend_by_edits); empty: none
  EdgeIndex edges_;
  size_t vertices_before_;
  long splits_ = 0, flips_ = 0, contractions_ = 0, thin_tried_ = 0;
};

Fan<int> Editor::star(int v) const {
  Fan<int> out;
  const int start = corner_face_[static_cast<size_t>(v)];
  if (start < 0) return out;
  int f = start;
  do {
    if (out.size() == kMostFan) return {};
    out.push_back(f);
    const Triangle& t = tri(f);
    const size_t k = static_cast<size_t>(std::find(t.begin(), t.end(), v) - t.begin());
    f = face_of(v, t[(k + 2) % 3]);  // across the edge into v
    if (f < 0) return {};
  } while (f != start);
  return out;
}

Fan<int> Editor::ring(int v) const { return ring_of(v, star(v)); }

Fan<int> Editor::ring_of(int v, const Fan<int>& around) const {
  Fan<int> out;
  for (int f : around) {
    const Triangle& t = tri(f);
    out.push_back(t[(static_cast<size_t>(std::find(t.begin(), t.end(), v) - t.begin()) + 1) % 3]);
  }
  return out;
}

// The frame's criteria with the kind of failure (judge.hpp).
Verdict Editor::judge(int f) const {
  const Triangle& t = tri(f);
  return judge_triangle(complex_, {at(t[0]), at(t[1]), at(t[2])}, mesh_.cells[static_cast<size_t>(t[0])], accept_);
}

// Edge a -> b is not locally Delaunay: the angles opposite it add up to more
// than pi (Lawson's flip criterion, on the mesh's own triangles).
bool Editor::should_flip(int a, int b) const {
  const int f = face_of(a, b), g = face_of(b, a);
  if (f < 0 || g < 0) return false;
  const int c = third(f, a, b), d = third(g, a, b);
  return angle_at(at(c), at(a), at(b)) + angle_at(at(d), at(a), at(b)) > M_PI + 1e-12;
}

// Edge a -> b (in triangle (a, b, c); (b, a, d) across it) becomes c - d:
// triangles (a, d, c) and (d, b, c), when both turn with the skin's normals
// and c - d is not an edge yet.
bool Editor::flip(int a, int b, std::vector<int>& touched) {
  const int f = face_of(a, b), g = face_of(b, a);
  if (f < 0 || g < 0) return false;
  const int c = third(f, a, b), d = third(g, a, b);
  if (c == d || face_of(c, d) >= 0 || face_of(d, c) >= 0) return false;
  const Triangle t1{a, d, c}, t2{d, b, c};
  if (!faces_out(t1) || !faces_out(t2)) return false;
  detach(f);
  detach(g);
  mesh_.triangles[static_cast<size_t>(f)] = t1;
  mesh_.triangles[static_cast<size_t>(g)] = t2;
  attach(f);
  attach(g);
  corner_face_[static_cast<size_t>(a)] = f;
  corner_face_[static_cast<size_t>(b)] = g;
  touched.push_back(f);
  touched.push_back(g);
  ++flips_;
  return true;
}

// Lawson's flips around a new vertex: each link edge (x -> y in the
// triangle (x, y, apex)) that is not locally Delaunay is flipped, and the
// two edges it uncovers are checked in turn.
void Editor::legalize(int apex, std::vector<std::pair<int, int>> link, std::vector<int>& touched) {
  int steps = 0;
  while (!link.empty() && steps++ < 64) {
    const auto [x, y] = link.back();
    link.pop_back();
    const int f = face_of(x, y);
    if (f < 0 || third(f, x, y) != apex || !should_flip(x, y)) continue;
    const int q = third(face_of(y, x), x, y);
    if (!flip(x, y, touched)) continue;
    link.emplace_back(x, q);  // now in (x, q, apex)
    link.emplace_back(q, y);  // now in (q, y, apex)
  }
}

bool Editor::try_flip(int f, std::vector<int>& touched) {
  const Triangle& t = tri(f);
  size_t longest = 0;
  double best = -1;
  for (size_t k = 0; k < 3; ++k) {
    const double len = (at(t[(k + 1) % 3]) - at(t[k])).squaredNorm();
    if (len > best) best = len, longest = k;
  }
  const int a = t[longest], b = t[(longest + 1) % 3];
  return should_flip(a, b) && flip(a, b, touched);
}

// The longest edge split at the skin point nearest its midpoint (the
// projection, exact on the skin), then Lawson's flips around it.
bool Editor::try_split(int f, std::vector<int>& touched) {
  const Triangle t = tri(f);
  size_t longest = 0;
  double best = -1;
  for (size_t k = 0; k < 3; ++k) {
    const double len = (at(t[(k + 1) % 3]) - at(t[k])).squaredNorm();
    if (len > best) best = len, longest = k;
  }
  const int a = t[longest], b = t[(longest + 1) % 3], c = t[(longest + 2) % 3];
  const int g = face_of(b, a);
  if (g < 0) return false;
  const int d = third(g, a, b);
  const Eigen::Vector3d mid = 0.5 * (at(a) + at(b));
  const Projection p = complex_.project(mid, mesh_.cells[static_cast<size_t>(a)], 1e-14);
  // Farther than half the edge, the projection went to another sheet.
  if (!p.converged || (p.point - mid).norm() > 0.5 * std::sqrt(best)) return false;
  const int m = static_cast<int>(mesh_.vertices.size());
  mesh_.vertices.push_back(p.point);
  mesh_.cells.push_back(p.cell);
  mesh_.normals.push_back(complex_.evaluate(p.point, p.cell).gradient.normalized());
  corner_face_.push_back(-1);
  edges_.add_vertex();
  const std::array<Triangle, 4> made{Triangle{a, m, c}, Triangle{m, b, c}, Triangle{b, m, d}, Triangle{m, a, d}};
  if (!std::all_of(made.begin(), made.end(), [&](const Triangle& n) { return faces_out(n); })) {
    mesh_.vertices.pop_back();
    mesh_.cells.pop_back();
    mesh_.normals.pop_back();
    corner_face_.pop_back();
    edges_.remove_last_vertex();
    return false;
  }
  detach(f);
  detach(g);
  mesh_.triangles[static_cast<size_t>(f)] = made[0];
  mesh_.triangles[static_cast<size_t>(g)] = made[2];
  const int f2 = add_face(made[1]), g2 = add_face(made[3]);
  for (int h : {f, g, f2, g2}) {
    attach(h);
    touched.push_back(h);
  }
  ++splits_;
  legalize(m, {{c, a}, {b, c}, {d, b}, {a, d}}, touched);
  return true;
}

// Vertex `gone` merged into `kept` along their edge: allowed where the link
// condition holds (their common neighbours are the two corners opposite the
// edge, so the topology stays) and every triangle it leaves passes.
bool Editor::contract(int gone, int kept, std::vector<int>& touched) {
  const int f = face_of(gone, kept), g = face_of(kept, gone);
  if (f < 0 || g < 0) return false;
  const Fan<int> star_gone = star(gone);
  const Fan<int> around_gone = ring_of(gone, star_gone);
  if (around_gone.size() < 3) return false;
  Fan<int> fan;  // triangles around `gone` that stay, with `kept` in its place
  for (int h : star_gone)
    if (h != f && h != g) fan.push_back(h);
  Fan<Triangle> renamed;
  for (int h : fan) {
    Triangle t = tri(h);
    std::replace(t.begin(), t.end(), gone, kept);
    if (!faces_out(t)) return false;
    renamed.push_back(t);
  }
  // The tests cheapest for what they refuse first: the shape; then each
  // triangle judged, the widest first (most thinning contractions are
  // refused for size or distance, which the widest triangle fails first,
  // and the first failure ends the judging), on a copy of each triangle;
  // last the link condition, whose rings cost more and which seldom refuses.
  for (const Triangle& t : renamed)
    if (!shape_passes({at(t[0]), at(t[1]), at(t[2])}, accept_.min_angle)) return false;
  Fan<std::pair<double, size_t>> widest_first;
  for (size_t i = 0; i < fan.size(); ++i) {
    const Triangle& t = renamed[i];
    widest_first.emplace_back(-circumradius_squared(at(t[0]), at(t[1]), at(t[2])), i);
  }
  std::sort(widest_first.begin(), widest_first.end());
  for (const auto& entry : widest_first) {
    const size_t i = entry.second;
    const Triangle saved = tri(fan[i]);
    mesh_.triangles[static_cast<size_t>(fan[i])] = renamed[i];
    const bool passes = judge(fan[i]) == Verdict::pass;
    mesh_.triangles[static_cast<size_t>(fan[i])] = saved;
    if (!passes) return false;
  }
  const Fan<int> around_kept = ring(kept);
  if (around_kept.size() < 3 || around_gone.size() + around_kept.size() < 8) return false;
  long common = 0;
  for (int v : around_gone) common += std::count(around_kept.begin(), around_kept.end(), v);
  if (common != 2) return false;
  // The corners opposite the edge lose a neighbour: each keeps three.
  if (star(third(f, gone, kept)).size() < 4 || star(third(g, gone, kept)).size() < 4) return false;
  detach(f);
  detach(g);
  for (int h : fan) detach(h);
  alive_[static_cast<size_t>(f)] = alive_[static_cast<size_t>(g)] = 0;
  for (size_t i = 0; i < fan.size(); ++i) {
    mesh_.triangles[static_cast<size_t>(fan[i])] = renamed[i];
    attach(fan[i]);
    touched.push_back(fan[i]);
  }
  corner_face_[static_cast<size_t>(gone)] = -1;
  ++contractions_;
  return true;
}

// A failing triangle's shortest edge, when transport crowded its ends
// together: the newer end goes (it was inserted later), else the other.
bool Editor::try_contract(int f, std::vector<int>& touched) {
  const Triangle t = tri(f);
  size_t shortest = 0;
  double best = INFINITY;
  for (size_t k = 0; k < 3; ++k) {
    const double len = (at(t[(k + 1) % 3]) - at(t[k])).norm();
    if (len < best) best = len, shortest = k;
  }
  const int a = t[shortest], b = t[(shortest + 1) % 3];
  const double target = std::min(
      target_edge_length(complex_, at(a), mesh_.cells[static_cast<size_t>(a)], accept_),
      target_edge_length(complex_, at(b), mesh_.cells[static_cast<size_t>(b)], accept_));
  if (!(best < options_.contract_below * target)) return false;
  return contract(std::max(a, b), std::min(a, b), touched) || contract(std::min(a, b), std::max(a, b), touched);
}

// The corners of the triangles `touched` (made by an edit) are no longer still.
void Editor::unsettle(const std::vector<int>& touched) {
  for (int h : touched)
    for (int v : tri(h))
      if (static_cast<size_t>(v) < still_.size()) still_[static_cast<size_t>(v)] = 0;
}

// Per vertex, whether a triangle around it has a corner that is not still
// (a vertex an edit made is not): a contraction of an edge between two
// vertices that are not near a change would judge a congruent fan, on a
// congruent skin, as in the frame before. Every vertex without `still_`.
std::vector<char> Editor::near_change() const {
  const size_t n = mesh_.vertices.size();
  if (still_.empty()) return std::vector<char>(n, 1);
  std::vector<char> near(n, 0);
  const auto still = [&](int v) { return static_cast<size_t>(v) < still_.size() && still_[static_cast<size_t>(v)]; };
  for (size_t f = 0; f < mesh_.triangles.size(); ++f) {
    if (!alive_[f]) continue;
    const Triangle& t = mesh_.triangles[f];
    if (still(t[0]) && still(t[1]) && still(t[2])) continue;
    for (int v : t) near[static_cast<size_t>(v)] = 1;
  }
  return near;
}

// Thinning contractions refused in the frame before (RefusedEdges, by the
// ids of the edge's ends), and those refused in this one.
class RefusalMemo {
 public:
  RefusalMemo(const std::vector<long>* ids, RefusedEdges* refused, const EditPolicy& options)
      : ids_(ids), refused_(refused), options_(options) {
    if (refused_) {
      before_.swap(*refused_);
      refused_->reserve(before_.size());
    }
  }
  // The edge a - b by the ids of its ends; none without a memo, or for a
  // vertex a split made in this frame (its edges are new).
  std::optional<std::pair<long, long>> key_of(int a, int b) const {
    if (!ids_ || !refused_ || static_cast<size_t>(std::max(a, b)) >= ids_->size()) return std::nullopt;
    const long ia = (*ids_)[static_cast<size_t>(a)], ib = (*ids_)[static_cast<size_t>(b)];
    return std::make_pair(std::min(ia, ib), std::max(ia, ib));
  }
  RefusalMemo(const RefusalMemo&) = delete;
  RefusalMemo& operator=(const RefusalMemo&) = delete;
  // Refused in a frame before, neither shrunk since nor aged: skipped, and
  // remembered a frame older.
  bool still_refused(const std::optional<std::pair<long, long>>& key, double length) {
    if (!key) return false;
    const auto it = before_.find(*key);
    if (it == before_.end()) return false;
    const auto [length_then, age] = it->second;
    if (length < (1 - options_.retry_shrink) * length_then || age + 1 >= options_.retry_after_frames) return false;
    refused_->add(*key, length_then, age + 1);
    return true;
  }
  void refuse(const std::optional<std::pair<long, long>>& key, double length) {
    if (key) refused_->add(*key, length, 0);
  }

 private:
  const std::vector<long>* ids_;
  RefusedEdges* refused_;
  const EditPolicy& options_;
  RefusedEdges before_;
};

// The thinning's marks: per vertex, near a change (near_change) and its
// target edge length (-1: not worked out yet); per triangle, bit k set
// where its edge k (lower end first) is near a change and shorter than
// thin_below times the target at its ends. Found in parallel.
Editor::Thinning Editor::thinning_marks() const {
  Thinning th;
  th.near = near_change();
  const size_t n = mesh_.vertices.size();
  th.target.assign(n, -1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 512), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      if (corner_face_[v] >= 0 && th.near[v])
        th.target[v] = target_edge_length(complex_, mesh_.vertices[v], mesh_.cells[v], accept_);
  });
  th.to_try.assign(mesh_.triangles.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, th.to_try.size(), 2048), [&](const tbb::blocked_range<size_t>& r) {
    const auto known_target = [&](int v) {  // not cached: other threads read `target`
      const double t = th.target[static_cast<size_t>(v)];
      return t >= 0 ? t : target_edge_length(complex_, at(v), mesh_.cells[static_cast<size_t>(v)], accept_);
    };
    for (size_t f = r.begin(); f != r.end(); ++f)
      if (alive_[f]) th.to_try[f] = edges_to_try(f, th.near, known_target);
  });
  return th;
}

// The marks kept up to date after a contraction: the triangles it changed
// (`touched`) and those around the vertices it brought near a change.
void Editor::mark_after_contraction(const std::vector<int>& touched, Thinning& th) const {
  const auto target_at = [&](int v) {
    double& t = th.target[static_cast<size_t>(v)];
    if (t < 0) t = target_edge_length(complex_, at(v), mesh_.cells[static_cast<size_t>(v)], accept_);
    return t;
  };
  std::vector<int> newly_near;
  for (int h : touched)
    for (int v : tri(h))  // its fan changed
      if (!th.near[static_cast<size_t>(v)]) th.near[static_cast<size_t>(v)] = 1, newly_near.push_back(v);
  for (int v : newly_near)
    for (int h : star(v)) th.to_try[static_cast<size_t>(h)] = edges_to_try(static_cast<size_t>(h), th.near, target_at);
  for (int h : touched) th.to_try[static_cast<size_t>(h)] = edges_to_try(static_cast<size_t>(h), th.near, target_at);
}

// Every edge shorter than thin_below times the target edge length at its
// ends is contracted where that keeps every guarantee (contract): splits
// add vertices where the skin stretches, and this takes them away where it
// shrinks, so that the vertex count follows the surface. With still marks,
// only edges near a change are tried (near_change).
void Editor::thin_crowded(std::unordered_map<int, int>& seen, const std::vector<long>* ids, RefusedEdges* refused) {
  RefusalMemo memo(ids, refused, options_);
  Thinning th = thinning_marks();
  std::vector<int> touched;
  for (size_t f = 0; f < th.to_try.size(); ++f) {
    for (size_t k = 0; k < 3 && th.to_try[f]; ++k) {
      if (!alive_[f] || !(th.to_try[f] & (1u << k))) continue;
      const Triangle& t = mesh_.triangles[f];
      const int a = t[k], b = t[(k + 1) % 3];
      const double length = (at(a) - at(b)).norm();
      const auto key = memo.key_of(a, b);
      if (memo.still_refused(key, length)) continue;
      touched.clear();
      ++thin_tried_;
      if (!contract(b, a, touched) && !contract(a, b, touched)) {
        memo.refuse(key, length);
        continue;
      }
      for (int h : touched) seen.emplace(h, 0);
      mark_after_contraction(touched, th);
      break;  // this triangle is gone
    }
  }
}

RepairResult Editor::run(const std::vector<char>& failing, const std::vector<long>* ids, RefusedEdges* refused) {
  std::deque<int> queue;
  for (size_t f = 0; f < failing.size(); ++f)
    if (failing[f]) queue.push_back(static_cast<int>(f));
  const long budget = options_.edits_per_failing * static_cast<long>(queue.size()) + 64;
  // Triangles to judge at the end, with the generation of the edit that
  // made them (0: failing after transport).
  std::unordered_map<int, int> seen;
  for (int f : queue) seen[f] = 0;
  long edits = 0;
  std::vector<int> touched;
  while (!queue.empty() && edits < budget) {
    const int f = queue.front();
    queue.pop_front();
    const int generation = seen[f];
    if (!alive_[static_cast<size_t>(f)] || generation >= options_.generations) continue;
    const Verdict verdict = judge(f);
    if (verdict == Verdict::pass || verdict == Verdict::inward) continue;
    touched.clear();
    bool mended = verdict == Verdict::shape && (try_contract(f, touched) || try_flip(f, touched));
    if (!mended) mended = try_split(f, touched);
    if (!mended) continue;  // left failing
    ++edits;
    unsettle(touched);
    for (int h : touched) {
      queue.push_back(h);
      seen[h] = generation + 1;
    }
  }
  if (options_.thin_below > 0) thin_crowded(seen, ids, refused);
  RepairResult out;
  out.ok = true;
  std::vector<int> kept_from;
  out.mesh = used_part(mesh_, alive_, kept_from);
  for (int v : kept_from) out.origin.push_back(static_cast<size_t>(v) < vertices_before_ ? v : -1);
  // The triangles an edit made or that failed, judged again in parallel;
  // the others kept the verdict pass.
  std::vector<int> again;
  again.reserve(seen.size());
  for (const auto& entry : seen)
    if (alive_[static_cast<size_t>(entry.first)]) again.push_back(entry.first);
  std::vector<char> fails(mesh_.triangles.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, again.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i)
      fails[static_cast<size_t>(again[i])] = judge(again[i]) != Verdict::pass;
  });
  for (size_t f = 0; f < mesh_.triangles.size(); ++f)
    if (alive_[f]) out.failing.push_back(fails[f]);
  out.left = std::count(out.failing.begin(), out.failing.end(), 1);
  out.counts.splits = splits_;
  out.counts.flips = flips_;
  out.counts.contractions = contractions_;
  out.thin_tried = thin_tried_;
  return out;
}

}  // namespace

RepairResult mend_by_edits(const SkinComplex& complex, SurfaceMesh mesh, const std::vector<char>& failing,
                      const MeshingOptions& accept, const EditPolicy& options, const std::vector<long>* ids,
                      RefusedEdges* refused, const std::vector<char>* still) {
  Editor editor(complex, std::move(mesh), accept, options, still);
  return editor.run(failing, ids, refused);
}

}  // namespace skinmesh::detail
